"""Floquet analysis of a periodic nominal motion.

Where the nominal motion is periodic with period ``T`` (a pendulum on an oscillating pivot, a
rotor on an anisotropic shaft, a vehicle on a periodic track) the linearization
``M̃(t)·η̈ + P(t)·η̇ + Q(t)·η = h(t)`` (METHOD.md §5) has T-periodic matrices, and frozen-time
eigenvalues say nothing about stability. With ``x = [η; η̇]`` and

    ẋ = A(t)·x,   A(t) = [[0, I], [−M̃⁻¹Q, −M̃⁻¹P]]   (M̃ factored, never inverted)

the *monodromy matrix* ``Φ(t0 + T, t0)`` maps the state over one period (``Φ̇ = A(t)·Φ``,
``Φ(t0) = I``, integrated at tight tolerances by jourdain's compiled DOP853, all 2f columns
as one problem; by SciPy's where there is no C compiler). Its eigenvalues are the
*Floquet multipliers* μ_i, and ``λ_i = ln(μ_i)/T`` the *Floquet (characteristic) exponents*
(imaginary parts modulo 2π/T). Floquet's theorem: every solution is a sum of
``p_i(t)·e^{λ_i t}`` with T-periodic ``p_i`` (times powers of t for a defective μ), so the
verdict reads

* asymptotically stable: every ``|μ_i| < 1``;
* unstable: some ``|μ_i| > 1``, or a multiplier on the unit circle repeated with too few
  eigenvectors (a transition curve of the Mathieu chart: a linearly growing motion);
* marginally stable: none outside the unit circle, those on it semisimple.

Numbers within the integration's accuracy of the unit circle count as on it
(:attr:`Floquet.tolerance`). Cyclic coordinates (:mod:`jourdain.analysis.cyclic`) are treated
as for equilibria: in Routh's sense, on the reduced state without their positions (each adds
a multiplier 1 of the full system).
"""

from __future__ import annotations

import ctypes
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import EvaluationError, warn
from ..numeric import parameter_vector
from ..numeric.linearization import CompiledLinearization, check_nominal, compile_linearization
from ..stages.linearization import Linearization, NominalMotionWarning
from .cyclic import check_cyclic, cyclic_coordinates
from .modes import ASYMPTOTICALLY_STABLE, MARGINALLY_STABLE, UNSTABLE

#: default relative tolerance of the integration of Φ̇ = A(t)·Φ
FLOQUET_RTOL = 1e-11


@dataclass(frozen=True)
class Floquet:
    """Floquet analysis of a T-periodic linearization (see the module docstring).

    Attributes
    ----------
    period, t0 : float
        The period T and the start of the period integrated over.
    monodromy : (n, n) array
        ``Φ(t0 + T, t0)`` for the state ``[η_r; η̇]``: n = 2f, less one row and column per
        cyclic coordinate (their positions are left out, Routh).
    multipliers : (n,) complex array
        Eigenvalues of the monodromy matrix, largest modulus first.
    exponents : (n,) complex array
        ``ln(μ)/T`` (principal logarithm: imaginary parts in (−π/T, π/T]); −inf real part for
        μ = 0.
    verdict, reason : str
        ``"asymptotically stable"``, ``"marginally stable"`` or ``"unstable"``, and why.
    tolerance : float
        How far from the unit circle a modulus may lie and still count as on it (from the
        integration tolerance and the size of Φ).
    state_names : tuple of str
        Names of the rows of the monodromy matrix (``<coordinate>`` then ``<coordinate>_d``).
    cyclic : tuple of str
        The coordinates treated as cyclic.
    parameters : dict
        All parameter values used.
    """

    period: float
    t0: float
    monodromy: np.ndarray
    multipliers: np.ndarray
    exponents: np.ndarray
    verdict: str
    reason: str
    tolerance: float
    state_names: tuple[str, ...]
    cyclic: tuple[str, ...]
    parameters: dict[str, float]

    @property
    def is_stable(self) -> bool:
        """True for asymptotically or marginally stable."""
        return self.verdict != UNSTABLE

    @property
    def max_modulus(self) -> float:
        """The largest |μ| (the spectral radius of the monodromy matrix)."""
        return float(np.abs(self.multipliers).max(initial=0.0))

    def __str__(self) -> str:
        lines = [f"Floquet analysis over the period T = {self.period:.6g} (from t0 = "
                 f"{self.t0:g}): monodromy matrix {self.monodromy.shape[0]}×"
                 f"{self.monodromy.shape[1]}",
                 f"{'multiplier μ':>30}  {'|μ|':>10}  {'exponent ln(μ)/T':>30}"]
        for mu, lam in zip(self.multipliers, self.exponents, strict=True):
            re = f"{lam.real:.6g}" if np.isfinite(lam.real) else "-inf"
            lines.append(f"{mu.real:>14.8g} {mu.imag:+14.8g}j  {abs(mu):>10.8f}  "
                         f"{re:>14} {lam.imag:+14.6g}j")
        lines.append(f"stability: {self.verdict}: {self.reason}")
        return "\n".join(lines)


