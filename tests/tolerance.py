"""Tolerances derived from the problem instead of fixed numbers (rules: tests/README.md).

Floating-point results differ between CPUs, BLAS builds and thread counts by rounding, and how
far depends on the problem. A quantity evaluated directly (sums of products) is accurate to a
few ``eps`` of the magnitude of the terms it is summed from; a quantity that comes out of a
linear solve ``A·x = b`` is accurate only to about ``cond(A)·eps`` relative to its scale. A
fixed ``1e-10`` is too loose for a well-conditioned 2×2 system and too tight for a mass matrix
with ``cond(M) ≈ 1e8`` (``1e8·2.2e-16 ≈ 2e-8``). The helpers compute the bound from the
matrices at hand, so it is tight where the problem is well-conditioned and wider only where the
problem itself loses digits.

Norms are 2-norms (spectral norms for matrices). The assertions compare the largest absolute
difference, which is never larger than the 2-norm, so each bound holds as stated.

Safety constants: every rule is ``c · n · eps · (problem-derived scale)`` with ``n`` the order
of the matrix or the number of summed terms. Rounding-error analysis (Higham, *Accuracy and
Stability of Numerical Algorithms*, 2nd ed., §3.1, §7.1, §9.3, §10.1) bounds a sum of ``n``
terms by ``γ_n ≈ n·eps`` times the sum of their magnitudes, and the backward error of Cholesky
or partially pivoted LU by a low-degree polynomial in ``n`` times ``eps`` (times LU's pivot
growth, small in practice). The worst-case polynomials (``n²``, ``n³``) are not attained in
practice (errors grow like ``√n`` to ``n``), so the rules use ``n``; ``c = 10`` covers that
matrices and right-hand sides carry evaluation errors of a few ``eps`` from the generated code
before the solve, and that another tool (Pinocchio, sympy, PyDy) rounds differently. Measured
on a few hundred random states of the suite's models (table in tests/README.md), the largest
error stays between 1/40 and 1/3000 of its bound (the solve rules are worst cases: they assume
the rounding lines up with the worst-conditioned direction). At well-conditioned states the
bounds are 1e-13..1e-10 relative, and a relative change of 1e-8 in g, M or q̄^c makes the
tests that check that quantity fail.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from functools import lru_cache
from typing import Any

import numpy as np

EPS = float(np.finfo(float).eps)
#: safety constant of the forward-error rules (:func:`solve_tol`, :func:`gram_solve_tol`)
C_SOLVE = 10.0
#: safety constant of the backward-error (residual) rule (:func:`residual_bound`)
C_RESIDUAL = 10.0
#: safety constant of the evaluation rule (:func:`eval_tol`)
C_EVAL = 10.0
#: singular values below this fraction of the largest count as zero in :func:`cond` with
#: ``rank_revealing`` (the minimum-norm solve of a rank-deficient system)
RANK_RTOL = 1e-8


# --- generic rules --------------------------------------------------------------------------
def norm(a: object) -> float:
    """2-norm of a vector, spectral norm of a matrix (0 for an empty array)."""
    a = np.asarray(a, dtype=float)
    if a.size == 0:
        return 0.0
    if a.ndim == 2 and min(a.shape) > 1:
        return float(np.linalg.norm(a, 2))
    return float(np.linalg.norm(a.ravel()))


def cond(A: object, rank_revealing: bool = False) -> float:
    """2-norm condition number ``σ_max/σ_min`` of a square matrix (``inf`` if singular).

    ``rank_revealing``: ``σ_max/σ_r`` over the singular values above ``RANK_RTOL·σ_max``, the
    condition number of a minimum-norm (truncated SVD) solve of a rank-deficient system.
    """
    a = np.atleast_2d(np.asarray(A, dtype=float))
    if a.size == 0:
        return 1.0  # no equations (a model without constrained directions): nothing amplified
    sv = np.linalg.svd(a, compute_uv=False)
    if rank_revealing:
        sv = sv[sv > RANK_RTOL * sv[0]]
    return float(sv[0] / sv[-1]) if sv[-1] > 0 else float("inf")


def solve_scale(A: object, x: object, b_terms: Iterable[object] = ()) -> float:
    """The scale of a solution ``x = A⁻¹·b``: ``‖x‖ + Σ‖t‖/‖A‖`` over the terms ``t`` that ``b``
    was summed from.

    Perturbation theory (Higham, Thm. 7.2): errors ``δA``, ``δb`` give
    ``‖δx‖ ≤ ‖A⁻¹‖·(‖δA‖·‖x‖ + ‖δb‖) = cond(A)·(‖δA‖/‖A‖·‖x‖ + ‖δb‖/‖A‖)``, and ``δb`` is a
    few ``eps`` of the terms ``b`` is summed from, not of ``b``: ``q − k`` can cancel to a small
    number while ``q`` and ``k`` are large. So pass the terms (``(q, k)``, or better the
    magnitudes of what ``q`` and ``k`` are summed from, :func:`eom_terms`), not ``q − k``.
    """
    return norm(x) + sum(norm(t) for t in b_terms) / max(norm(A), np.finfo(float).tiny)


def solve_tol(A: object, scale: float | None = None, c: float = C_SOLVE,
              rank_revealing: bool = False) -> float:
    """Forward-error tolerance for a quantity obtained from a linear solve with ``A``:
    ``c · n · cond(A) · eps · scale``, ``n`` the order of ``A``.

    ``scale``: the magnitude the error is relative to; for ``x = A⁻¹·b`` itself
    :func:`solve_scale` (``≥ ‖x‖``), for a linear image ``L·x`` of the solution
    ``‖L‖·solve_scale(...)``. ``None``: scale 1, the relative tolerance.
    """
    n = np.atleast_2d(np.asarray(A)).shape[0]
    s = 1.0 if scale is None else float(scale)
    return c * n * cond(A, rank_revealing) * EPS * s


def gram_solve_tol(A: object, w_norm: float, scale: float | None = None,
                   c: float = C_SOLVE) -> float:
    """Tolerance for the image ``W·B·x`` (or ``B·x``) of a solution ``x = A⁻¹·b`` when ``A`` is
    a Gram matrix ``A = BᵀWB`` (or ``A = BᵀW⁻¹B``), ``W`` symmetric positive semi-definite,
    ``w_norm = ‖W‖``: ``c · n · eps · √(‖W‖·‖A‖·cond(A)) · scale``, ``scale`` the
    :func:`solve_scale` of ``x``.

    This is ``M = J̄ᵀM̄J̄`` (ÿ mapped to forces by ``M̄·J̄``) and ``N̂ = Q̄ᵀM̄⁻¹Q̄`` (g mapped to
    forces by ``Q̄``), ``W = M̄``. The computed ``x`` solves ``A·x = b + ρ`` with
    ``‖ρ‖ ≤ c·n·eps·‖A‖·scale`` (backward error plus the evaluation errors of ``A`` and ``b``),
    so the image is off by ``W·B·A⁻¹·ρ``; since ``W^½·B·A^-½`` has orthonormal columns,
    ``‖W·B·A⁻¹‖ = ‖W^½·(W^½·B·A^-½)·A^-½‖ ≤ √(‖W‖·‖A⁻¹‖)`` (the same for ``B·A⁻¹`` when
    ``A = BᵀW⁻¹B``). The error of ``x`` is large along the eigenvectors of the small
    eigenvalues of ``A``, and exactly those ``W·B`` maps to small forces: the forces are
    accurate to ``√cond(A)·eps``, not ``cond(A)·eps``.
    """
    A = np.atleast_2d(np.asarray(A, dtype=float))
    s = 1.0 if scale is None else float(scale)
    return c * A.shape[0] * EPS * float(np.sqrt(float(w_norm) * norm(A) * cond(A))) * s


def residual_bound(A: object, x: object, b: object, b_scale: float | None = None,
                   c: float = C_RESIDUAL) -> float:
    """Normwise backward-error bound of a computed solution of ``A·x = b`` (Higham, Thm. 7.1,
    Rigal–Gaches): ``c · n · eps · (‖A‖·‖x‖ + ‖b‖)``.

    A backward-stable solver (Cholesky, LU with partial pivoting, QR, SVD) returns an ``x``
    that exactly solves a system within a few ``eps`` of ``A``, ``b``, whatever ``cond(A)`` is,
    so this needs no condition number. ``b_scale`` replaces ``‖b‖`` by the magnitude of the
    terms ``b`` was summed from when ``A`` and ``b`` were evaluated again (another compiled
    path, another tool) rather than being the very arrays that were solved.
    """
    A = np.atleast_2d(np.asarray(A, dtype=float))
    bs = norm(b) if b_scale is None else float(b_scale)
    return c * A.shape[0] * EPS * (norm(A) * norm(x) + bs)


def assert_residual_small(A: object, x: object, b: object, b_scale: float | None = None,
                          c: float = C_RESIDUAL, err_msg: str = "") -> None:
    """``max|A·x − b| ≤`` :func:`residual_bound`."""
    A = np.atleast_2d(np.asarray(A, dtype=float))
    x, b = np.asarray(x, dtype=float), np.asarray(b, dtype=float)
    r = float(np.abs(A @ x - b).max(initial=0.0))
    bound = residual_bound(A, x, b, b_scale, c)
    assert r <= bound, f"{err_msg} residual {r:.3e} > {bound:.3e} (backward-error bound)"


def assert_close_solved(ours: object, ref: object, A: object | Sequence[object],
                        scale: float | None = None, c: float = C_SOLVE,
                        err_msg: str = "") -> None:
    """Two independently solved results agree: ``max|ours − ref| ≤ Σ_A solve_tol(A, scale)``.

    ``A``: the matrix of the solve, or a list of the matrices of all solves that either side
    went through (each adds its bound; list the same matrix twice when both sides solved with
    it). ``scale`` defaults to ``‖ref‖``; pass :func:`solve_scale` when the right-hand side
    cancels.
    """
    mats = list(A) if isinstance(A, list | tuple) else [A]
    ours, ref = np.asarray(ours, dtype=float), np.asarray(ref, dtype=float)
    s = norm(ref) if scale is None else float(scale)
    tol = sum(solve_tol(M, s, c) for M in mats)
    d = float(np.abs(ours - ref).max(initial=0.0))
    assert d <= tol, (f"{err_msg} max difference {d:.3e} > {tol:.3e} (cond "
                      f"{', '.join(f'{cond(M):.2e}' for M in mats)}, scale {s:.3e})")


def eval_tol(n_terms: int, scale: float, c: float = C_EVAL) -> float:
    """Tolerance for a quantity evaluated directly (sums of products, no solve):
    ``c · n_terms · eps · scale``.

    ``scale`` is the magnitude of the summed terms, not of the result (a sum that cancels keeps
    the absolute error of its terms), e.g. the largest entry of ``|J̄|ᵀ|M̄||J̄|`` for
    ``M = J̄ᵀM̄J̄``; ``n_terms`` the number of terms summed into one entry (6p for a projection
    over p bodies). The products inside each term add a few ``eps`` each, covered by ``c``.
    """
    return c * max(int(n_terms), 1) * EPS * float(scale)


def assert_close_eval(ours: object, ref: object, n_terms: int, scale: float | None = None,
                      c: float = C_EVAL, err_msg: str = "") -> None:
    """``max|ours − ref| ≤ eval_tol(n_terms, scale)``; ``scale`` by default ``max|ref|``."""
    ours, ref = np.asarray(ours, dtype=float), np.asarray(ref, dtype=float)
    s = float(np.abs(ref).max(initial=0.0)) if scale is None else float(scale)
    tol = eval_tol(n_terms, s, c)
    d = float(np.abs(ours - ref).max(initial=0.0))
    assert d <= tol, f"{err_msg} max difference {d:.3e} > {tol:.3e} ({n_terms} terms, scale {s:.3e})"


def eig_with_tol(A: object, dA: float, c: float = C_SOLVE) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues of ``A`` and, for each, how far the eigenvalues of a matrix ``dA`` away
    (2-norm) may lie: ``κ_i·(dA + c·n·eps·‖A‖)`` with ``κ_i = ‖y_i‖·‖x_i‖/|y_iᴴx_i|`` the
    condition number of the eigenvalue (left and right eigenvectors ``y_i``, ``x_i``; first
    order, Wilkinson). The second term is the backward error of the eigensolver; an
    eigenvalue can be ill-conditioned (non-normal ``A``) however well-conditioned ``A`` is.
    Returns ``(eigenvalues, tolerances)`` sorted by real, then imaginary part.
    """
    import scipy.linalg as sla

    A = np.asarray(A, dtype=float)
    lam, yl, xr = sla.eig(A, left=True, right=True)
    kappa = (np.linalg.norm(yl, axis=0) * np.linalg.norm(xr, axis=0)
             / np.abs(np.sum(yl.conj() * xr, axis=0)))
    order = np.lexsort((lam.imag, lam.real))
    return lam[order], (kappa * (float(dA) + c * A.shape[0] * EPS * norm(A)))[order]


