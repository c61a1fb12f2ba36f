"""The numbers of the method for a general system at one state (METHOD.md §7): what
:meth:`jourdain.System.evaluate` gives for a system with velocity constraints.

At the state (the independent coordinates of ``y`` held, the dependent ones solved; the speeds
``z`` from ``ẏ``) with ``ẏ = L·z + l``: the global velocity Jacobian ``L̄ = J̄_tree·L``, ``M, k,
q`` in z, ``ż``, ``ÿ``, the rows' directions ``Q̄_c`` (a contact's force along each row at its
contact point: ``J̄_treeᵀ·Q̄_c = Aᵀ``, so ``L̄ᵀ·Q̄_c = 0``: Jourdain's principle) and the contact
forces: the multipliers of ``M_tree·ÿ + k_tree − q_tree = Aᵀλ`` by row label
(``rear.N`` normal, ``rear.T1``, ``rear.T2`` tangential, ...).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from functools import lru_cache
from typing import Any

import numpy as np

from ..errors import EvaluationError
from ..model import System
from ..numeric import CompiledFunction, lambdify
from ..numeric import evaluate as tree_evaluate
from .general import GeneralEvaluator
from .general_choice import general_constraints


@lru_cache(maxsize=16)
def _directions(system: System) -> CompiledFunction:
    return lambdify(system.tree, {"Q_c": general_constraints(system).Q_bar})


def evaluate_general(system: System, y: Any, yd: Any = None, t: float = 0.0,
                     parameters: Mapping[str, float] | None = None,
                     inputs: Sequence[float] | None = None) -> dict[str, Any]:
    """The numbers at a state of the general ``system`` (see the module docstring): keys
    ``y, yd, z, zd, ydd, speeds, independent, L, l, M, k, q, M_bar, J_bar, Q_c, labels,
    contact_forces`` (by label; ``contacts_undetermined``: the rows whose share the equations
    leave open, redundant rows sharing their force evenly), ``lambda``, ``Phi`` (holonomic rows), ``Phi_dot`` (every
    row's ``A·ẏ + a``), ``orthogonality`` (the largest entry of ``L̄ᵀ·Q̄_c``)."""
    if inputs is not None and len(inputs):
        raise EvaluationError(f"{system.name}: inputs are not available for systems with "
                              "velocity constraints yet")
    ev = GeneralEvaluator(system, y, t, parameters)
    x = ev.initial(y, yd, t)
    s = ev.accelerations(x, t)
    lam = ev.multipliers(s)
    Phi, Phi_dot = ev.residuals(s, t)
    tree = tree_evaluate(system.tree, s["y"], s["yd"], t, parameters,
                         [0.0] * len(system.tree.inputs) if system.tree.inputs else None)
    p = ev.p
    Qc = _directions(system)
    Q_c = Qc.split(Qc.raw(np.ascontiguousarray(s["y"]), np.ascontiguousarray(s["yd"]), t, p,
                          ev.u))["Q_c"]
    J_bar = tree["J_bar"] @ s["L"]
    out = {k: s[k] for k in ("y", "yd", "z", "zd", "ydd", "L", "l", "M", "k", "q", "gamma")}
    out.update(
        speeds=list(ev.speed_names), independent=list(ev.independent_names),
        M_bar=tree["M_bar"], J_bar=J_bar, J_bar_tree=tree["J_bar"], Q_c=Q_c,
        labels=list(ev.labels), **{"lambda": lam},
        contact_forces=dict(zip(ev.labels, (float(v) for v in lam), strict=True)),
        contacts_undetermined=ev.undetermined(),
        Phi=Phi, Phi_dot=Phi_dot,
        orthogonality=float(np.max(np.abs(J_bar.T @ Q_c), initial=0.0)))
    return out


__all__ = ["evaluate_general"]