def _compiled(lin: Linearization | CompiledLinearization) -> CompiledLinearization:
    if isinstance(lin, CompiledLinearization):
        return lin
    if isinstance(lin, Linearization):
        return compile_linearization(lin)
    raise EvaluationError(f"floquet: expected a Linearization or CompiledLinearization (a "
                          f"periodic nominal motion, symbolic in t), got {type(lin).__name__}")


def floquet(lin: Linearization | CompiledLinearization, period: float, t0: float = 0.0,
            parameters: Mapping[str, float] | None = None, rtol: float = FLOQUET_RTOL,
            cyclic: Sequence[str] | None = None) -> Floquet:
    """Monodromy matrix, Floquet multipliers and exponents and the stability verdict of a
    linearization about a T-periodic nominal motion (see the module docstring).

    Parameters
    ----------
    lin : Linearization or CompiledLinearization
        About a nominal motion whose M̃, P, Q repeat with ``period`` (compiled here when
        symbolic; pass the compiled form for many calls, e.g. over a parameter).
    period : float
        T > 0, in the units of t.
    t0 : float
        Start of the period.
    parameters : mapping, optional
        Overrides of the default parameter values.
    rtol : float
        Relative tolerance of the integration (the absolute one is ``rtol·1e-3``).
    cyclic : sequence of str, optional
        Coordinates to treat as cyclic; None finds them
        (:func:`jourdain.analysis.cyclic.cyclic_coordinates`), ``()`` treats none.

    Raises
    ------
    EvaluationError
        A period that is not a positive finite number, matrices that do not repeat after
        ``period`` (at t0 + T/3 against t0 + 4T/3 and t0 against t0 + T, to 1e-8 of their
        size), a singular M̃ along the period or non-finite numbers.

    Warns
    -----
    NominalMotionWarning
        When the nominal motion does not solve the equations of motion (h ≠ 0 at t0 and
        t0 + T/3, against the forces at work): the verdict is then about the linear system
        only, and the reason says so.
    """
    from scipy.linalg import cho_factor, cho_solve

    from ..errors import refuse_closed

    own = getattr(lin, "floquet", None)
    if callable(own):  # a closed system's linearization about a nominal motion
        return own(period, t0, parameters, rtol, cyclic)
    refuse_closed(getattr(lin, "system", None) or getattr(getattr(lin, "linearization", None),
                                                          "system", None),
                  "Floquet analysis needs the linearization about a periodic nominal motion: "
                  "linearize the closed system about expressions of t for its independent "
                  "coordinates (its linearization about a state has no period)")

    T = check_period(period, rtol)
    t0 = float(t0)
    comp = _compiled(lin)
    base = comp.linearization
    system = base.system
    f, m = system.f, len(system.inputs)
    p = parameter_vector(system, parameters)
    pars = {str(s): float(v) for s, v in zip(system.parameter_symbols, p, strict=True)}
    fn = comp.function
    zf, zu = np.zeros(f), np.zeros(m)

    def matrices(t: float) -> dict[str, np.ndarray]:
        return fn(zf, zf, t, p, zu)

    # the matrices must repeat with the period
    for a, b in ((t0, t0 + T), (t0 + T / 3, t0 + 4 * T / 3)):
        ma, mb = matrices(a), matrices(b)
        for key in ("M_tilde", "P", "Q"):
            scale = max(1.0, float(np.abs(ma[key]).max(initial=0.0)))
            if not (np.all(np.isfinite(ma[key])) and np.all(np.isfinite(mb[key]))):
                raise EvaluationError(f"floquet: {key} is not finite at t = {a:g} or {b:g}")
            if np.abs(ma[key] - mb[key]).max(initial=0.0) > 1e-8 * scale:
                raise EvaluationError(
                    f"floquet: the linearization about {_nominal_text(base)} is not periodic "
                    f"with T = {T:.6g}: {key} at t = {a:.6g} and t = {b:.6g} differ by "
                    f"{np.abs(ma[key] - mb[key]).max():.3g}; give the period of the nominal "
                    "motion (and of any excitation in t)")
    names = tuple(system.coordinate_names)

    def state_matrix(t: float) -> np.ndarray:
        mt = matrices(t)
        try:
            factor = cho_factor(0.5 * (mt["M_tilde"] + mt["M_tilde"].T), lower=True,
                                check_finite=False)
        except np.linalg.LinAlgError:
            raise EvaluationError(f"floquet: M_tilde is not positive definite at t = {t:.6g}"
                                  ) from None
        A = np.zeros((2 * f, 2 * f))
        A[:f, f:] = np.eye(f)
        A[f:] = -cho_solve(factor, np.hstack([mt["Q"], mt["P"]]), check_finite=False)
        return A

    if cyclic is None:
        cyclic = cyclic_coordinates(base.equations_of_motion)
    cyc = check_cyclic(state_matrix(t0), names, cyclic)
    cyc = check_cyclic(state_matrix(t0 + T / 3), names, cyc)
    drop = {names.index(c) for c in cyc}
    keep = [i for i in range(2 * f) if i not in drop]
    n = len(keep)
    ix = np.ix_(keep, keep)

    accel = _monodromy_accel(fn)
    if accel is not None:  # all 2f columns by the compiled DOP853, then Routh's rows/columns
        Phi = _monodromy_compiled(accel, f, m, p, (t0, t0 + T), rtol)[ix]
    else:  # no compiler: SciPy's DOP853 on the reduced state
        Phi = monodromy_scipy(lambda t: state_matrix(t)[ix], n, t0, T, rtol)
    mu, lam, tol = multipliers(Phi, T, rtol)
    verdict, reason = _verdict(Phi, mu, tol)
    if cyc:
        reason += (f"; in Routh's sense, without the position(s) of the cyclic coordinate(s) "
                   f"{', '.join(cyc)}")
    reason = _nominal_warning(base, reason, t0, T, parameters)
    state = tuple([*(names[i] for i in range(f) if i not in drop), *(f"{c}_d" for c in names)])
    return Floquet(period=T, t0=t0, monodromy=Phi, multipliers=mu, exponents=lam,
                   verdict=verdict, reason=reason, tolerance=tol, state_names=state,
                   cyclic=cyc, parameters=pars)


