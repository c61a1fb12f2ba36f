"""The options of a simulation: the methods, the defaults, the bounds and one check per option,
shared by :func:`jourdain.simulate`, :meth:`System.simulate`, the ``[simulation]`` table of model
files and ``jourdain simulate`` (``docs/method.md``, "Numbers, simulation, files";
``docs/model-format.md``).

Each check raises :class:`~jourdain.errors.EvaluationError` naming the option as the caller
calls it (``name``: "rtol" in Python, "--rtol" on the command line); the model file loader adds
the file, line and key.
"""

from __future__ import annotations

import math
import numbers
from functools import lru_cache
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import EvaluationError

if TYPE_CHECKING:
    pass


#: methods whose step loop runs in C, and their codes in the C library
C_METHODS = {"DOP853": 1, "RK45": 0, "DOPRI5": 0, "Radau": 2}
#: methods of scipy.integrate.solve_ivp (one call from Python per right-hand side)
SCIPY_METHODS = ("BDF", "LSODA", "scipy:Radau", "scipy:RK45", "scipy:DOP853")

#: the defaults of every simulation: :func:`simulate`, :meth:`System.simulate`, the
#: ``[simulation]`` table of model files and ``jourdain simulate`` all take them from here
DEFAULT_METHOD = "DOP853"
DEFAULT_RTOL = 1e-8
DEFAULT_ATOL = 1e-10
DEFAULT_T_END = 5.0
DEFAULT_SAMPLES = 501

#: the bounds of the options (docs/model-format.md, ``[simulation]``): below ``RTOL_MIN`` the
#: error estimate is round-off; an ``atol`` above ``ATOL_MAX`` switches the error control off
#: for states of any ordinary size; ``|t| <= MAX_TIME`` (a longer run of a mechanical model
#: cannot finish); ``max_step`` asks for at most ``MAX_STEPS`` steps over the span; the output
#: holds ``MIN_SAMPLES`` to ``MAX_SAMPLES`` samples and at most ``MAX_OUTPUT_BYTES``
RTOL_MIN = 1e-14
ATOL_MAX = 1e3
MAX_TIME = 1e9
MAX_STEPS = 10**9
MIN_SAMPLES, MAX_SAMPLES = 2, 10**7
MAX_OUTPUT_BYTES = 4 * 2**30
#: the results files that ``output=`` writes as the run goes (Results.save's formats)
OUTPUT_SUFFIXES = (".csv", ".h5", ".hdf5")


# --- options: one check each, shared by the API, the model files and the command line ------
# Each raises EvaluationError naming the option as the caller calls it (``name``: "rtol" in
# Python, "--rtol" on the command line); the model file loader adds the file, line and key.

def _real(value: Any, name: str) -> float:
    kind = type(value)
    if kind is float:  # the common cases first: isinstance of an ABC costs half a microsecond
        return value
    if kind is int:
        return float(value)
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise EvaluationError(f"{name} must be a number, got {_shown(value)}")
    return float(value)


def _shown(value: Any, n: int = 60) -> str:
    """``value`` for a message: its repr, clipped, control characters escaped."""
    text = repr(value)
    return text if len(text) <= n else f"{text[:n // 2]} … {text[-n // 2:]}"


def check_method(method: Any, name: str = "method") -> str:
    """``method`` if it is one of :data:`C_METHODS` or :data:`SCIPY_METHODS`."""
    if not isinstance(method, str) or (method not in C_METHODS and method not in SCIPY_METHODS):
        raise EvaluationError(f"unknown {name} {_shown(method)}; methods are "
                              f"{', '.join(sorted(C_METHODS) + list(SCIPY_METHODS))}")
    return method


def check_rtol(rtol: Any, name: str = "rtol") -> float:
    """The relative tolerance: ``RTOL_MIN <= rtol < 1``."""
    v = _real(rtol, name)
    if not (RTOL_MIN <= v < 1):
        raise EvaluationError(
            f"{name} = {v:g}: the relative tolerance must be at least {RTOL_MIN:g} (below it "
            "the error estimate is round-off) and below 1 (at 1 or more nothing is controlled)")
    return v


