"""Reaction forces in numbers (``docs/method.md`` §4): N̂, k̂, q̂ from the compiled M̄, Q̄, q̄^c,
q̄^e (:func:`projected_reactions`), the solution of ``N̂·g = k̂ − q̂`` bordered with the rows
without inertia, with undetermined components reported as NaN and by name (:func:`solve_g`),
the evaluation at one state (:func:`evaluate_reactions`) or for selected joints
(:func:`joint_reactions`), the joint wrenches with them (:func:`evaluate_keys`), and the check
of the assembled ``J̄ᵀ·Q̄ = 0`` in compiled code (:func:`check_orthogonality`,
:func:`check_reactions`).

Floor: analysis (above the numeric layer, whose compiled code it evaluates, and beside
:mod:`jourdain.wrenches`); the symbolic matrices are formed by :mod:`jourdain.stages.reactions`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING, Any

import numpy as np
import symengine as se

from ..errors import EvaluationError, JourdainError, ModelError, SingularMassMatrix
from ..model.bodies import WORLD
from ..numeric import _eom_function, lambdify, state_vectors
from ..numeric import evaluate as evaluate_eom
from ..stages.kinematics import kinematics
from ..stages.newton_euler import newton_euler
from ..stages.projection import projection  # the model has no stage methods (issue 16)
from ..stages.reactions.checks import _check_assembled, _checked_joints
from ..stages.reactions.formation import Reactions
from ..stages.reactions.joints import (
    JointReactions,
    Wrench,
    constrained_directions,
    joint_directions,
)
from ..stages.reactions.rows import _body_rows, _singular_rows
from ..stages.reactions.subtree import _subtree_parts
from ..symbolic import SymMatrix
from ..wrenches import joint_wrenches

if TYPE_CHECKING:
    from ..model.system import System


@dataclass(frozen=True)
class ReactionLayout:
    """What the numeric reactions need besides the compiled matrices: the joints with their
    constrained directions, the names of g, the rows of M̄ without inertia, and per body the
    columns of Q̄ that touch it (its joint's and its children's joints' directions)."""

    joints: tuple[JointReactions, ...]
    g_names: tuple[str, ...]
    singular_rows: tuple[int, ...]
    touching: tuple[tuple[int, ...], ...]


@lru_cache(maxsize=32)
def _reactions_function(system: System) -> tuple[ReactionLayout, Any]:
    """The compiled Newton–Euler matrices with Q̄ (:func:`jourdain.numeric.recursive`), after
    the joint-by-joint check and the check of the assembled J̄ᵀ·Q̄ = 0; ModelError when the
    model's reactions cannot be formed."""

    joints = joint_directions(system)
    _checked_joints(system)
    fn = _eom_function(system)
    index = _body_rows(system)
    touching: list[list[int]] = [list(jr.columns) for jr in joints]
    for b, jr in zip(system.bodies, joints, strict=True):
        if b.parent != WORLD:
            touching[index[b.parent]].extend(jr.columns)
    lay = ReactionLayout(joints, tuple(n for jr in joints for n in jr.names),
                         _singular_rows(system)[0], tuple(tuple(sorted(t)) for t in touching))
    _check_assembled(system, joints, fn)
    return lay, fn


def check_reactions(system: System) -> None:
    """The checks made before reaction forces are given in numbers: constrained directions
    that can be formed, the joint-by-joint and the assembled orthogonality ``J̄ᵀ·Q̄ = 0``;
    :class:`ModelError` naming the joint otherwise (no symbolic N̂ is formed)."""
    _reactions_function(system)


def projected_reactions(lay: ReactionLayout, M_bar: np.ndarray, Q_bar: np.ndarray,
                        q_c: np.ndarray, q_e: np.ndarray
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``N̂ = Q̄_rᵀM̄_r⁻¹Q̄_r``, ``k̂ = Q̄_rᵀM̄_r⁻¹q̄^c_r``, ``q̂ = Q̄_rᵀM̄_r⁻¹q̄^e_r`` in numbers over
    the regular rows r of M̄ (METHOD.md §4), for one state or a batch (leading axes).

    M̄ is block diagonal, so the products are formed body by body from the few columns of Q̄
    that touch each body (O(p) small products, never a 6p×6p solve); with the Cholesky factor
    C of each block, ``N̂ += (C⁻¹Q̄_b)ᵀ(C⁻¹Q̄_b)``, so N̂ is exactly symmetric.
    """
    require_finite("in the Newton–Euler equations", M_bar=M_bar, Q_bar=Q_bar, q_c=q_c, q_e=q_e)
    lead = Q_bar.shape[:-2]
    n6, q = Q_bar.shape[-2:]
    p = n6 // 6
    singular = set(lay.singular_rows)
    N = np.zeros((*lead, q, q))
    kh = np.zeros((*lead, q))
    qh = np.zeros((*lead, q))
    for i in range(p):
        cols = list(lay.touching[i])
        if not cols:
            continue
        _body_products(M_bar, Q_bar, q_c, q_e, i, cols, singular, (N, kh, qh))
    return 0.5 * (N + np.swapaxes(N, -1, -2)), kh, qh


def _body_products(M_bar: np.ndarray, Q_bar: np.ndarray, q_c: np.ndarray, q_e: np.ndarray,
                   i: int, cols: list[int], singular: set[int],
                   out: tuple[np.ndarray, np.ndarray, np.ndarray]) -> None:
    """Body ``i``'s terms of N̂, k̂, q̂ added to ``out`` (inf where they overflow, without a
    warning: :func:`require_finite` names them before N̂ is factorized)."""
    N, kh, qh = out
    p = Q_bar.shape[-2] // 6
    with np.errstate(over="ignore", invalid="ignore"):
        for base in (3 * i, 3 * p + 3 * i):
            rows = [base + a for a in range(3) if base + a not in singular]
            if not rows:
                continue
            Mb = M_bar[..., rows, :][..., :, rows]
            C = np.linalg.cholesky(Mb)
            B = np.linalg.solve(C, Q_bar[..., rows, :][..., :, cols])
            bc = np.linalg.solve(C, q_c[..., rows, None])[..., 0]
            be = np.linalg.solve(C, q_e[..., rows, None])[..., 0]
            ix = np.ix_(cols, cols)
            N[..., ix[0], ix[1]] += np.swapaxes(B, -1, -2) @ B
            kh[..., cols] += np.einsum("...rc,...r->...c", B, bc)
            qh[..., cols] += np.einsum("...rc,...r->...c", B, be)


def require_finite(what: str, **arrays: np.ndarray) -> None:
    """An :class:`EvaluationError` naming the arrays that hold inf or NaN: checked before
    every factorization (LAPACK's SVD of a matrix holding inf may loop without end, deaf to
    Ctrl-C, or fail with a LinAlgError)."""
    bad = [k for k, v in arrays.items() if not np.isfinite(v).all()]
    if bad:
        raise EvaluationError(f"{', '.join(bad)} contain{'s' if len(bad) == 1 else ''} NaN or "
                              f"inf {what} (numbers beyond the floating-point range: check the "
                              "magnitudes of the masses, inertias, lengths and forces)")


def solve_g(Q_bar: np.ndarray, N_hat: np.ndarray, k_hat: np.ndarray, q_hat: np.ndarray,
            q_c: np.ndarray, q_e: np.ndarray, singular_rows: Sequence[int],
            names: Sequence[str] = ()) -> tuple[np.ndarray, list[str]]:
    """Solve ``N̂·g = k̂ − q̂`` (Cholesky; N̂ symmetric positive definite), or with rows of
    bodies without inertia the bordered system of the module docstring.

    Returns ``g`` (NaN where undetermined) and the names of the undetermined components.
    """
    q = N_hat.shape[0]
    with np.errstate(over="ignore", invalid="ignore"):
        rhs = k_hat - q_hat
    require_finite("in the reaction equations at this state", N_hat=N_hat, k_hat_minus_q_hat=rhs,
                   Q_bar=Q_bar, q_c=q_c, q_e=q_e)
    s = list(singular_rows)
    if not s:
        try:
            C = np.linalg.cholesky(N_hat)
            return np.linalg.solve(C.T, np.linalg.solve(C, rhs)), []
        except np.linalg.LinAlgError:
            pass  # not positive definite: redundant directions; the general path says which
    Qs = Q_bar[s, :]
    K = np.block([[N_hat, Qs.T], [Qs, np.zeros((len(s), len(s)))]])
    b = np.concatenate([rhs, q_c[s] - q_e[s]])
    U, sv, Vt = np.linalg.svd(K)
    tol = max(K.shape) * np.finfo(float).eps * (sv[0] if sv.size else 0.0) * 1e3
    rank = int((sv > tol).sum())
    x = Vt[:rank].T @ ((U[:, :rank].T @ b) / sv[:rank])
    resid = np.abs(K @ x - b).max()
    if resid > 1e-8 * max(1.0, np.abs(b).max(), np.abs(K).max() * np.abs(x).max()):
        raise EvaluationError(
            "the reaction equations have no solution at this state: applied or gyroscopic loads "
            "on rows without inertia that no joint can balance (rows "
            f"{[s[i - q] for i in range(q, q + len(s)) if abs((K @ x - b)[i]) > 1e-8]})"
        )
    g = x[:q].copy()
    null = Vt[rank:, :q]
    und = np.nonzero(np.abs(null).max(axis=0) > 1e-8)[0] if null.size else np.array([], int)
    g[und] = np.nan
    return g, [names[i] for i in und] if names else [str(i) for i in und]


def reactions_along(lay: ReactionLayout, M_bar: np.ndarray, Q_bar: np.ndarray,
                    q_c: np.ndarray, q_e: np.ndarray) -> np.ndarray:
    """``g`` (N, q) from ``N̂·g = k̂ − q̂`` at N states at once (leading axis N of ``M_bar``,
    ``Q_bar``, ``q_c``, ``q_e``): one batched solve, or state by state (:func:`solve_g`) where
    bodies without inertia or redundant directions need the bordered system."""
    N, kh, qh = projected_reactions(lay, M_bar, Q_bar, q_c, q_e)
    require_finite("along the motion", N_hat=N, k_hat=kh, q_hat=qh)
    if not lay.singular_rows:  # N̂ g = k̂ − q̂ for all states in one batched solve
        try:
            return np.linalg.solve(N, (kh - qh)[:, :, None])[:, :, 0]
        except np.linalg.LinAlgError:
            pass
    g = np.empty((N.shape[0], N.shape[1]))
    for i in range(N.shape[0]):
        g[i], _ = solve_g(Q_bar[i], N[i], kh[i], qh[i], q_c[i], q_e[i], lay.singular_rows,
                          lay.g_names)
    return g


def _refuse_friction(system: Any) -> None:
    """Friction that depends on the reactions couples them with ÿ: these functions of the
    plain equations would leave it out without a word."""
    frictions = getattr(system, "frictions", ())
    if frictions:
        raise EvaluationError(
            f"{getattr(system, 'name', 'the system')!r} has joint friction "
            f"({', '.join(f.name for f in frictions)}) that depends on the reactions: its "
            "reactions are solved with the equations of motion by system.evaluate")


def evaluate_reactions(system: System, y: Any, yd: Any, t: float = 0.0,
                       parameters: Mapping[str, float] | None = None,
                       inputs: Mapping[str, float] | Sequence[float] | None = None,
                       eom: Mapping[str, np.ndarray] | None = None) -> dict[str, Any]:
    """Reaction forces at one state ``y, ẏ, t`` (no ÿ needed).

    Returns a dict with ``Q_bar`` (6p×q), ``N_hat`` (q×q), ``k_hat``, ``q_hat``, ``g`` (q,
    NaN where undetermined), ``g_names`` (list of str) and ``g_undetermined`` (list of the names
    of undetermined components; empty for a well-posed model). ``eom``: the output of
    :func:`jourdain.numeric.evaluate` at the same state, if already at hand.
    """
    _refuse_friction(system)

    lay, _ = _reactions_function(system)
    if eom is None or "Q_bar" not in eom:
        eom = evaluate_eom(system, y, yd, t=t, parameters=parameters, inputs=inputs)
    Q = np.asarray(eom["Q_bar"])
    qc, qe = np.asarray(eom["q_c"]).reshape(-1), np.asarray(eom["q_e"]).reshape(-1)
    N, kh, qh = projected_reactions(lay, np.asarray(eom["M_bar"]), Q, qc, qe)
    # NaN marks undetermined components only; anything else not finite is an error, found
    # before N̂ is factorized
    bad = [k for k, v in (("N_hat", N), ("k_hat", kh), ("q_hat", qh)) if not np.isfinite(v).all()]
    if not bad:
        g, und = solve_g(Q, N, kh, qh, qc, qe, lay.singular_rows, lay.g_names)
    else:
        g, und = np.full(len(lay.g_names), np.nan), []
    determined = [i for i, n in enumerate(lay.g_names) if n not in und]
    if not np.isfinite(g[determined]).all():
        bad.append("g")
    if bad:
        raise EvaluationError(f"{', '.join(bad)} of {system.name!r} contain NaN or inf at this "
                              "state (the reaction equations are not solvable in floating point "
                              "here)")
    return {"Q_bar": Q, "N_hat": N, "k_hat": kh, "q_hat": qh, "g": g,
            "g_names": list(lay.g_names), "g_undetermined": und}


@lru_cache(maxsize=64)
def _joint_function(system: System, joints: tuple[str, ...]) -> tuple[list, Any]:
    """Compiled M, k, q and, per joint, ``Eᵀ·W0``, ``Eᵀ·W_y`` and ``EᵀE`` (E: its constrained
    directions), so that ``EᵀE·g_j = Eᵀ·(W0 + W_y·ÿ)``."""

    eom = projection(newton_euler(kinematics(system)))
    ne = eom.newton_euler
    by_joint = {b.joint.name: b for b in system.bodies}
    params = system.parameter_values
    mats: dict[str, SymMatrix] = {"M": eom.M, "k": eom.k, "q": eom.q}
    info = []
    for k, name in enumerate(joints):
        body = by_joint[name]
        dirs = constrained_directions(body.joint, system.coordinates, params)
        info.append((name, [sfx for sfx, _ in dirs]))
        if not dirs:
            continue
        W0, Wy = _subtree_parts(ne, body.name)

        def dot(w: Wrench, v: Wrench) -> se.Basic:
            return se.Add(*(x * y for x, y in zip(w, v, strict=True) if x != 0 and y != 0))

        mats[f"G0_{k}"] = SymMatrix.column([dot(w, W0) for _, w in dirs])
        mats[f"Gy_{k}"] = SymMatrix.from_rows([[dot(w, Wj) for Wj in Wy] for _, w in dirs])
        mats[f"EE_{k}"] = SymMatrix.from_rows([[dot(w, v) for _, v in dirs] for _, w in dirs])
    return info, lambdify(system, mats)


def joint_reactions(system: System, joints: str | Sequence[str], y: Any, yd: Any,
                    t: float = 0.0, parameters: Mapping[str, float] | None = None,
                    inputs: Mapping[str, float] | Sequence[float] | None = None
                    ) -> dict[str, float]:
    """Reaction components of the named joints only, without forming ``N̂`` or all of ``g``.

    ÿ comes from the equations of motion; the residual ``M̄·J̄·ÿ + q̄^c − q̄^e`` of the sub-tree
    each joint carries, moved to the joint point and the child frame, is the wrench ``W`` the
    joint transmits, and ``EᵀE·g_j = Eᵀ·W`` gives its components along the joint's constrained
    directions ``E``. Compiled once per system and set of joints (``M, k, q`` and, per joint,
    ``Eᵀ·W`` split into its part without ÿ and its coefficients of ÿ).

    Returns ``{"<joint>.<direction>": value}``; directions that others of the same joint repeat
    share their force and come back as NaN (undetermined).
    """
    _refuse_friction(system)

    if isinstance(joints, str):
        joints = [joints]
    by_joint = {b.joint.name: b for b in system.bodies}
    for name in joints:
        if name not in by_joint:
            raise ModelError(f'unknown joint "{name}"; joints are: {", ".join(by_joint)}')
    args = state_vectors(system, y, yd, t, parameters, inputs)
    info, fn = _joint_function(system, tuple(joints))
    return joint_components(info, fn(*args))


def joint_components(info: list, out_: Mapping[str, np.ndarray], where: str = "at this state"
                     ) -> dict[str, float]:
    """The reaction components of :func:`joint_reactions` from the numbers of
    :func:`_joint_function` at one state (``info`` and the compiled function's output; a
    batch's one row), ``where`` naming the state in the errors."""
    require_finite(where, **{k: np.asarray(v, float) for k, v in out_.items()})
    try:
        ydd = np.linalg.solve(np.atleast_2d(out_["M"]), (out_["q"] - out_["k"]).reshape(-1))
    except np.linalg.LinAlgError:
        raise SingularMassMatrix(f"the mass matrix M is singular {where}") from None
    out: dict[str, float] = {}
    for k, (name, suffixes) in enumerate(info):
        if not suffixes:
            continue
        with np.errstate(over="ignore", invalid="ignore"):
            rhs = out_[f"G0_{k}"].reshape(-1) + out_[f"Gy_{k}"] @ ydd
        EE = out_[f"EE_{k}"]
        require_finite(f'in the reactions of joint "{name}"', ydd=ydd, rhs=rhs)
        gj, *_ = np.linalg.lstsq(EE, rhs, rcond=None)
        # directions that the others repeat (a rank-deficient Gram matrix) share their force
        _, sv, Vt = np.linalg.svd(EE)
        null = Vt[int((sv > 1e-10 * sv[0]).sum()):]
        if null.size:
            gj[np.abs(null).max(axis=0) > 1e-8] = np.nan
        for sfx, v in zip(suffixes, gj, strict=True):
            out[f"{name}.{sfx}"] = float(v)
    return out


def evaluate_keys(system: System, y: Any, yd: Any, t: float, parameters: Any, inputs: Any,
                  eom: Mapping[str, np.ndarray]) -> dict[str, Any]:
    """The reaction entries of :meth:`System.evaluate`: ``Q_bar, N_hat, k_hat, q_hat, g,
    g_names, g_undetermined`` and ``joint_wrenches`` (``{joint: JointWrench}``: force and
    torque vectors in the joint frame and the inertial frame, :mod:`jourdain.wrenches`).

    A model whose reactions cannot be formed (a joint moved by another joint's coordinate, a
    symbolic joint axis, constrained directions that do work), or a state where they have no
    solution (a load on a body without inertia that nothing balances), still has equations of
    motion: then the only entry is ``reactions_error``, the message that
    :func:`evaluate_reactions` raises, so that no reaction numbers appear for it.
    """
    try:
        _reactions_function(system)
        out = evaluate_reactions(system, y, yd, t, parameters, inputs, eom=eom)
    except JourdainError as exc:
        return {"reactions_error": str(exc)}

    out["joint_wrenches"] = joint_wrenches(system, out["g"], y, yd, t, parameters)
    return out


def check_orthogonality(r: Reactions, samples: int = 3, seed: int = 7, fn: Any = None) -> float:
    """The orthogonality relation ``J̄ᵀ·Q̄ = 0`` of the assembled symbolic matrices of ``r``,
    checked with J̄ and Q̄ compiled (``fn``: a compiled function giving ``J_bar`` and ``Q_bar``,
    compiled here from ``r`` when not given) at random states (coordinates in (−π, π), t in
    (0, 2), parameters within 10 % of their defaults), and that ``[J̄, Q̄]`` is square and
    regular (no reaction missing). :meth:`jourdain.System.evaluate` checks its own numeric Q̄
    the same way before it gives reaction forces.

    Returns the largest relative residual ``|J̄ᵀQ̄| / (|J̄|ᵀ|Q̄|)`` over the columns; raises
    :class:`ModelError` naming the joint and the direction of a column that does work.
    """
    system = r.system
    if fn is None:
        fn = lambdify(system, {"J_bar": r.newton_euler.J_bar, "Q_bar": r.Q_bar})
    return _check_assembled(system, r.joints, fn, samples, seed)