def check_period(period: Any, rtol: float) -> float:
    """The period as a positive finite number, and ``rtol`` in (0, 1e-3); EvaluationError
    naming the bad one."""
    T = float(period)
    if not np.isfinite(T) or T <= 0:
        raise EvaluationError(f"floquet: the period must be a positive finite number, got "
                              f"{period!r}")
    if not 0 < rtol < 1e-3:
        raise EvaluationError(f"floquet: rtol must be in (0, 1e-3), got {rtol!r}")
    return T


def monodromy_scipy(state_matrix: Callable[[float], np.ndarray], n: int, t0: float, T: float,
                    rtol: float) -> np.ndarray:
    """The monodromy matrix of ``ẋ = A(t)·x`` (n states) over ``[t0, t0 + T]`` by SciPy's
    DOP853 from Python, ``A(t) = state_matrix(t)``."""
    from scipy.integrate import solve_ivp

    def rhs(t: float, z: np.ndarray) -> np.ndarray:
        return (state_matrix(t) @ z.reshape(n, n)).ravel()

    sol = solve_ivp(rhs, (t0, t0 + T), np.eye(n).ravel(), method="DOP853", rtol=rtol,
                    atol=rtol * 1e-3)
    if not sol.success:
        raise EvaluationError(f"floquet: the integration over one period failed: "
                              f"{sol.message}")
    return sol.y[:, -1].reshape(n, n)


def multipliers(Phi: np.ndarray, T: float, rtol: float
                ) -> tuple[np.ndarray, np.ndarray, float]:
    """The Floquet multipliers μ of the monodromy matrix ``Phi`` (by modulus, then imaginary
    part), the exponents ``ln(μ)/T`` and the tolerance of the verdict on |μ| = 1."""
    if not np.all(np.isfinite(Phi)):
        raise EvaluationError("floquet: the monodromy matrix is not finite")
    mu = np.linalg.eigvals(Phi)
    mu = mu[np.lexsort((-mu.imag, -np.round(np.abs(mu), 12)))]
    with np.errstate(divide="ignore"):
        lam = np.log(mu.astype(complex)) / T
    # the integration's global error is a few rtol times the size of Φ (DOP853 keeps the
    # local error per step below rtol·|z|, and a period takes tens to thousands of steps)
    tol = max(1e3 * rtol, 1e2 * np.finfo(float).eps) * max(1.0, float(np.linalg.norm(Phi, 2)))
    return mu, lam, tol


def _monodromy_accel(fn: object) -> int | None:
    """The address of the compiled linearization's ``jd_monodromy_accel``
    (:func:`jourdain.numeric.linearization.monodromy_accel_source`), or None (interpreted)."""
    try:
        return ctypes.cast(fn.lib.jd_monodromy_accel, ctypes.c_void_p).value  # type: ignore[attr-defined]
    except AttributeError:
        return None


