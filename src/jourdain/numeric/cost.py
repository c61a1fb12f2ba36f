"""The integrator's evaluation path chosen by predicted cost, not by a node count (issue 35).

Three paths compute the integrator's ÿ = M⁻¹(q − k) (``jd_accel``):

* ``symbolic``: the straight-line code of the symbolic projection's M, k, q, then LDLᵀ
  (:func:`jourdain.numeric.compiled.symbolic_mkq`);
* ``planar``: the recursion in planar vectors (:mod:`jourdain.numeric.planar_recursion`),
  for systems whose bodies all move in the x-y plane;
* ``spatial``: the recursion in spatial vectors (:mod:`jourdain.numeric.recursive`).

Both recursions take the articulated-body ÿ where every coordinate belongs to one joint, else
LDLᵀ of their M. Their cost per right-hand side is predicted from the model's structure alone
(bodies, Jacobian columns, the operations of the per-joint expressions, f); the symbolic
path's from the nodes and the C library's calls of its expression graph, and f. The symbolic
projection is derived only where a lower bound of its cost (the LDLᵀ solve and one operation per entry of M, k, q) beats
the best recursion, and its graph is counted only up to the size at which it would lose
(never deriving what the chosen path does not need). Past :data:`SYMBOLIC_MAX_NODES` it is not
taken however fast: its code generation and compile time grow faster than its graph, and a
model's first simulation waits for them (the 7-joint arm's 3 320 nodes: 1.2-1.4 s against
0.3-0.7 s for the recursion, for 0.96 against 1.14 µs per state; a 24-link planar chain's
symbolic code took 9.5 s).

The constants (:data:`COST_NS`) are fitted by ``benchmarks/paths.py --fit`` to the measured
times of every path on planar and spatial chains and trees, f = 1 … 128; the same script shows
every model's chosen path against the fastest it could have taken.

Floor: numeric.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import lru_cache
from types import MappingProxyType
from typing import TYPE_CHECKING

from ..errors import refuse_closed
from ..graph import count_graph, count_nodes
from ..stages.kinematics import kinematics
from ..stages.newton_euler import newton_euler
from ..stages.projection import projection
from .planar_recursion import is_planar
from .recursive import _disjoint, layout

if TYPE_CHECKING:
    from ..model.system import System
    from ..stages.projection import EquationsOfMotion

#: ns per right-hand side (AMD EPYC, gcc -O2; ``benchmarks/paths.py --fit``, 2026-11-27):
#: per body, per Jacobian column, per node of the per-joint expressions, per f³ of an LDLᵀ
#: solve (the recursions where coordinates are shared), and a constant; the symbolic path per
#: node of its graph, per call of the C library in it (a sine of a sum of angles), per f² (the
#: entries of M and their solve) and per f³
COST_NS: Mapping[str, Mapping[str, float]] = MappingProxyType({
    "planar": MappingProxyType({"body": 25.5, "column": 0.0, "local": 7.7, "solve": 0.26,
                                "base": 0.9}),
    "spatial": MappingProxyType({"body": 83.0, "column": 67.0, "local": 0.97, "solve": 0.13,
                                 "base": 36.0}),
    "symbolic": MappingProxyType({"node": 0.30, "call": 3.5, "entry": 0.0, "solve": 0.00066,
                                  "base": 7.3}),
})
#: the symbolic path is not taken above this many nodes of its graph (its compile time)
SYMBOLIC_MAX_NODES = 3000
#: nor above this many coordinates (its graph is not derived)
SYMBOLIC_MAX_F = 24


@dataclass(frozen=True)
class PathChoice:
    """The path :func:`jourdain.numeric.mkq_function` compiles, and why.

    ``path``: ``"symbolic"``, ``"planar"`` or ``"spatial"``; ``cost``: the predicted ns per
    right-hand side of every path considered (the symbolic one only where derived);
    ``features``: what the prediction read (``f``, ``bodies``, ``columns``, ``local`` nodes,
    ``shared`` coordinates (1 or 0), ``planar`` (1 or 0), ``nodes`` and library ``calls`` of
    the symbolic graph, counted up to where it loses); ``eom``: the symbolic projection where
    it was derived and taken."""

    path: str
    cost: Mapping[str, float]
    features: Mapping[str, int]
    eom: EquationsOfMotion | None = field(default=None, repr=False, compare=False)


def recursion_features(system: System) -> dict[str, int]:
    """Bodies, Jacobian columns, nodes of the per-joint expressions, whether coordinates are
    shared between joints, whether the system is planar, and f."""
    lay = layout(system)
    return {"f": system.f, "bodies": len(lay.parent),
            "columns": sum(len(c) for c in lay.columns),
            "local": count_nodes(list(lay.exprs), 10 ** 7),
            "shared": 0 if _disjoint(lay.columns) else 1,
            "planar": 1 if is_planar(system) else 0}


def recursion_cost(kind: str, feats: Mapping[str, int]) -> float:
    """Predicted ns per right-hand side of the ``planar`` or ``spatial`` recursion."""
    c = COST_NS[kind]
    return (c["base"] + c["body"] * feats["bodies"] + c["column"] * feats["columns"]
            + c["local"] * feats["local"] + c["solve"] * feats["shared"] * feats["f"] ** 3)


def symbolic_cost(nodes: int, calls: int, f: int) -> float:
    """Predicted ns per right-hand side of the symbolic path whose graph has ``nodes`` nodes,
    ``calls`` of them calls of the C library (:func:`jourdain.graph.count_graph`)."""
    c = COST_NS["symbolic"]
    return (c["base"] + c["node"] * nodes + c["call"] * calls + c["entry"] * f * f
            + c["solve"] * f ** 3)


@lru_cache(maxsize=32)
def evaluation_path(system: System) -> PathChoice:
    """The cheapest path per right-hand side for ``system`` by the cost model (memoized per
    system), deriving the symbolic projection only where it can win. A closed system (closing
    joints, contacts, generalized velocities) is refused by name: these paths compute the open
    tree's ÿ."""
    refuse_closed(system, "the evaluation paths compute the open tree's ÿ",
                  "use system.tree for the open tree")
    feats = recursion_features(system)
    cost = {"spatial": recursion_cost("spatial", feats)}
    if feats["planar"]:
        cost["planar"] = recursion_cost("planar", feats)
    best = min(cost.values())
    f = system.f
    entries = f * (f + 1) // 2 + 2 * f
    eom = None
    if f <= SYMBOLIC_MAX_F and symbolic_cost(entries, 0, f) < best:
        eom = projection(newton_euler(kinematics(system)))
        exprs = [*eom.M.entries(), *eom.k.entries(), *eom.q.entries()]
        # the graph is counted only as far as the symbolic path could still win
        node = max(COST_NS["symbolic"]["node"], 1e-9)
        cap = min(SYMBOLIC_MAX_NODES, int((best - symbolic_cost(0, 0, f)) / node) + 1)
        nodes, calls = count_graph(exprs, cap)
        feats["nodes"], feats["calls"] = nodes, calls
        if nodes <= cap:
            cost["symbolic"] = symbolic_cost(nodes, calls, f)
    path = min(cost, key=lambda k: (cost[k], k))
    return PathChoice(path, MappingProxyType(cost), MappingProxyType(feats),
                      eom if path == "symbolic" else None)
