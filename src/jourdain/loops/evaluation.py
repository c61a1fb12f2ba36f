"""The numbers of the method for a closed system at one state (METHOD.md §7, §4): what
:meth:`jourdain.System.evaluate` gives for a system with closing joints.

At the state ``y, ẏ`` (the tree's coordinates; the independent ones held, the rest assembled
onto ``Φ = 0``, ``Φ̇ = 0``) with the velocity map ``ẏ = L·ẏ_i + l`` and ``ÿ = L·ÿ_i + γ``:

* the closed system's global Jacobian ``J̄ = J̄_tree·L`` and ``M = LᵀM_tree·L``,
  ``k = Lᵀ(k_tree + M_tree·γ)``, ``q = Lᵀq_tree`` in the independent coordinates;
* ``Q̄ = [Q̄_tree, Q̄_c]``: the tree joints' constrained directions and the closing joints' rows
  (:func:`jourdain.stages.constraints.constraints`, ``J̄_treeᵀ·Q̄_c = Φ_yᵀ``, so
  ``J̄ᵀ·Q̄ = 0``), and ``N̂·g = k̂ − q̂`` with ``N̂ = Q̄ᵀM̄⁻¹Q̄``, ``k̂ = Q̄ᵀ(J̄_tree·ÿ +
  M̄⁻¹q̄^c)``, ``q̂ = Q̄ᵀM̄⁻¹q̄^e``: every joint's reactions, the closing joints' included
  (their g equal the multipliers λ of ``M_tree·ÿ + k_tree − q_tree = Φ_yᵀλ``; a general
  constraint of expressions has no direction in the bodies: its reaction is λ alone).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace
from functools import lru_cache
from typing import Any

import numpy as np

from ..analysis.reactions import _reactions_function, projected_reactions, solve_g
from ..errors import EvaluationError, JourdainError
from ..model import System
from ..numeric import CompiledFunction, lambdify, state_vectors
from ..numeric import evaluate as tree_evaluate
from ..symbolic import SymMatrix
from ..wrenches import joint_wrenches
from .closed_loop import LoopEvaluator, constraints
from .reactions import closing_reactions


@lru_cache(maxsize=16)
def _closing_columns(system: System) -> tuple[list[int], CompiledFunction]:
    """The rows of Φ with a direction in the bodies (not ``generic``) and Q̄_c of those,
    compiled in the tree's arguments."""
    con = constraints(system)
    keep = [i for i, r in enumerate(con.rows) if r.kind != "generic"]
    Q = con.Q_bar.rows
    cols = SymMatrix.from_rows([[row[i] for i in keep] for row in Q]) if keep else None
    mats = {"Q_c": cols} if cols is not None else {"Q_c": SymMatrix.zeros(1, 1)}
    return keep, lambdify(system.tree, mats)


def closed_reactions(system: System, s: Mapping[str, Any], lam: np.ndarray | None, t: float,
                     parameters: Mapping[str, float] | None, u: np.ndarray,
                     tree: Mapping[str, np.ndarray]) -> dict[str, Any]:
    """Q̄, N̂, k̂, q̂ and g of the closed system at the assembled state ``s`` (see the module
    docstring); ``tree``: the tree's M̄, q̄^c, q̄^e, Q̄, J̄ there."""
    con = constraints(system)
    lay, _ = _reactions_function(system.tree)
    keep, fn = _closing_columns(system)
    Qt = np.asarray(tree["Q_bar"])
    q0 = Qt.shape[1]
    if keep:
        args = state_vectors(system.tree, s["z"], s["zd"], t, parameters,
                             list(u) if len(system.inputs) else None)
        Qc = np.asarray(fn(*args)["Q_c"]).reshape(Qt.shape[0], len(keep))
    else:
        Qc = np.zeros((Qt.shape[0], 0))
    Q = np.concatenate([Qt, Qc], axis=1)
    names = [b.name for b in system.bodies]
    touching = [list(c) for c in lay.touching]
    for j, i in enumerate(keep):
        row = con.rows[i]
        for body in (row.body_a, row.body_b):
            if body != "world":
                touching[names.index(body)].append(q0 + j)
    lay_c = replace(lay, touching=tuple(tuple(sorted(set(c))) for c in touching),
                    g_names=(*lay.g_names, *(con.rows[i].label for i in keep)))
    M_bar = np.asarray(tree["M_bar"])
    qc = np.asarray(tree["q_c"]).reshape(-1)
    qe = np.asarray(tree["q_e"]).reshape(-1)
    # k̂ = Q̄ᵀ(J̄_tree·ÿ + M̄⁻¹q̄^c) = Q̄ᵀM̄⁻¹(M̄·J̄_tree·ÿ + q̄^c): J̄_treeᵀQ̄_tree = 0, but the
    # closing columns see the tree's accelerations (Q̄_cᵀJ̄_tree·ÿ = Φ_y·ÿ = −c)
    qc_eff = qc + M_bar @ (np.asarray(tree["J_bar"]) @ s["zdd"])
    N, kh, qh = projected_reactions(lay_c, M_bar, Q, qc_eff, qe)
    g, und = solve_g(Q, N, kh, qh, qc_eff, qe, lay.singular_rows, lay_c.g_names)
    if not (np.isfinite(N).all() and np.isfinite(kh).all() and np.isfinite(qh).all()):
        raise EvaluationError(f"N_hat, k_hat or q_hat of {system.name!r} contain NaN or inf at "
                              "this state")
    return {"Q_bar": Q, "N_hat": N, "k_hat": kh, "q_hat": qh, "g": g,
            "g_names": list(lay_c.g_names), "g_undetermined": und, "_q_tree": q0}