def _monodromy_compiled(accel: int, f: int, m: int, p: np.ndarray,
                        t_span: tuple[float, float], rtol: float) -> np.ndarray:
    """Φ(t1, t0) of the full state [η; η̇] (2f×2f): its columns integrated together by the
    compiled DOP853 (:func:`jourdain.simulation.problem.integrate_accel`), the accelerations
    from ``jd_monodromy_accel``. Against SciPy's DOP853 calling A(t) from Python: no import of
    scipy.integrate (0.36 s of a report's first Floquet analysis) and a right-hand side in
    microseconds instead of tens of them."""
    from ..simulation.problem import integrate_accel

    n = 2 * f
    H, Hd = np.zeros((n, f)), np.zeros((n, f))  # row c: column c of Φ's upper/lower half
    H[np.arange(f), np.arange(f)] = 1.0
    Hd[np.arange(f, n), np.arange(f)] = 1.0
    x0 = np.concatenate([H.ravel(), Hd.ravel(), [0.0]])
    try:
        x = integrate_accel(accel, n * f, p, m, x0, t_span, rtol, rtol * 1e-3)
    except EvaluationError as exc:
        raise EvaluationError(f"floquet: the integration over one period failed: {exc}"
                              ) from None
    return np.vstack([x[:n * f].reshape(n, f).T, x[n * f:2 * n * f].reshape(n, f).T])


def _verdict(Phi: np.ndarray, mu: np.ndarray, tol: float) -> tuple[str, str]:
    mod = np.abs(mu)
    outside = mod > 1 + tol
    if np.any(outside):
        worst = mu[np.argmax(mod)]
        kind = ("real multiplier: a divergence (μ > 1) or a parametric resonance of half the "
                "excitation frequency (μ < −1)" if abs(worst.imag) <= tol else
                "complex multiplier: a growing oscillation (combination resonance)")
        return UNSTABLE, (f"{int(outside.sum())} Floquet multiplier(s) outside the unit circle, "
                          f"largest |μ| = {abs(worst):.8g} at μ = {_fmt(worst)} ({kind}); the "
                          f"motion grows by that factor every period")
    on = mod >= 1 - tol
    if not np.any(on):
        return ASYMPTOTICALLY_STABLE, (f"all {mu.size} Floquet multipliers lie inside the unit "
                                       f"circle (largest |μ| = {mod.max():.8g})")
    # multipliers on the circle: repeated ones must be semisimple; a Jordan block splits them
    # by about √(error), so they are grouped first
    cluster = 10 * np.sqrt(tol)
    idx = [int(i) for i in np.flatnonzero(on)]
    groups: list[list[int]] = []
    for i in idx:
        for grp in groups:
            if abs(mu[i] - mu[grp[0]]) <= cluster:
                grp.append(i)
                break
        else:
            groups.append([i])
    n = Phi.shape[0]
    for grp in groups:
        if len(grp) < 2:
            continue
        centre = mu[grp].mean()
        sv = np.linalg.svd(Phi - centre * np.eye(n), compute_uv=False)
        geometric = int(np.sum(sv <= cluster * max(1.0, float(sv[0]))))
        if geometric < len(grp):
            return UNSTABLE, (f"the Floquet multiplier μ = {_fmt(centre)} on the unit circle is "
                              f"repeated {len(grp)} times with only {geometric} eigenvector(s): "
                              "the motion grows linearly in time (a transition curve of the "
                              "stability chart)")
    return MARGINALLY_STABLE, (f"no Floquet multiplier lies outside the unit circle; {len(idx)} "
                               f"lie on it (to {tol:.1g}) and are semisimple, e.g. "
                               f"μ = {_fmt(mu[idx[0]])}")


def _fmt(z: complex) -> str:
    return f"{z.real:.8g}{z.imag:+.8g}j"


def _nominal_text(lin: Linearization) -> str:
    return ", ".join(f"{n} = {e}" for n, e in zip(lin.system.coordinate_names,
                                                    lin.y_s.entries(), strict=True))


def _nominal_warning(lin: Linearization, reason: str, t0: float, T: float,
                     parameters: Mapping[str, float] | None) -> str:
    for t in (t0, t0 + T / 3):
        check = check_nominal(lin, t, parameters)
        if not check.is_solution:
            text = (f"the nominal motion is not a solution of the equations of motion at "
                    f"t = {t:.6g} (|h| = {np.abs(check.h).max():.3g}, {check.relative:.2g} of "
                    "the forces at work): the verdict is about the linear system only")
            warn(text, NominalMotionWarning)
            return f"{reason}. WARNING: {text}"
    return reason

