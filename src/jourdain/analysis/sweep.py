"""Eigenvalues over a swept parameter, and the value at which stability is lost.

Rotor speed, follower load, a damping coefficient: the linearization is symbolic in every
parameter (and the nominal motion may depend on it, e.g. ``phi = Omega*t``), so a sweep only
evaluates numbers; a :class:`~jourdain.CompiledLinearization` makes long sweeps faster.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import EvaluationError, refuse_closed
from ..numeric.linearization import CompiledLinearization
from ..stages.linearization import Linearization
from .modes import ASYMPTOTICALLY_STABLE, UNSTABLE, _cyclic_of, stability
from .state_space import _from_numbers, _linearization_of, numbers, state_space


@dataclass(frozen=True)
class Sweep:
    """Eigenvalues of the linearization for each value of one parameter.

    Attributes
    ----------
    parameter : str
    values : (n,) array
    eigenvalues : (n, 2f) complex array
        Sorted by imaginary part, then real part, at every value.
    max_real_part : (n,) array
    verdicts : tuple of str
        Stability verdict at every value.
    """

    parameter: str
    values: np.ndarray
    eigenvalues: np.ndarray
    max_real_part: np.ndarray
    verdicts: tuple[str, ...]

    def first_unstable(self) -> float | None:
        """The first swept value at which the system is unstable (None if it never is)."""
        for v, verdict in zip(self.values, self.verdicts, strict=True):
            if verdict == UNSTABLE:
                return float(v)
        return None


def _check_parameter(lin: object, parameter: str) -> None:
    if not isinstance(lin, Linearization):
        raise EvaluationError("sweeps need the symbolic Linearization (or its compiled form); a "
                              "NumericLinearization holds one set of parameter values")
    names = [k for k, _ in lin.system.parameters]
    if parameter not in names:
        raise EvaluationError(f'unknown parameter "{parameter}"; parameters are {names}')


def sweep(lin: Linearization | CompiledLinearization, parameter: str,
          values: Sequence[float] | np.ndarray, t: float = 0.0,
          parameters: Mapping[str, float] | None = None) -> Sweep:
    """Eigenvalues and stability verdicts over ``values`` of ``parameter`` (other parameters at
    their defaults, overridden by ``parameters``); the verdicts in Routh's sense where the
    system has cyclic coordinates (:func:`jourdain.analysis.stability`). A general system's
    linearization (numbers about a steady motion) is taken anew at each value (``lin.at``);
    where its coordinates change along the sweep (a decoupled cyclic speed left out at some
    values), the missing eigenvalues are NaN."""
    if callable(getattr(lin, "at", None)):
        return _sweep_numeric(lin, parameter, values, parameters)
    refuse_closed(getattr(lin, "system", None), "sweeps need the symbolic linearization, which "
                  "closed systems do not have: linearize the closed system at each value "
                  "(System.linearize with parameters) or use a study (jourdain study)")
    base = _linearization_of(lin)
    _check_parameter(base, parameter)
    vals = np.asarray(values, dtype=float).reshape(-1)
    # refuses time-variant results with a clear message (the nominal check is not needed)
    state_space(lin, t, parameters, nominal_check=None)
    cyclic = _cyclic_of(lin)
    eigs, maxre, verdicts = [], [], []
    for v in vals:
        pars = {**(parameters or {}), parameter: float(v)}
        ss = _from_numbers(base, numbers(lin, t, pars), float(t), pars)
        lam = np.linalg.eigvals(ss.A)
        eigs.append(lam[np.lexsort((lam.real, lam.imag))])
        maxre.append(float(lam.real.max()))
        verdicts.append(stability(ss, cyclic=cyclic).verdict)
    return Sweep(parameter, vals, np.array(eigs), np.array(maxre), tuple(verdicts))


def _numeric_at(lin: Any, parameter: str, parameters: Mapping[str, float] | None
                ) -> Callable[[float], Any]:
    """The linearization of a general system at a value of ``parameter`` (checked)."""
    names = list(dict(lin.parameters or {}))
    if parameter not in names:
        raise EvaluationError(f'unknown parameter "{parameter}"; parameters are {names}')
    return lambda v: lin.at({**(parameters or {}), parameter: float(v)})


def _sweep_numeric(lin: Any, parameter: str, values: Sequence[float] | np.ndarray,
                   parameters: Mapping[str, float] | None) -> Sweep:
    """:func:`sweep` of a general system's linearization (see there)."""
    at = _numeric_at(lin, parameter, parameters)
    vals = np.asarray(values, dtype=float).reshape(-1)
    lams, verdicts = [], []
    for v in vals:
        other = at(v)
        lam = np.asarray(other.eigenvalues, complex)
        lams.append(lam[np.lexsort((lam.real, lam.imag))])
        verdicts.append(stability(other).verdict)
    eigs = np.full((len(vals), max((len(x) for x in lams), default=0)), np.nan + 0j)
    for i, x in enumerate(lams):
        eigs[i, :len(x)] = x
    return Sweep(parameter, vals, eigs, np.nanmax(eigs.real, axis=1, initial=-np.inf),
                 tuple(verdicts))


