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

from ..analysis.reactions import (
    ReactionLayout,
    _reactions_function,
    projected_reactions,
    reactions_along,
    solve_g,
)
from ..errors import EvaluationError, JourdainError
from ..model import System
from ..numeric import CompiledFunction, lambdify, state_vectors
from ..numeric import evaluate as tree_evaluate
from ..symbolic import SymMatrix
from ..wrenches import joint_wrenches
from .closed_loop import LoopEvaluator, constraints
from .reactions import closing_reactions


@lru_cache(maxsize=16)
def _closing_columns(system: System) -> tuple[ReactionLayout, int, CompiledFunction | None]:
    """The layout of the closed system's reactions (the tree's, extended by the closing rows
    with a direction in the bodies: not ``generic``), the number of the tree's columns, and
    Q̄_c of those rows compiled in the tree's arguments (None where there is none)."""
    con = constraints(system)
    lay, _ = _reactions_function(system.tree)
    keep = [i for i, r in enumerate(con.rows) if r.kind != "generic"]
    q0 = len(lay.g_names)
    names = [b.name for b in system.bodies]
    touching = [list(c) for c in lay.touching]
    for j, i in enumerate(keep):
        for body in (con.rows[i].body_a, con.rows[i].body_b):
            if body != "world":
                touching[names.index(body)].append(q0 + j)
    lay_c = replace(lay, touching=tuple(tuple(sorted(set(c))) for c in touching),
                    g_names=(*lay.g_names, *(con.rows[i].label for i in keep)))
    if not keep:
        return lay_c, q0, None
    cols = SymMatrix.from_rows([[row[i] for i in keep] for row in con.Q_bar.rows])
    return lay_c, q0, lambdify(system.tree, {"Q_c": cols})


def _closed_matrices(system: System, tree: Mapping[str, np.ndarray], Qc: np.ndarray | None,
                     zdd: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``Q̄ = [Q̄_tree, Q̄_c]`` and the q̄^c, q̄^e for ``N̂·g = k̂ − q̂`` of the closed system, at
    one state or a batch (leading axis): ``k̂ = Q̄ᵀ(J̄_tree·ÿ + M̄⁻¹q̄^c) = Q̄ᵀM̄⁻¹(M̄·J̄_tree·ÿ +
    q̄^c)``, since J̄_treeᵀQ̄_tree = 0 but the closing columns see the tree's accelerations
    (Q̄_cᵀJ̄_tree·ÿ = Φ_y·ÿ = −c)."""
    Qt = np.asarray(tree["Q_bar"])
    Q = Qt if Qc is None else np.concatenate([Qt, Qc.reshape(*Qt.shape[:-1], -1)], axis=-1)
    M_bar = np.asarray(tree["M_bar"])
    qc = np.asarray(tree["q_c"]).reshape(*Qt.shape[:-2], -1)
    qe = np.asarray(tree["q_e"]).reshape(*Qt.shape[:-2], -1)
    a = np.einsum("...rc,...c->...r", np.asarray(tree["J_bar"]), zdd)
    return Q, qc + np.einsum("...rc,...c->...r", M_bar, a), qe


def closed_reactions(system: System, s: Mapping[str, Any], t: float,
                     parameters: Mapping[str, float] | None, u: np.ndarray,
                     tree: Mapping[str, np.ndarray]) -> dict[str, Any]:
    """Q̄, N̂, k̂, q̂ and g of the closed system at the assembled state ``s`` (see the module
    docstring); ``tree``: the tree's M̄, q̄^c, q̄^e, Q̄, J̄ there."""
    lay_c, q0, fn = _closing_columns(system)
    Qc = None
    if fn is not None:
        args = state_vectors(system.tree, s["z"], s["zd"], t, parameters,
                             list(u) if len(system.inputs) else None)
        Qc = np.asarray(fn(*args)["Q_c"])
    Q, qc_eff, qe = _closed_matrices(system, tree, Qc, s["zdd"])
    N, kh, qh = projected_reactions(lay_c, np.asarray(tree["M_bar"]), Q, qc_eff, qe)
    g, und = solve_g(Q, N, kh, qh, qc_eff, qe, lay_c.singular_rows, lay_c.g_names)
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
        r = closed_reactions(system, s, tv, parameters, uv, tree)
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


def closed_reactions_along(system: System, res: Any) -> tuple[np.ndarray, list[str]]:
    """``g`` (N, q) and its names along a closed system's motion ``res``
    (:class:`jourdain.Results`): the tree's compiled numbers for all samples in one call, the
    closing columns likewise, and one batched solve (:func:`reactions_along`), as for a
    tree's motion."""
    lay_c, _, fn_c = _closing_columns(system)
    _, fn = _reactions_function(system.tree)
    p = np.array([res.parameters[k] for k, _ in system.parameters])
    U = res.u if res.u.shape[1] else None
    tree = fn.batch(res.y, res.yd, res.t, p, U)
    Qc = None if fn_c is None else fn_c.batch(res.y, res.yd, res.t, p, U)["Q_c"]
    Q, qc_eff, qe = _closed_matrices(system, tree, Qc, res.ydd)
    return reactions_along(lay_c, np.asarray(tree["M_bar"]), Q, qc_eff, qe), list(lay_c.g_names)


__all__ = ["closed_reactions", "closed_reactions_along", "evaluate_closed"]