def check_atol(atol: Any, size: int, name: str = "atol") -> np.ndarray:
    """The absolute tolerance, one number or ``size`` numbers, each in ``(0, ATOL_MAX]``;
    returned as ``size`` numbers."""
    if type(atol) is float and 0.0 < atol <= ATOL_MAX:  # the common case, without NumPy
        return np.full(size, atol)
    if isinstance(atol, (str, bytes, bool)) or atol is None:
        raise EvaluationError(f"{name} must be a number or {size} numbers, got {_shown(atol)}")
    try:
        a = np.asarray(atol, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise EvaluationError(f"{name} must be a number or {size} numbers, got "
                              f"{_shown(atol)}") from None
    if a.size == 1:
        a = np.full(size, a[0])
    if a.size != size:
        raise EvaluationError(f"{name} must be a number or {size} numbers (y then ẏ), got "
                              f"{a.size} numbers")
    if not np.all(np.isfinite(a)) or not np.all(a > 0) or np.any(a > ATOL_MAX):
        bad = next(float(x) for x in a if not (math.isfinite(x) and 0 < x <= ATOL_MAX))
        raise EvaluationError(
            f"{name} = {bad:g}: the absolute tolerance must be positive, finite and at most "
            f"{ATOL_MAX:g} (a larger one switches the error control off)")
    return a


def checked_options(method: Any, rtol: Any, atol: Any, size: int) -> tuple[str, float, np.ndarray]:
    """``method``, ``rtol`` and ``atol`` checked (:func:`check_method`, :func:`check_rtol`,
    :func:`check_atol` with ``size`` = 2f): the method, rtol, and the ``size`` absolute
    tolerances with their smallest appended, the work W's (read-only). Memoized where all
    three are plain ``str``, ``float``, ``float`` (exact types: ``True == 1`` must not find
    the entry of ``1``, nor a subclass that of its base): a check that raises is never kept,
    so a bad value raises every time."""
    if type(method) is str and type(rtol) is float and type(atol) is float:
        return _checked_plain(method, rtol, atol, size)
    return _check_options(method, rtol, atol, size)


def _check_options(method: Any, rtol: Any, atol: Any, size: int) -> tuple[str, float, np.ndarray]:
    method = check_method(method)
    rtol = check_rtol(rtol)
    a = check_atol(atol, size)
    atol_x = np.concatenate([a, [a.min()]])
    atol_x.flags.writeable = False  # shared by the runs that the memo serves
    return method, rtol, atol_x


_checked_plain = lru_cache(maxsize=64)(_check_options)


def check_t_span(t_span: Any, name: str = "t_span") -> tuple[float, float]:
    """``(t0, t1)``: finite, ``t1 > t0``, both within ±``MAX_TIME``, the span above the
    round-off of t."""
    try:
        a, b = t_span
        t0, t1 = _real(a, name), _real(b, name)
    except (TypeError, ValueError, EvaluationError):
        raise EvaluationError(f"{name} must be (t0, t1), two numbers, got "
                              f"{_shown(t_span)}") from None
    if not (math.isfinite(t0) and math.isfinite(t1)) or t1 <= t0:
        raise EvaluationError(f"{name} must be finite with t1 > t0, got ({t0:g}, {t1:g})")
    if max(abs(t0), abs(t1)) > MAX_TIME:
        raise EvaluationError(
            f"{name} = ({t0:g}, {t1:g}): times must lie within ±{MAX_TIME:g} (about 32 years "
            "in seconds; a run that long cannot finish with the steps of a mechanical model)")
    if t1 - t0 < 1000 * math.ulp(max(abs(t0), abs(t1))):
        raise EvaluationError(f"{name} = ({t0!r}, {t1!r}): the span is below the round-off of t")
    return t0, t1


def check_t_end(t_end: Any, name: str = "t_end") -> float:
    """The end time of a run from t = 0: positive, finite, at most ``MAX_TIME``."""
    v = _real(t_end, name)
    if not (v > 0 and math.isfinite(v)):
        raise EvaluationError(f"{name} = {v:g}: the end time must be positive and finite")
    if v > MAX_TIME:
        raise EvaluationError(
            f"{name} = {v:g}: the end time must be at most {MAX_TIME:g} (about 32 years in "
            "seconds; a run that long cannot finish with the steps of a mechanical model)")
    return v


def max_samples(f: int, n_inputs: int = 0) -> int:
    """The most output samples of a model with ``f`` coordinates and ``n_inputs`` inputs:
    ``MAX_SAMPLES``, fewer where the results would take more than ``MAX_OUTPUT_BYTES``."""
    per_sample = 8 * (2 * (2 * f + 1) + 2 * (3 * f + n_inputs + 4))  # the loop's, the results'
    return max(MIN_SAMPLES, min(MAX_SAMPLES, MAX_OUTPUT_BYTES // per_sample))


def check_samples(samples: Any, f: int, n_inputs: int = 0, name: str = "samples") -> int:
    """The number of output samples: an integer from ``MIN_SAMPLES`` to
    :func:`max_samples`."""
    v = _real(samples, name)
    if not (math.isfinite(v) and v == int(v)):
        raise EvaluationError(f"{name} = {samples!r}: the number of samples must be a whole "
                              "number")
    n, top = int(v), max_samples(f, n_inputs)
    if n < MIN_SAMPLES:
        raise EvaluationError(f"{name} = {n}: at least {MIN_SAMPLES} samples are needed (the "
                              "start and the end)")
    if n > top:
        why = ("" if top == MAX_SAMPLES else
               f" for a model with f = {f} (the results would take more than "
               f"{MAX_OUTPUT_BYTES / 2**30:g} GiB)")
        raise EvaluationError(f"{name} = {n}: at most {top} samples{why}")
    return n


def check_t_eval(t_eval: Any, t0: float, t1: float, f: int, n_inputs: int = 0,
                 name: str = "t_eval") -> np.ndarray:
    """Output times: finite, sorted, within ``[t0, t1]``, at most :func:`max_samples`."""
    try:
        te = np.ascontiguousarray(t_eval, dtype=float)
        if te.ndim != 1:
            te = te.reshape(-1)
    except (TypeError, ValueError):
        raise EvaluationError(f"{name} must be a sequence of numbers, got "
                              f"{_shown(t_eval)}") from None
    # the common cases in a few operations (the checks below cost 6 µs on a call of 20):
    # comparisons with NaN are false, so a NaN fails them and the checks below name it; one
    # time is always within the bound on samples (MIN_SAMPLES and more)
    if te.size == 1 and t0 <= te[0] <= t1:
        return te
    top = max_samples(f, n_inputs)
    if 1 < te.size <= top and t0 <= te[0] and te[-1] <= t1 and not (te[1:] < te[:-1]).any() \
            and math.isfinite(te.dot(te)):  # sorted: all within ±MAX_TIME, x·x cannot overflow
        return te
    if te.size == 0 or te.size > top:
        raise EvaluationError(f"{name} holds {te.size} times: from 1 to {top} are allowed")
    bad = np.flatnonzero(~np.isfinite(te))
    if bad.size:
        raise EvaluationError(f"{name}[{bad[0]}] = {float(te[bad[0]])}: output times must be finite")
    down = np.flatnonzero(np.diff(te) < 0)
    if down.size:
        i = int(down[0])
        raise EvaluationError(f"{name} must be sorted: {name}[{i + 1}] = {te[i + 1]:g} comes "
                              f"after {name}[{i}] = {te[i]:g}")
    if te[0] < t0 or te[-1] > t1:
        raise EvaluationError(f"{name} must lie within t_span ({t0:g}, {t1:g}), got "
                              f"{te[0]:g} … {te[-1]:g}")
    return te


def check_max_step(max_step: Any, t0: float, t1: float, name: str = "max_step") -> float:
    """The largest step: positive (``inf``: no limit) and at least ``(t1 − t0)/MAX_STEPS``."""
    v = _real(max_step, name)
    if not v > 0:
        raise EvaluationError(f"{name} must be positive, got {v:g}")
    if (t1 - t0) / v > MAX_STEPS:
        raise EvaluationError(
            f"{name} = {v:g} over a span of {t1 - t0:g} means at least {(t1 - t0) / v:.3g} "
            f"steps; at most {MAX_STEPS:g} are allowed ({name} >= {(t1 - t0) / MAX_STEPS:.3g})")
    return v


def steps_per_call(f: int) -> int:
    """Steps per call of the C loop: about 0.1 s of work estimated from the model's size
    (Ctrl-C and the progress report wait at most that long). Never from the wall clock: the
    calls must not depend on the machine's load (an explicit method continues exactly across
    calls, and the step sequence of the others depends on where the calls end)."""
    return max(200, min(20000, 4_000_000 // (f * f + 50)))