def _boundary_numeric(lin: Any, parameter: str, a: float, b: float,
                      parameters: Mapping[str, float] | None, rtol: float) -> float:
    """:func:`stability_boundary` of a linearization that is numbers about a nominal state
    (a general system's, :class:`jourdain.loops.general_linear.GeneralLinearization`): each
    value linearized anew (``lin.at``), bisection on the verdict to 1e-3 of the bracket, then
    Brent's method on the largest real part (to ``rtol`` and rounding)."""
    from scipy.optimize import brentq

    at = _numeric_at(lin, parameter, parameters)

    def analyse(v: float) -> tuple[str, float]:
        st = stability(at(v))
        return st.verdict, st.max_real_part

    va, vb = analyse(a), analyse(b)
    ua = va[0] == UNSTABLE
    _check_bracket(parameter, a, b, ua, vb[0] == UNSTABLE)

    def narrow(tol: float) -> None:  # bisection on the verdict, to tol of the bracket
        nonlocal a, b, va, vb
        while abs(b - a) > tol * max(1.0, abs(a), abs(b)):
            mid = 0.5 * (a + b)
            vm = analyse(mid)
            if (vm[0] == UNSTABLE) == ua:
                a, va = mid, vm
            else:
                b, vb = mid, vm

    narrow(max(1e-3, rtol))
    if va[1] * vb[1] < 0:
        return float(brentq(lambda v: analyse(v)[1], a, b, xtol=1e-14,
                            rtol=max(rtol * 1e-4, 4 * np.finfo(float).eps)))
    narrow(rtol)
    return 0.5 * (a + b)


def _check_bracket(parameter: str, a: float, b: float, ua: bool, ub: bool) -> None:
    """EvaluationError where both ends of the bracket have the same verdict."""
    if ua == ub:
        word = "unstable" if ua else "stable"
        raise EvaluationError(f'stability_boundary: the system is {word} at both {parameter} = '
                              f"{a} and {parameter} = {b}; give a bracket where it changes")


def stability_boundary(lin: Linearization | CompiledLinearization, parameter: str,
                       lower: float, upper: float, t: float = 0.0,
                       parameters: Mapping[str, float] | None = None,
                       rtol: float = 1e-10) -> float:
    """The value of ``parameter`` in ``[lower, upper]`` at which the verdict changes between
    stable (asymptotically or marginally) and unstable.

    Bisection on the verdict; where the stable side is asymptotically stable, the crossing of
    the largest real part through zero is then found by Brent's method (the verdict's tolerance
    on "zero real part" would otherwise shift the answer by about that tolerance divided by the
    slope). Raises :class:`EvaluationError` when both ends have the same verdict.
    """
    from scipy.optimize import brentq

    if callable(getattr(lin, "at", None)):  # a general system's: linearized anew per value
        return _boundary_numeric(lin, parameter, float(lower), float(upper), parameters, rtol)
    refuse_closed(getattr(lin, "system", None), "the stability boundary needs the symbolic "
                  "linearization, which closed systems do not have")
    base = _linearization_of(lin)
    _check_parameter(base, parameter)

    def analyse(v: float) -> tuple[str, float]:
        pars = {**(parameters or {}), parameter: float(v)}
        ss = _from_numbers(base, numbers(lin, t, pars), float(t), pars)
        st = stability(ss, cyclic=cyclic)
        return st.verdict, st.max_real_part

    state_space(lin, t, parameters, nominal_check=None)  # refuses time-variant ones
    cyclic = _cyclic_of(lin)
    a, b = float(lower), float(upper)
    va, vb = analyse(a)[0], analyse(b)[0]
    ua, ub = va == UNSTABLE, vb == UNSTABLE
    _check_bracket(parameter, a, b, ua, ub)
    # the evaluated point nearest to the boundary that was asymptotically stable
    asym = a if va == ASYMPTOTICALLY_STABLE else b if vb == ASYMPTOTICALLY_STABLE else None
    while abs(b - a) > rtol * max(1.0, abs(a), abs(b)):
        mid = 0.5 * (a + b)
        vm, _ = analyse(mid)
        if vm == ASYMPTOTICALLY_STABLE:
            asym = mid
        if (vm == UNSTABLE) == ua:
            a = mid
        else:
            b = mid
    unstable_end = a if ua else b
    if asym is not None and analyse(unstable_end)[1] > 0:
        # the crossing of the largest real part through zero, between the nearest
        # asymptotically stable point and the unstable end
        return float(brentq(lambda v: analyse(v)[1], asym, unstable_end, xtol=1e-14,
                            rtol=4 * np.finfo(float).eps))
    return 0.5 * (a + b)
