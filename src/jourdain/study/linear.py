"""Linearizations of a stack of cases: state matrices, eigenvalues, verdicts, frequency
responses and critical values.

- M̃, P, Q, B (and h) of all cases of a block from one C call (:func:`linearization_numbers`);
- the state matrices ``A = [[0, I], [−M̃⁻¹Q, −M̃⁻¹P]]`` by stacked Cholesky solves and the
  eigenvalues by one stacked LAPACK call; the verdict as :func:`jourdain.analysis.stability`
  gives it (its rule applied to the stack where the largest real part decides it, the function
  itself otherwise) (:func:`analyse`);
- magnitude and phase of the steady-state response over the study's frequencies, the complex
  solves stacked over cases and frequencies (:func:`frequency_responses`);
- bisection on the verdict for all cases of the block together, then the crossing of the
  largest real part through zero, as :func:`jourdain.analysis.stability_boundary`
  (:func:`critical`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from .context import Context

__all__ = ["ASYMPTOTICALLY_STABLE_CODE", "MARGINALLY_STABLE_CODE", "UNSTABLE_CODE", "VERDICTS",
           "analyse", "closed_linearizations", "critical", "frequency_responses", "linearization_numbers",
           "state_matrices"]

#: verdict codes stored in the results (−1: the case failed)
ASYMPTOTICALLY_STABLE_CODE, MARGINALLY_STABLE_CODE, UNSTABLE_CODE = 0, 1, 2
VERDICTS = ("asymptotically stable", "marginally stable", "unstable")


def linearization_numbers(ctx: Context, P: np.ndarray, Y: np.ndarray | None = None
                          ) -> dict[str, Any]:
    """M̃, P, Q, B, ... of the linearization at each row of ``P`` (n ≥ 1), in one C call; for
    a closed system :func:`closed_linearizations` (one linearization per case, ``Y`` the
    cases' initial coordinates: the equilibria's starting guesses)."""
    if ctx.closed:
        return closed_linearizations(ctx, P, Y)
    n, f = len(P), ctx.system.f
    Z = np.zeros((n, f))
    U = np.zeros((n, len(ctx.system.inputs))) if ctx.system.inputs else None
    return ctx.compiled_linearization.function.batch(Z, Z, 0.0, P, U)


def closed_linearizations(ctx: Context, P: np.ndarray, Y: np.ndarray | None = None
                          ) -> dict[str, Any]:
    """A closed system's linearization at each row of ``P``, one case at a time, exactly as
    :func:`jourdain.loops.nominal.linearize_closed` (what ``System.linearize`` calls)
    gives it for that case's parameters: about the model's nominal state (evaluated at the
    case's parameters), or, with ``about = "equilibrium"``, about the equilibrium
    :func:`jourdain.loops.linearization.equilibrium` finds nearest the case's initial
    coordinates (a row of ``Y``; the model's ``y0`` where None). Returns ``M_tilde``, ``P``,
    ``Q`` (n, f, f) and the state matrix ``A`` (n, 2f, 2f) in the independent coordinates,
    ``y_s`` (n, tree coordinates: the configuration linearized about) and ``errors`` (row ->
    message; those rows NaN)."""
    from ..loops.general_linear import linearize_general
    from ..loops.linearization import equilibrium
    from ..loops.nominal import linearize_state
    from .context import FAILURES, state_mapping

    n, f, ft = len(P), ctx.f_linear, ctx.system.f
    out: dict[str, Any] = {"M_tilde": np.full((n, f, f), np.nan), "P": np.full((n, f, f), np.nan),
                           "Q": np.full((n, f, f), np.nan),
                           "A": np.full((n, 2 * f, 2 * f), np.nan),
                           "y_s": np.full((n, ft), np.nan), "errors": {}}
    names = ctx.parameter_names
    for i in range(n):
        params = dict(zip(names, P[i].tolist(), strict=True))
        try:
            nominal: Any
            if ctx.nominal_state is None:
                guess = ctx.y0 if Y is None else Y[i]
                nominal = equilibrium(ctx.system, guess, parameters=params)
            else:
                v = np.asarray(ctx.nominal_state(P[i]), dtype=float).reshape(-1)
                nominal = state_mapping(ctx.system, v)
            lin: Any
            if ctx.system.is_general:  # velocity constraints, about the steady motion
                lin = linearize_general(ctx.system, nominal, params)
            else:
                lin = linearize_state(ctx.system, nominal, parameters=params)
            if lin.A.shape != (2 * f, 2 * f):
                raise ValueError(f"the linearization has {lin.A.shape[0] // 2} independent "
                                 f"coordinates ({', '.join(lin.names)}), the study's "
                                 f"{f} ({', '.join(ctx.independent)})")
        except FAILURES as exc:
            out["errors"][i] = str(exc)
            continue
        out["M_tilde"][i], out["P"][i], out["Q"][i], out["A"][i] = lin.M_tilde, lin.P, lin.Q, lin.A
        out["y_s"][i] = lin.z_s
    return out


def analyse(ctx: Context, P: np.ndarray, nums: Mapping[str, Any] | None = None,
            Y: np.ndarray | None = None
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict[int, str]]:
    """Eigenvalues (n, 2f) sorted as :func:`jourdain.analysis.sweep` sorts them, the largest
    real part (n,) and the verdict code (n,) of the linearization at each row of ``P``; and
    the errors by row (their outputs NaN / −1). ``nums``: :func:`linearization_numbers` at
    ``P`` where already computed. A closed system's state matrices are those of its per-case
    linearizations (:func:`closed_linearizations`, ``Y`` the cases' initial coordinates)."""
    from ..analysis.cyclic import reduced_matrix
    from ..analysis.modes import ZERO_RTOL, _verdict

    n, f = len(P), ctx.f_linear
    lam = np.full((n, 2 * f), np.nan + 0j)
    maxre = np.full(n, np.nan)
    verdict = np.full(n, -1, dtype=np.int8)
    errs: dict[int, str] = {}
    if not n:
        return lam, maxre, verdict, errs
    if nums is None:
        nums = linearization_numbers(ctx, P, Y)
    if "A" in nums:  # a closed system's: the linearizations' own state matrices
        A, bad = np.array(nums["A"]), dict(nums["errors"])
        for i in np.flatnonzero(~np.all(np.isfinite(A.reshape(n, -1)), axis=1)):
            bad.setdefault(int(i), "the linearization has non-finite entries at this case")
        A[list(bad)] = 0.0
    else:
        A, bad = state_matrices(nums["M_tilde"], nums["P"], nums["Q"])
    for i, msg in bad.items():
        errs[i] = msg
    good = np.ones(n, dtype=bool)
    good[list(bad)] = False
    if not good.any():
        return lam, maxre, verdict, errs
    Ag = A[good]
    ev = np.linalg.eigvals(Ag)
    order = np.lexsort((ev.real, ev.imag), axis=-1)
    ev = np.take_along_axis(ev, order, axis=-1)
    names = tuple(ctx.system.coordinate_names)
    Ar = (np.stack([reduced_matrix(a, names, ctx.cyclic) for a in Ag]) if ctx.cyclic
          else Ag)
    evr = np.linalg.eigvals(Ar) if ctx.cyclic else ev
    # the verdict of modes._verdict: a group's centre lies within 2·cluster_tol of its
    # members, so a largest real part beyond tol + 2·cluster_tol is unstable and one below
    # −tol − 2·cluster_tol asymptotically stable; cases in between take the function itself
    scale = np.maximum(1.0, np.abs(evr).max(axis=1))
    tol = ZERO_RTOL * scale
    cluster = 1e3 * np.sqrt(np.finfo(float).eps) * scale
    mr = evr.real.max(axis=1)
    v = np.where(mr > tol + 2 * cluster, UNSTABLE_CODE,
                 np.where(mr < -tol - 2 * cluster, ASYMPTOTICALLY_STABLE_CODE, -1))
    for k in np.flatnonzero(v < 0):
        v[k] = VERDICTS.index(_verdict(Ar[k], ZERO_RTOL).verdict)
    gi = np.flatnonzero(good)
    lam[gi] = ev
    maxre[gi] = ev.real.max(axis=1)
    verdict[gi] = v
    return lam, maxre, verdict, errs


def frequency_responses(ctx: Context, P: np.ndarray,
                        nums: Mapping[str, np.ndarray] | None = None
                        ) -> tuple[np.ndarray, np.ndarray, dict[int, str]]:
    """``|η̂|`` and ``arg η̂`` (unwrapped along the frequencies), each (n, n_ω, f, m), of the
    linearization at each row of ``P``: ``η̂ = (Q − Ω²M̃ + iΩP)⁻¹·F`` with ``F = B`` (inputs)
    or the identity (``h``), as :func:`jourdain.analysis.frequency_response` gives it for one
    case; M̃, P, Q, B of all cases from one C call, the complex solves stacked over cases and
    frequencies. A case whose dynamic stiffness is singular at some Ω records its error.
    ``nums``: :func:`linearization_numbers` at ``P`` where already computed."""
    fr = ctx.spec.compute["frequency_response"]
    n, f = len(P), ctx.system.f
    w = np.asarray(fr["omega"], dtype=float)
    m = len(ctx.system.inputs) if fr["excitation"] == "inputs" else f
    mag = np.full((n, len(w), f, m), np.nan)
    phase = np.full((n, len(w), f, m), np.nan)
    errs: dict[int, str] = {}
    if not n:
        return mag, phase, errs
    if nums is None:
        nums = linearization_numbers(ctx, P)
    F = nums["B"] if fr["excitation"] == "inputs" else np.broadcast_to(np.eye(f), (n, f, f))
    W = w[None, :, None, None]
    Z = (nums["Q"][:, None] - W**2 * nums["M_tilde"][:, None] + 1j * W * nums["P"][:, None])
    rhs = np.broadcast_to(F[:, None], (n, len(w), f, m)).astype(complex)
    try:
        eta = np.linalg.solve(Z, rhs)
        rows = range(n) if not np.all(np.isfinite(eta)) else ()
    except np.linalg.LinAlgError:
        eta, rows = np.full(rhs.shape, np.nan + 0j), range(n)
    for i in rows:  # case by case where the stack failed: name the frequency
        for k, wk in enumerate(w):
            try:
                eta[i, k] = np.linalg.solve(Z[i, k], rhs[i, k])
            except np.linalg.LinAlgError:
                eta[i] = np.nan
                errs[i] = (f"the dynamic stiffness Q - Ω²M̃ + iΩP is singular at Ω = {wk} "
                           "rad/s (an undamped resonance, or a rigid-body mode at Ω = 0)")
                break
    mag[:] = np.abs(eta)
    phase[:] = np.unwrap(np.angle(eta), axis=1)
    return mag, phase, errs


def state_matrices(M: np.ndarray, Pm: np.ndarray, Q: np.ndarray
                   ) -> tuple[np.ndarray, dict[int, str]]:
    """``A = [[0, I], [−M̃⁻¹Q, −M̃⁻¹P]]`` for a stack (n, f, f), by the Cholesky factor of
    M̃ as :func:`jourdain.analysis.state_space` forms it; rows where M̃ is not finite or not
    positive definite are reported (their A is zero)."""
    n, f = M.shape[0], M.shape[1]
    A = np.zeros((n, 2 * f, 2 * f))
    A[:, :f, f:] = np.eye(f)
    bad: dict[int, str] = {}
    finite = np.all(np.isfinite(M.reshape(n, -1)) & np.isfinite(Pm.reshape(n, -1))
                    & np.isfinite(Q.reshape(n, -1)), axis=1)
    for i in np.flatnonzero(~finite):
        bad[int(i)] = "the linearization has non-finite entries at this case"
    idx = np.flatnonzero(finite)
    Ms = 0.5 * (M[idx] + np.swapaxes(M[idx], 1, 2))
    try:
        L = np.linalg.cholesky(Ms)
        chol_ok = np.ones(idx.size, dtype=bool)
    except np.linalg.LinAlgError:  # some case is not positive definite: find which
        L = np.zeros_like(Ms)
        chol_ok = np.zeros(idx.size, dtype=bool)
        for k in range(idx.size):
            try:
                L[k] = np.linalg.cholesky(Ms[k])
                chol_ok[k] = True
            except np.linalg.LinAlgError:
                ev = np.linalg.eigvalsh(Ms[k])
                bad[int(idx[k])] = (f"M_tilde is not positive definite (eigenvalues "
                                    f"{np.array2string(ev, precision=4)})")
    idx, L = idx[chol_ok], L[chol_ok]
    if idx.size:
        Lt = np.swapaxes(L, 1, 2)
        X = np.concatenate([Q[idx], Pm[idx]], axis=2)
        S = np.linalg.solve(Lt, np.linalg.solve(L, X))
        A[idx, f:, :f] = -S[:, :, :f]
        A[idx, f:, f:] = -S[:, :, f:]
    return A, bad


# --- critical value by bisection on the verdict ------------------------------------------

def critical(ctx: Context, P: np.ndarray, Y: np.ndarray | None = None
             ) -> tuple[np.ndarray, dict[int, str]]:
    """The value of the critical parameter in [lower, upper] where the verdict changes between
    stable and unstable, for every row of ``P`` (the other parameters); as
    :func:`jourdain.analysis.stability_boundary`: bisection on the verdict to ``rtol``, then,
    where the stable side is asymptotically stable, the zero of the largest real part between
    the nearest asymptotically stable point and the unstable end (Illinois' regula falsi,
    all rows together). Rows whose ends have the same verdict are errors."""
    c = ctx.spec.compute["critical"]
    j = ctx.parameter_names.index(c["parameter"])
    n = len(P)
    out = np.full(n, np.nan)
    errs: dict[int, str] = {}
    if not n:
        return out, errs
    ab = np.asarray(ctx.bounds(P), dtype=float).reshape(n, 2)
    a, b = ab[:, 0].copy(), ab[:, 1].copy()

    def at(x: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray, dict[int, str]]:
        Px = P[rows].copy()
        Px[:, j] = x
        _, mr, v, e = analyse(ctx, Px, Y=None if Y is None else Y[rows])
        return v, mr, e

    rows = np.arange(n)
    va, _, ea = at(a, rows)
    vb, _, eb = at(b, rows)
    alive = np.ones(n, dtype=bool)
    for e, msg in {**ea, **eb}.items():
        errs[e] = f"at the bracket's end: {msg}"
        alive[e] = False
    ua, ub = va == UNSTABLE_CODE, vb == UNSTABLE_CODE
    for ii in np.flatnonzero(alive & (ua == ub)):
        i = int(ii)
        word = "unstable" if ua[i] else "stable"
        errs[i] = (f"the system is {word} at both {c['parameter']} = {a[i]:.17g} and "
                   f"{b[i]:.17g}; give a bracket where it changes")
        alive[i] = False
    asym = np.where(va == ASYMPTOTICALLY_STABLE_CODE, a,
                    np.where(vb == ASYMPTOTICALLY_STABLE_CODE, b, np.nan))
    rtol = c["rtol"]
    for _ in range(2000):
        width = np.abs(b - a) > rtol * np.maximum(1.0, np.maximum(np.abs(a), np.abs(b)))
        live = np.flatnonzero(alive & width)
        if not live.size:
            break
        mid = 0.5 * (a[live] + b[live])
        vm, _, em = at(mid, live)
        for i, msg in em.items():
            errs[int(live[i])] = f"at {c['parameter']} = {mid[i]:.17g}: {msg}"
            alive[live[i]] = False
        asym[live] = np.where(vm == ASYMPTOTICALLY_STABLE_CODE, mid, asym[live])
        same = (vm == UNSTABLE_CODE) == ua[live]
        a[live] = np.where(same, mid, a[live])
        b[live] = np.where(same, b[live], mid)
    unstable_end = np.where(ua, a, b)
    out[:] = 0.5 * (a + b)
    # the crossing of the largest real part through zero, between the nearest asymptotically
    # stable point and the unstable end
    rows = np.flatnonzero(alive & np.isfinite(asym))
    if rows.size:
        x0, x1 = asym[rows].copy(), unstable_end[rows].copy()
        _, f0, _ = at(x0, rows)
        _, f1, _ = at(x1, rows)
        go = f1 > 0
        x0, x1, f0, f1, rows = x0[go], x1[go], f0[go], f1[go], rows[go]
        xs = 0.5 * (x0 + x1)
        for _ in range(200):
            if not rows.size:
                break
            xs = x1 - f1 * (x1 - x0) / (f1 - f0)
            xs = np.where(np.isfinite(xs), xs, 0.5 * (x0 + x1))
            _, fs, em = at(xs, rows)
            fs = np.where(np.isfinite(fs), fs, 0.0)
            # Illinois: keep the bracket [x0, x1] with f0 < 0 < f1 (f0 halved when x1 moves)
            left = fs < 0
            side0 = np.where(left, xs, x0)
            side1 = np.where(left, x1, xs)
            f0n = np.where(left, fs, f0 * 0.5)
            f1n = np.where(left, f1 * 0.5, fs)
            done = (np.abs(side1 - side0) <= 4 * np.finfo(float).eps * np.abs(xs) + 1e-300) | (
                fs == 0)
            out[rows[done]] = xs[done]
            keep = ~done
            x0, x1, f0, f1, rows = side0[keep], side1[keep], f0n[keep], f1n[keep], rows[keep]
            out[rows] = 0.5 * (x0 + x1)
    for i in errs:
        out[i] = np.nan
    return out, errs