# --- the quantities of the method (METHOD.md) ------------------------------------------------
def state_space_eig_tol(ss: Any) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues of a :class:`~jourdain.StateSpace` ``A`` and their tolerances
    (:func:`eig_with_tol`), ``A``'s own error being its lower blocks' ``−M̃⁻¹·[Q, P]``
    forward-error bound ``solve_tol(M̃, solve_scale(M̃, A_lower, (Q, P)))``."""
    f = np.shape(ss.M_tilde)[0]
    dA = solve_tol(ss.M_tilde, solve_scale(ss.M_tilde, ss.A[f:], (ss.Q, ss.P)))
    return eig_with_tol(ss.A, dA)


def eom_terms(out: Mapping[str, Any]) -> tuple[np.ndarray, np.ndarray]:
    """Magnitudes of the terms ``k = J̄ᵀq̄^c`` and ``q = J̄ᵀq̄^e`` are summed from:
    ``|J̄|ᵀ|q̄^c|`` and ``|J̄|ᵀ|q̄^e|`` (the ``b_terms`` of ``M·ÿ = q − k``)."""
    aJ = np.abs(np.asarray(out["J_bar"], dtype=float))
    return (aJ.T @ np.abs(np.ravel(out["q_c"])), aJ.T @ np.abs(np.ravel(out["q_e"])))


def ydd_of(out: Mapping[str, Any]) -> np.ndarray:
    """ÿ from ``M·ÿ = q − k`` (LU with partial pivoting)."""
    return np.linalg.solve(np.atleast_2d(out["M"]), np.ravel(out["q"]) - np.ravel(out["k"]))


def ydd_tol(out: Mapping[str, Any], ydd: object) -> float:
    """Forward-error tolerance for ÿ: ``solve_tol(M, solve_scale(M, ÿ, eom_terms))``."""
    return solve_tol(out["M"], solve_scale(out["M"], ydd, eom_terms(out)))


def reaction_system(out: Mapping[str, Any]) -> tuple[np.ndarray, tuple[np.ndarray, ...]]:
    """The matrix that ``g`` is solved with and the terms of its right-hand side: ``N̂`` and
    ``(k̂, q̂)``, or, with rows of bodies without inertia (zero rows of M̄, indices ``s``), the
    bordered matrix ``[[N̂, Q̄_sᵀ], [Q̄_s, 0]]`` of reactions.py and ``(k̂, q̂, q̄^c_s, q̄^e_s)``."""
    N = np.atleast_2d(np.asarray(out["N_hat"], dtype=float))
    terms: tuple[np.ndarray, ...] = (np.ravel(out["k_hat"]), np.ravel(out["q_hat"]))
    s = np.flatnonzero(np.all(np.asarray(out["M_bar"]) == 0, axis=1))
    if not s.size:
        return N, terms
    Qs = np.asarray(out["Q_bar"], dtype=float)[s, :]
    K = np.block([[N, Qs.T], [Qs, np.zeros((s.size, s.size))]])
    return K, (*terms, np.ravel(out["q_c"])[s], np.ravel(out["q_e"])[s])


def reactions_tol(out: Mapping[str, Any]) -> float:
    """Forward-error tolerance for ``g`` of :meth:`System.evaluate` (largest absolute error of
    a determined component): ``solve_tol`` of the :func:`reaction_system` with
    ``solve_scale(K, g, terms)``. With undetermined components (redundant directions, a
    rank-deficient system solved with minimum norm) the rank-revealing condition number."""
    K, terms = reaction_system(out)
    g = np.nan_to_num(np.asarray(out["g"], dtype=float))
    return solve_tol(K, solve_scale(K, g, terms), rank_revealing=bool(out["g_undetermined"]))


def newton_euler_tol(out: Mapping[str, Any], ydd: object) -> float:
    """Tolerance for the Newton–Euler residual ``M̄·J̄·ÿ + q̄^c − q̄^e − Q̄·g`` (2-norm, so also
    its largest entry) at one state; ``out`` is :meth:`System.evaluate`'s dict, ``ydd`` the
    solution of ``M·ÿ = q − k``.

    The residual is the error of ÿ mapped to forces by ``M̄·J̄``, the error of ``g`` mapped by
    ``Q̄`` (both :func:`gram_solve_tol`, ``W = M̄``), and the evaluation error of the four
    summed terms (:func:`eval_tol`, ``6p`` terms)::

        gram_solve_tol(M, ‖M̄‖, solve_scale(M, ÿ, eom_terms))
        + gram_solve_tol(N̂, ‖M̄‖, solve_scale(N̂, g, (k̂, q̂)))
        + eval_tol(6p, ‖M̄J̄ÿ‖ + ‖q̄^c‖ + ‖q̄^e‖ + ‖Q̄g‖)

    With rows of bodies without inertia ``g`` comes from the bordered system
    (:func:`reaction_system`), no Gram matrix, and with undetermined components from a
    minimum-norm solve: then ``‖Q̄‖·reactions_tol(out)`` replaces the second term.
    """
    Mb = np.asarray(out["M_bar"], dtype=float)
    MJ = Mb @ np.asarray(out["J_bar"], dtype=float)
    M, Q = np.atleast_2d(out["M"]), np.asarray(out["Q_bar"], dtype=float)
    g = np.nan_to_num(np.asarray(out["g"], dtype=float))
    ydd = np.asarray(ydd, dtype=float)
    tol = gram_solve_tol(M, norm(Mb), solve_scale(M, ydd, eom_terms(out)))
    K, terms = reaction_system(out)
    if K.shape == np.shape(out["N_hat"]) and not out["g_undetermined"]:
        tol += gram_solve_tol(K, norm(Mb), solve_scale(K, g, terms))
    else:
        tol += norm(Q) * reactions_tol(out)
    summed = norm(MJ @ ydd) + norm(out["q_c"]) + norm(out["q_e"]) + norm(Q @ g)
    return tol + eval_tol(MJ.shape[0], summed)


def subtree_tol(out: Mapping[str, Any], ydd: object, extent: float) -> float:
    """Tolerance for a joint's wrench, or its components along unit orthogonal constrained
    directions, formed from the Newton–Euler equations of the sub-tree the joint carries (the
    single-joint path of reactions.py, Pinocchio's RNEA) against the same from ``g``.

    The two differ by the sub-tree's Newton–Euler residual moved to the joint point: each
    body's 6-vector turned (norm 1) and its force moved by a lever arm of at most ``extent``
    (the largest distance between a joint point and a centre of mass, :func:`tree_extent`), so
    by at most ``√p·(1 + extent)`` times the residual's bound :func:`newton_euler_tol`.
    """
    p = np.shape(out["M_bar"])[0] // 6
    return float(np.sqrt(p)) * (1.0 + float(extent)) * newton_euler_tol(out, ydd)


@lru_cache(maxsize=16)
def _points_function(system: Any) -> Any:
    from jourdain.numeric import lambdify, parameter_vector

    kin = system.kinematics()
    mats = {}
    for b in kin.bodies:
        mats[f"{b.name}.r"], mats[f"{b.name}.r_O"] = b.r, b.r_O
    fn = lambdify(system, mats)
    p = parameter_vector(system, None)
    nu = len(system.inputs)
    return lambda y, t: np.array([np.ravel(v) for v in fn(y, np.zeros(len(y)), t, p,
                                                           np.zeros(nu)).values()])


def tree_extent(system: Any, y: object, t: float = 0.0) -> float:
    """The largest distance between any two of the body frames' origins (the joint points) and
    the centres of mass at ``y, t`` (default parameters), with the inertial origin."""
    pts = np.vstack([_points_function(system)(np.asarray(y, dtype=float), float(t)),
                     np.zeros((1, 3))])
    return float(np.max(np.linalg.norm(pts[:, None, :] - pts[None, :, :], axis=-1)))