def evaluate_closed(system: System, y: Any, yd: Any, t: float = 0.0,
                    parameters: Mapping[str, float] | None = None,
                    inputs: Mapping[str, float] | Sequence[float] | None = None
                    ) -> dict[str, Any]:
    """Every number of the method for the closed ``system`` at the state assembled from
    ``y, ẏ`` (the tree's coordinates, the independent ones held): a dict by the seed's names.

    ``y, yd, ydd`` (f: the assembled tree state and its accelerations), ``independent``
    (names), ``M, k, q`` (in the independent coordinates), ``L`` (f×g), ``l`` (f), ``gamma``,
    ``J_bar`` (6p×g: the closed system's, J̄_tree·L), ``M_bar, q_c, q_e`` (the tree's),
    ``Phi``, ``Phi_y``, ``Phi_t``, ``Phi_dot``, ``constraint_labels``, ``lambda`` (the
    multipliers, by row), ``closure_residual`` (``{"Phi": max|Φ|, "Phi_dot": max|Φ̇|}``),
    ``orthogonality`` (``max|Φ_y·L|``), and the reactions ``Q_bar, N_hat, k_hat, q_hat, g,
    g_names, g_undetermined, joint_wrenches, closing_wrenches`` (or ``reactions_error``).
    """
    tree_sys = system.tree
    names = system.input_names
    _, _, tv, _, uv = state_vectors(tree_sys, np.zeros(system.f), np.zeros(system.f), t,
                                    parameters, inputs)
    ev = LoopEvaluator(system, y, tv, parameters, uv)
    asm = ev.assemble(y, yd, tv)
    ind = list(ev.part.independent)
    s = ev.accelerations(asm.z[ind], asm.zd[ind], tv)
    lam = ev.multipliers(s)
    tree = tree_evaluate(tree_sys, s["z"], s["zd"], tv, parameters, list(uv) if names else None)
    L = s["J_z"]
    con = ev._con(s["z"], s["zd"], tv)
    out: dict[str, Any] = {
        "y": s["z"], "yd": s["zd"], "ydd": s["zdd"],
        "independent": list(ev.independent_names), "dependent": list(ev.dependent_names),
        "M_bar": tree["M_bar"], "J_bar": np.asarray(tree["J_bar"]) @ L,
        "q_c": tree["q_c"], "q_e": tree["q_e"],
        "M": s["M"], "k": s["k"], "q": s["q"],
        "L": L, "l": s["zd"] - L @ asm.zd[ind], "gamma": s["gamma"],
        "Phi": con["Phi"][:, 0], "Phi_y": con["Phi_z"], "Phi_t": con["Phi_t"][:, 0],
        "Phi_dot": s["Phi_dot"], "lambda": lam,
        "constraint_labels": list(ev.labels),
        "closure_residual": {"Phi": float(np.max(np.abs(s["Phi"]), initial=0.0)),
                             "Phi_dot": float(np.max(np.abs(s["Phi_dot"]), initial=0.0))},
        "orthogonality": float(np.max(np.abs(s["Phi_z"][list(ev.part.rows)] @ L),
                                      initial=0.0)),
    }
    try:
        r = closed_reactions(system, s, lam, tv, parameters, uv, tree)
        q0 = r.pop("_q_tree")
        out.update(r)
        out["joint_wrenches"] = joint_wrenches(tree_sys, r["g"][:q0], s["z"], s["zd"], tv,
                                               parameters)
    except JourdainError as exc:
        out["reactions_error"] = str(exc)
    pv = ev.p
    out["closing_wrenches"] = {
        k: {"F": v["F"][0], "T": v["T"][0]}
        for k, v in closing_reactions(system, s["z"][None, :], lam[None, :], np.array([tv]),
                                      pv).items()}
    return out


__all__ = ["closed_reactions", "closed_reactions_along", "evaluate_closed"]


def closed_reactions_along(system: System, res: Any) -> tuple[np.ndarray, list[str]]:
    """``g`` (N, q) and its names along a closed system's motion ``res``
    (:class:`jourdain.Results`): :func:`closed_reactions` at every sample, from the tree's
    numbers there."""
    tree_sys = system.tree
    n = len(res.t)
    names: list[str] = []
    rows: list[np.ndarray] = []
    params = dict(res.parameters)
    lam = res.multipliers
    for i in range(n):
        u = res.u[i] if res.u.shape[1] else np.zeros(0)
        tree = tree_evaluate(tree_sys, res.y[i], res.yd[i], float(res.t[i]), params,
                             list(u) if len(system.inputs) else None)
        s = {"z": res.y[i], "zd": res.yd[i], "zdd": res.ydd[i]}
        r = closed_reactions(system, s, lam[i], float(res.t[i]), params, u, tree)
        names = r["g_names"]
        rows.append(r["g"])
    q = len(names) if names else 0
    return (np.array(rows) if rows else np.zeros((0, q))), names
