"""Eigenvalues, modes and the stability verdict of a linear time-invariant system.

For ``ẋ = A·x`` with eigenvalues ``λ = δ ± iω_d``: the natural (undamped) angular frequency is
``ω_n = |λ|``, the damping ratio ``ζ = −δ/|λ|``, the damped frequency ``ω_d = |Im λ|``; the mode
shape is the position part (first f rows) of the eigenvector.

Stability (Lyapunov, of the linear system): *asymptotically stable* when every eigenvalue has a
negative real part; *marginally stable* when none has a positive real part and those on the
imaginary axis are semisimple (as many independent eigenvectors as their multiplicity);
*unstable* otherwise — an eigenvalue with a positive real part (real: divergence, complex:
flutter) or a repeated eigenvalue on the imaginary axis with too few eigenvectors (secular,
linearly growing motion, e.g. a free rigid-body coordinate).

Cyclic coordinates (:mod:`jourdain.analysis.cyclic`: they appear in no equation, only their
rates) drift along a family of steady motions; for a linearization the verdict is taken, in
Routh's sense, on the reduced system without their positions, and says which coordinates were
treated so (``Stability.cyclic``; ``cyclic=()`` asks for the full system).

The verdict is about the linear system. Where the nominal motion it came from is an equilibrium
or a steady motion that does not solve the equations of motion (``h ≠ 0``,
:class:`jourdain.stages.linearization.NominalCheck`), the reason says so and a
:class:`jourdain.stages.linearization.NominalMotionWarning` is issued.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np

from ..errors import warn
from ..stages.linearization import NominalMotionWarning
from .cyclic import check_cyclic, cyclic_coordinates, reduced_matrix
from .state_space import ZERO_RTOL, AnyLinearization, StateSpace, state_space

ASYMPTOTICALLY_STABLE = "asymptotically stable"
MARGINALLY_STABLE = "marginally stable"
UNSTABLE = "unstable"


@dataclass(frozen=True)
class Modes:
    """Eigen-analysis of a state-space system, sorted by natural frequency (conjugate pairs
    adjacent, the one with positive imaginary part first).

    Attributes
    ----------
    eigenvalues : (2f,) complex array
    vectors : (2f, 2f) complex array
        Eigenvectors of A (columns), for the state ``[η; η̇]``.
    shapes : (f, 2f) complex array
        Mode shapes: the position part of each eigenvector, scaled so that its largest component
        is 1.
    natural_frequencies : (2f,) array
        ``ω_n = |λ|`` in rad/s.
    damping_ratios : (2f,) array
        ``ζ = −Re λ / |λ|`` (NaN for λ = 0).
    damped_frequencies : (2f,) array
        ``|Im λ|`` in rad/s.
    coordinate_names : tuple of str
    """

    eigenvalues: np.ndarray
    vectors: np.ndarray
    shapes: np.ndarray
    natural_frequencies: np.ndarray
    damping_ratios: np.ndarray
    damped_frequencies: np.ndarray
    coordinate_names: tuple[str, ...]

    @property
    def frequencies_hz(self) -> np.ndarray:
        """Natural frequencies in Hz."""
        return self.natural_frequencies / (2 * np.pi)

    def oscillating(self) -> np.ndarray:
        """Indices of one eigenvalue per oscillating mode (positive imaginary part)."""
        scale = max(1.0, float(np.abs(self.eigenvalues).max(initial=0.0)))
        return np.flatnonzero(self.eigenvalues.imag > 1e-9 * scale)

    def __str__(self) -> str:
        """A table of the eigenvalues, natural frequencies and damping ratios. Real and
        imaginary parts below ``ZERO_RTOL`` of the largest |λ| (the tolerance of the stability
        verdict) are shown as 0; a zero eigenvalue (a rigid-body or neutral mode) has no damping
        ratio, shown as a dash."""
        tol = _zero_tol(self.eigenvalues)
        lines = [f"{'eigenvalue [1/s]':>28}  {'f_n [Hz]':>10}  {'zeta':>8}"]
        zero = False
        for lam in self.eigenvalues:
            lam = _chop(lam, tol)
            if lam == 0:
                zero = True
                lines.append(f"{0:>13g} {0:+13g}j  {0:>10g}  {'—':>8}")
                continue
            fn = abs(lam) / (2 * np.pi)
            z = -lam.real / abs(lam) + 0.0  # + 0.0: no "-0"
            lines.append(f"{lam.real:>13.6g} {lam.imag:+13.6g}j  {fn:>10.5g}  {z:>8.4f}")
        if zero:
            lines.append("  (—: λ = 0, a rigid-body or neutral mode: no damping ratio)")
        return "\n".join(lines)


def _zero_tol(lam: np.ndarray, rtol: float = ZERO_RTOL) -> float:
    return rtol * max(1.0, float(np.abs(lam).max(initial=0.0)))


def _chop(z: complex, tol: float) -> complex:
    """``z`` with real and imaginary parts of at most ``tol`` set to (positive) zero."""
    re = 0.0 if abs(z.real) <= tol else float(z.real)
    im = 0.0 if abs(z.imag) <= tol else float(z.imag)
    return complex(re, im)


@dataclass(frozen=True)
class Stability:
    """Stability verdict of a linear time-invariant system.

    ``verdict`` is one of ``"asymptotically stable"``, ``"marginally stable"``, ``"unstable"``;
    ``reason`` says why in words (and ends with a warning where the nominal motion is not a
    solution); ``max_real_part`` is the largest real part of the eigenvalues; ``critical`` the
    eigenvalues that decide the verdict; ``nominal_is_solution`` whether the equilibrium or
    steady motion linearized about solves the equations of motion (``h = 0``; None where not
    known or for other nominal motions); ``cyclic`` the coordinates treated as cyclic (Routh:
    the verdict is on the reduced system without their positions; empty for the full system).
    """

    verdict: str
    reason: str
    max_real_part: float
    critical: np.ndarray
    nominal_is_solution: bool | None = None
    cyclic: tuple[str, ...] = ()

    @property
    def is_stable(self) -> bool:
        """True for asymptotically or marginally stable."""
        return self.verdict != UNSTABLE

    def __str__(self) -> str:
        return f"{self.verdict}: {self.reason}"


def _as_state_space(system: StateSpace | AnyLinearization, t: float | None,
                    parameters: Mapping[str, float] | None) -> StateSpace:
    if isinstance(system, StateSpace):
        return system
    return state_space(system, t, parameters)


def modes(system: StateSpace | AnyLinearization, t: float | None = None,
          parameters: Mapping[str, float] | None = None) -> Modes:
    """Eigenvalues, natural frequencies, damping ratios and mode shapes.

    ``system`` is a :class:`StateSpace` or a linearization (evaluated at ``t`` with
    ``parameters``).
    """
    ss = _as_state_space(system, t, parameters)
    lam, V = np.linalg.eig(ss.A)
    order = np.lexsort((-lam.imag, np.round(np.abs(lam), 12)))
    lam, V = lam[order], V[:, order]
    f = ss.f
    shapes = V[:f].copy()
    for j in range(shapes.shape[1]):
        col = shapes[:, j]
        k = int(np.argmax(np.abs(col)))
        if abs(col[k]) > 0:
            shapes[:, j] = col / col[k]
    wn = np.abs(lam)
    with np.errstate(invalid="ignore", divide="ignore"):
        zeta = np.where(wn > 0, -lam.real / np.where(wn > 0, wn, 1.0), np.nan)
    return Modes(eigenvalues=lam, vectors=V, shapes=shapes, natural_frequencies=wn,
                 damping_ratios=zeta, damped_frequencies=np.abs(lam.imag),
                 coordinate_names=ss.coordinate_names)


def stability(system: StateSpace | AnyLinearization, t: float | None = None,
              parameters: Mapping[str, float] | None = None, rtol: float = ZERO_RTOL,
              cyclic: Sequence[str] | None = None) -> Stability:
    """Stability verdict with its reason (see the module docstring for the definitions).

    ``rtol`` is the relative tolerance (to the largest |λ|, at least 1) below which a real part
    counts as zero. ``cyclic``: the coordinates to treat as cyclic in Routh's sense (the verdict
    is then on the reduced state matrix, :func:`jourdain.analysis.cyclic.reduced_matrix`);
    None (the default) finds them for a linearization
    (:func:`jourdain.analysis.cyclic.cyclic_coordinates`) and treats none for a
    :class:`StateSpace`; ``()`` judges the full system.

    Raises
    ------
    EvaluationError
        A name in ``cyclic`` that is not a coordinate, or one whose position acts on the motion
        (its column of A is not zero).

    Warns
    -----
    NominalMotionWarning
        When the linearization is about an equilibrium or a steady motion that leaves h ≠ 0
        (:attr:`StateSpace.nominal_check`); the reason ends with the same warning.
    """
    ss = _as_state_space(system, t, parameters)
    if cyclic is None:
        cyclic = () if isinstance(system, StateSpace) else _cyclic_of(system)
    names = check_cyclic(ss.A, ss.coordinate_names, cyclic)
    st = _verdict(reduced_matrix(ss.A, ss.coordinate_names, names) if names else ss.A, rtol)
    if names:
        st = replace(st, cyclic=names, reason=(
            f"{st.reason}; in Routh's sense, on the reduced system without the position(s) of "
            f"the cyclic coordinate(s) {', '.join(names)} (they appear in no equation, only "
            "their rates: their drift is left out, their rates are judged)"))
    check = ss.nominal_check
    if check is None or check.kind == "nominal motion":
        return st
    if check.is_solution:
        return replace(st, nominal_is_solution=True)
    message = check.message()
    warn(message, NominalMotionWarning)
    return replace(st, reason=f"{st.reason}. WARNING: {message}", nominal_is_solution=False)


def _cyclic_of(lin: AnyLinearization) -> tuple[str, ...]:
    known = getattr(lin, "cyclic_in_eta", None)  # a general system's: found in its numbers
    if known is not None:
        return tuple(known)
    if callable(getattr(lin, "state_space", None)):  # a closed system's, in numbers: none
        return ()
    base = lin.linearization if hasattr(lin, "linearization") else lin
    eom = getattr(base, "equations_of_motion", None)
    return cyclic_coordinates(eom if eom is not None else base.system)


def _verdict(A: np.ndarray, rtol: float) -> Stability:
    lam = np.linalg.eigvals(A)
    n = lam.size
    scale = max(1.0, float(np.abs(lam).max(initial=0.0)))
    tol = rtol * scale
    # eigenvalues that split from a defective (Jordan) eigenvalue sit about sqrt(eps)·scale
    # apart; group them first and judge each group by its centre
    cluster_tol = 1e3 * np.sqrt(np.finfo(float).eps) * scale
    groups: list[list[int]] = []
    for i in np.argsort(lam.real):
        for grp in groups:
            if abs(lam[i] - lam[grp[0]]) <= cluster_tol:
                grp.append(int(i))
                break
        else:
            groups.append([int(i)])
    max_re = float(lam.real.max(initial=-np.inf))
    unstable, on_axis, defective = [], [], []
    for grp in groups:
        centre = lam[grp].mean()
        if centre.real > tol:
            unstable.extend(grp)
        elif centre.real >= -tol:
            on_axis.extend(grp)
            if len(grp) > 1:
                # geometric multiplicity from the rank of A − λI
                sv = np.linalg.svd(A - centre * np.eye(n), compute_uv=False)
                geometric = int(np.sum(sv <= 1e3 * np.sqrt(np.finfo(float).eps) * scale))
                if geometric < len(grp):
                    defective.append((centre, len(grp), geometric))
    if unstable:
        lu = lam[unstable]
        worst = lu[np.argmax(lu.real)]
        kind = ("flutter: an oscillating mode grows" if abs(worst.imag) > tol
                else "divergence: a real eigenvalue is positive")
        reason = (f"{len(lu)} eigenvalue(s) with positive real part, largest "
                  f"λ = {_fmt(worst, tol)} ({kind})")
        return Stability(UNSTABLE, reason, max_re, lu)
    if defective:
        centre, alg, geo = defective[0]
        reason = (f"eigenvalue λ = {_fmt(centre, tol)} on the imaginary axis is repeated {alg} times "
                  f"with only {geo} eigenvector(s): the motion grows linearly in time "
                  "(e.g. a free rigid-body coordinate without stiffness)")
        return Stability(UNSTABLE, reason, max_re, lam[on_axis])
    if on_axis:
        la = lam[on_axis]
        reason = (f"no eigenvalue has a positive real part; {len(la)} lie on the imaginary axis "
                  f"(undamped or rigid-body motion, e.g. λ = {_fmt(la[np.argmax(la.imag)], tol)}) "
                  "and are semisimple")
        return Stability(MARGINALLY_STABLE, reason, max_re, la)
    worst = lam[np.argmax(lam.real)]
    reason = (f"all {n} eigenvalues have negative real parts (largest real part {max_re:.6g} "
              f"at λ = {_fmt(worst, tol)})")
    return Stability(ASYMPTOTICALLY_STABLE, reason, max_re, np.array([worst]))


def _fmt(z: complex, tol: float) -> str:
    """``z`` for a sentence, parts below ``tol`` (round-off about the axes) shown as 0."""
    z = _chop(complex(z), tol)
    return f"{z.real:.6g}{z.imag:+.6g}j"
