"""Time integration of the equations of motion ``M(y,t)·ÿ + k(y,ẏ,t) = q(y,ẏ,t)``.

:func:`simulate` integrates from ``y(t0) = y0, ẏ(t0) = ẏ0`` and returns a
:class:`~jourdain.simulation.results.Results`. The default methods ``"DOP853"`` and ``"RK45"``
(Dormand–Prince 8(5,3) and 5(4), adaptive steps, continuous extension) and the stiff method
``"Radau"`` (Radau IIA, order 5) run their step loop in C (:mod:`jourdain.numeric.integrator_c`),
calling the generated ``M, k, q`` code and a Cholesky factorization of ``M`` in every
evaluation, without returning to Python between steps. ``"BDF"``, ``"LSODA"`` and
``"scipy:<method>"`` use :func:`scipy.integrate.solve_ivp` with the same compiled right-hand
side (one call from Python per evaluation).

Inputs ``u(t)`` are given per input name as

- a number (constant),
- a table ``(times, values)`` (linear interpolation, held constant outside; runs in C),
- an expression in ``t``, the coordinates, their rates and the parameters (compiled into the C
  loop; state feedback is allowed),
- a Python callable ``u(t) -> float`` or ``u(t, y, yd) -> float`` (state feedback), called back
  from C at every evaluation: much slower.

Events are :class:`Event` objects holding an expression in ``t``, ``y``, ``ẏ``, parameters and
inputs; the run records the times at which it crosses zero (located on the continuous extension)
and stops at the first crossing of a terminal event.

The run goes in chunks so that a long run shows progress, can write its results as it goes
(``output=``) and, when interrupted (Ctrl-C, an exception in an input callable), keeps what was
computed: the results say ``interrupted`` and why.
"""

from __future__ import annotations

import ctypes
import inspect
import math
import numbers
import signal
import sys
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING, Any

import numpy as np
import symengine as se

from ..errors import EvaluationError, JourdainError, SingularMassMatrix
from ..model.expressions import as_expr
from ..numeric import CompiledFunction, lambdify, mkq_function, parameter_vector
from ..numeric.diagnose import nonfinite_sources
from ..numeric.integrator_c import source as integrator_source
from ..numeric.toolchain import build, content_key
from ..symbolic import SymMatrix
from .results import Results

if TYPE_CHECKING:
    from ..model.system import System

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

_DONE, _CONTINUE, _EVENT = 0, 1, 2
_ESINGULAR, _ENAN, _ESTEP, _ECALLBACK, _ENOMEM = -1, -2, -3, -4, -5


class IntegrationError(JourdainError, RuntimeError):
    """The integration failed: a NaN in the state, a step size below the round-off limit."""


@dataclass(frozen=True)
class Event:
    """A zero crossing to record (and to stop at, when ``terminal``).

    Parameters
    ----------
    expr : expression in t, coordinates, rates, parameters and inputs
    direction : +1 records rising crossings only, -1 falling ones, 0 both
    terminal : stop the run at the first crossing
    name : label in the results (default: the expression as text)
    """

    expr: Any
    direction: int = 0
    terminal: bool = False
    name: str | None = None

    @property
    def label(self) -> str:
        return self.name if self.name is not None else str(self.expr)


class _Problem(ctypes.Structure):
    _fields_ = [
        ("f", ctypes.c_long), ("nu", ctypes.c_long), ("nev", ctypes.c_long),
        ("mkq", ctypes.c_void_p), ("uexpr", ctypes.c_void_p), ("events", ctypes.c_void_p),
        ("ucb", ctypes.c_void_p), ("p", ctypes.c_void_p), ("u_const", ctypes.c_void_p),
        ("u_kind", ctypes.c_void_p), ("tab_off", ctypes.c_void_p), ("tab_t", ctypes.c_void_p),
        ("tab_v", ctypes.c_void_p), ("ev_dir", ctypes.c_void_p), ("ev_term", ctypes.c_void_p),
        ("method", ctypes.c_int), ("rtol", ctypes.c_double), ("atol", ctypes.c_void_p),
        ("h_max", ctypes.c_double), ("h_first", ctypes.c_double), ("accel", ctypes.c_void_p),
    ]


_CALLBACK = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_double, ctypes.POINTER(ctypes.c_double),
                             ctypes.POINTER(ctypes.c_double), ctypes.POINTER(ctypes.c_double))


#: compiler flags of the integrator library, after toolchain.CFLAGS
INTEGRATOR_FLAGS = ("-O3",)


@lru_cache(maxsize=1)
def integrator_library() -> ctypes.CDLL:
    """The compiled integrator (built once, cached on disk like the model code)."""
    src = integrator_source()
    # -O3: the stage sums and the error norm over the state vector are vectorized; 10 % less
    # time per right-hand side at 2f + 1 = 27 states (12-link pendulum on a cart), 3 % at 11
    lib = build(content_key("integrator", src, *INTEGRATOR_FLAGS), src, INTEGRATOR_FLAGS)
    vp, lg, db = ctypes.c_void_p, ctypes.c_long, ctypes.c_double
    lib.jd_integrate.restype = ctypes.c_int
    lib.jd_integrate.argtypes = [vp, db, vp, vp, vp, vp, vp, vp, lg, vp, vp, vp, vp, lg, vp, vp,
                                 vp, vp, lg, vp, lg, vp]
    lib.jd_rhs.restype = ctypes.c_int
    lib.jd_rhs.argtypes = [vp, db, vp, vp, vp]
    return lib


def _ptr(a: np.ndarray | None) -> int | None:
    """The address of ``a``'s data (``__array_interface__``: 0.6 µs less than ``a.ctypes.data``,
    and a run's set-up takes 25 of them)."""
    return None if a is None else a.__array_interface__["data"][0]


class _Setup:
    """Everything the C loop needs, with the arrays kept alive while it runs."""

    def __init__(self, system: System, mkq: CompiledFunction, p: np.ndarray,
                 inputs: Mapping[str, Any] | None, events: Sequence[Event], method: int,
                 rtol: float, atol: np.ndarray, max_step: float, first_step: float) -> None:
        f, nu = system.f, len(system.inputs)
        self.system = system
        self.p = np.ascontiguousarray(p, dtype=float)
        self.u_const = np.zeros(max(nu, 1))
        self.u_kind = np.zeros(max(nu, 1), dtype=np.intc)
        self.tab_off = np.zeros(nu + 1, dtype=np.int_)
        tab_t: list[np.ndarray] = []
        tab_v: list[np.ndarray] = []
        self.callables: dict[int, Callable[..., Any]] = {}
        self.feedback: dict[int, bool] = {}
        self.callback_error: BaseException | None = None
        exprs: list[se.Basic] = [se.Integer(0)] * nu
        names = system.input_names
        if inputs is not None and not isinstance(inputs, Mapping):
            seq = list(inputs)  # values in the order of system.input_names
            if len(seq) != nu:
                raise EvaluationError(f"inputs: expected {nu} values for {names}, got {len(seq)}")
            inputs = dict(zip(names, seq, strict=True))
        inputs = dict(inputs or {})
        unknown = set(inputs) - set(names)
        if unknown:
            raise EvaluationError(f"unknown input(s) {sorted(unknown)}; inputs are {names}")
        missing = [n for n in names if n not in inputs]
        if missing:
            raise EvaluationError(
                f"input(s) {missing} not given: pass inputs={{{', '.join(repr(m) + ': 0.0' for m in missing)}}}"
                " or a function of time, an expression in t or a table (times, values)")
        state_names = set(system.coordinate_names) | {f"{n}_d" for n in system.coordinate_names}
        allowed = state_names | {"t"} | {k for k, _ in system.parameters}
        n_tab = 0
        for i, name in enumerate(names):
            v = inputs[name]
            if isinstance(v, numbers.Real) and not isinstance(v, bool):
                if not math.isfinite(float(v)):
                    raise EvaluationError(f'input "{name}" = {v!r} is not finite')
                self.u_const[i] = float(v)
            elif isinstance(v, tuple) and len(v) == 2:
                tt = np.asarray(v[0], dtype=float).reshape(-1)
                vv = np.asarray(v[1], dtype=float).reshape(-1)
                if tt.size < 2 or tt.size != vv.size:
                    raise EvaluationError(f'input "{name}": a table needs two arrays of the same '
                                          f"length >= 2, got {tt.size} and {vv.size}")
                if not (np.all(np.isfinite(tt)) and np.all(np.isfinite(vv))):
                    raise EvaluationError(f'input "{name}": table contains NaN or inf')
                if np.any(np.diff(tt) <= 0):
                    raise EvaluationError(f'input "{name}": table times must increase strictly')
                self.u_kind[i] = 1
                tab_t.append(tt)
                tab_v.append(vv)
                n_tab += tt.size
            elif callable(v) and not isinstance(v, se.Basic):
                self.u_kind[i] = 3
                self.callables[i] = v
                self.feedback[i] = _takes_state(v)
            else:
                try:
                    e = as_expr(v, f'input "{name}"')
                except JourdainError as exc:
                    raise EvaluationError(str(exc)) from None
                bad = {str(s) for s in e.free_symbols} - allowed
                if bad:
                    raise EvaluationError(
                        f'input "{name}": expression {e} uses {sorted(bad)}; input expressions '
                        "may use t, coordinates, rates and parameters")
                self.u_kind[i] = 2
                exprs[i] = e
            self.tab_off[i + 1] = n_tab
        self.tab_t = np.concatenate(tab_t) if tab_t else np.zeros(1)
        self.tab_v = np.concatenate(tab_v) if tab_v else np.zeros(1)
        self.uexpr = (lambdify(system, {"u": SymMatrix.column(exprs)})
                      if np.any(self.u_kind == 2) else None)
        allowed_ev = allowed | set(names)
        ev_exprs = []
        for ev in events:
            if not isinstance(ev, Event):
                raise EvaluationError(f"events: expected jourdain.Event objects, got {ev!r}")
            try:
                e = as_expr(ev.expr, f"event {ev.label}")
            except JourdainError as exc:
                raise EvaluationError(str(exc)) from None
            bad = {str(s) for s in e.free_symbols} - allowed_ev
            if bad:
                raise EvaluationError(f"event {ev.label}: unknown symbol(s) {sorted(bad)}")
            if ev.direction not in (-1, 0, 1):
                raise EvaluationError(f"event {ev.label}: direction must be -1, 0 or +1")
            ev_exprs.append(e)
        self.events = list(events)
        self.ev_fn = lambdify(system, {"g": SymMatrix.column(ev_exprs)}) if ev_exprs else None
        self.ev_dir = np.array([ev.direction for ev in events] or [0], dtype=np.intc)
        self.ev_term = np.array([int(ev.terminal) for ev in events] or [0], dtype=np.intc)
        self.atol = np.ascontiguousarray(atol, dtype=float)
        self.mkq = mkq
        self._cb = _CALLBACK(self._callback) if self.callables else None
        self.problem = _Problem(
            f, nu, len(ev_exprs), mkq.address, self.uexpr.address if self.uexpr else None,
            self.ev_fn.address if self.ev_fn else None,
            ctypes.cast(self._cb, ctypes.c_void_p).value if self._cb else None,
            _ptr(self.p), _ptr(self.u_const), _ptr(self.u_kind), _ptr(self.tab_off),
            _ptr(self.tab_t), _ptr(self.tab_v), _ptr(self.ev_dir), _ptr(self.ev_term), method,
            float(rtol), _ptr(self.atol), float(max_step), float(first_step),
            mkq.accel_address)

    def _callback(self, t: float, y: Any, yd: Any, u: Any) -> int:
        try:
            f = self.system.f
            for i, fn in self.callables.items():
                if self.feedback[i]:
                    v = float(fn(t, np.ctypeslib.as_array(y, (f,)).copy(),
                                 np.ctypeslib.as_array(yd, (f,)).copy()))
                else:
                    v = float(fn(t))
                u[i] = v
            return 0
        except BaseException as exc:  # noqa: BLE001 - reported by simulate(), never swallowed
            self.callback_error = exc
            return 1

    def inputs_at(self, t: np.ndarray, x: np.ndarray) -> np.ndarray:
        """Input values at output times (for the results)."""
        f, nu = self.system.f, len(self.system.inputs)
        U = np.zeros((len(t), nu))
        if nu == 0:
            return U
        for i in range(nu):
            k = self.u_kind[i]
            if k == 0:
                U[:, i] = self.u_const[i]
            elif k == 1:
                a, b = self.tab_off[i], self.tab_off[i + 1]
                U[:, i] = np.interp(t, self.tab_t[a:b], self.tab_v[a:b])
            elif k == 3:
                fn = self.callables[i]
                for j, tt in enumerate(t):
                    try:
                        U[j, i] = float(fn(tt, x[j, :f].copy(), x[j, f:2 * f].copy())
                                        if self.feedback[i] else fn(tt))
                    except BaseException:  # noqa: BLE001 - the run already reported it
                        U[j, i] = np.nan
        if self.uexpr is not None:
            ue = self.uexpr.batch(x[:, :f], x[:, f:2 * f], t, self.p, None)["u"][:, :, 0]
            mask = self.u_kind[:nu] == 2
            U[:, mask] = ue[:, mask]
        return U


def _takes_state(fn: Callable[..., Any]) -> bool:
    """True for ``u(t, y, yd)`` (state feedback), False for ``u(t)``."""
    try:
        params = inspect.signature(fn).parameters.values()
    except (TypeError, ValueError):
        return False
    positional = [p for p in params if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    return len(positional) >= 3 or any(p.kind == p.VAR_POSITIONAL for p in params)


# --- options: one check each, shared by the API, the model files and the command line ------
# Each raises EvaluationError naming the option as the caller calls it (``name``: "rtol" in
# Python, "--rtol" on the command line); the model file loader adds the file, line and key.

def _real(value: Any, name: str) -> float:
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


def check_t_span(t_span: Any, name: str = "t_span") -> tuple[float, float]:
    """``(t0, t1)``: finite, ``t1 > t0``, both within ±``MAX_TIME``, the span above the
    round-off of t."""
    try:
        t0, t1 = (_real(v, name) for v in t_span)
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
        te = np.ascontiguousarray(t_eval, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise EvaluationError(f"{name} must be a sequence of numbers, got "
                              f"{_shown(t_eval)}") from None
    top = max_samples(f, n_inputs)
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


def _error(code: int, setup: _Setup, fail: np.ndarray) -> JourdainError:
    sysm = setup.system
    f = sysm.f
    t = fail[0]
    state = ", ".join(f"{n}={v:.6g}" for n, v in zip(sysm.coordinate_names, fail[1:1 + f],
                                                       strict=True))
    rates = ", ".join(f"{n}_d={v:.6g}" for n, v in zip(sysm.coordinate_names,
                                                       fail[1 + f:1 + 2 * f], strict=True))
    where = f"at t = {t:.9g}, state {state}; rates {rates}"
    if code == _ESINGULAR:
        return SingularMassMatrix(f"the mass matrix M of {sysm.name!r} is not positive definite "
                                  f"{where}")
    if code == _ENAN:
        y, yd = fail[1:1 + f], fail[1 + f:1 + 2 * f]
        try:
            u = setup.inputs_at(np.array([t]), np.concatenate([y, yd])[None, :])[0]
            sources = nonfinite_sources(sysm, y, yd, float(t), setup.p, np.asarray(u, float))
        except Exception:  # noqa: BLE001 - the trace is a courtesy; the error stands
            sources = []
        cause = ("caused by " + "; ".join(sources)) if sources else \
            "check the parameters and inputs"
        return IntegrationError(f"NaN or inf in the state or its derivative {where} ({cause})")
    if code == _ESTEP:
        hint = ("try method='Radau'" if setup.problem.method != C_METHODS["Radau"] else
                "the stiff method Radau does not get past it either: look for a singular "
                "configuration or a force that grows without bound there")
        return IntegrationError(f"step size fell below the round-off limit {where}; the motion "
                                f"may be singular or very stiff ({hint})")
    if code == _ECALLBACK:
        return IntegrationError(f"an input function raised {setup.callback_error!r} {where}")
    return IntegrationError(f"integrator failed with code {code}")


def simulate(system: System, t_span: tuple[float, float], y0: Any, yd0: Any,
             parameters: Mapping[str, float] | None = None,
             inputs: Mapping[str, Any] | None = None, method: str = DEFAULT_METHOD,
             rtol: float = DEFAULT_RTOL, atol: float | Sequence[float] = DEFAULT_ATOL,
             t_eval: Sequence[float] | None = None, events: Sequence[Event] = (),
             max_step: float = math.inf, first_step: float | None = None,
             progress: bool | Callable[[float, float], None] = False,
             output: str | None = None, raise_on_interrupt: bool = False) -> Results:
    """Integrate ``M(y,t)·ÿ + k(y,ẏ,t) = q(y,ẏ,t)`` over ``t_span`` from ``y0, ẏ0``.

    Parameters
    ----------
    system : System
    t_span : (t0, t1) with t1 > t0, both within ±``MAX_TIME`` (1e9)
    y0, yd0 : initial coordinates and rates (f each, in the order of ``system.coordinates``)
    parameters : overrides of parameter values by name (no recompilation)
    inputs : input name -> number, table ``(times, values)``, expression or callable (see module)
    method : "DOP853" (default), "RK45", "Radau" (step loop in C) or "BDF", "LSODA",
        "scipy:Radau", "scipy:RK45", "scipy:DOP853" (SciPy's solve_ivp)
    rtol, atol : tolerances (default :data:`DEFAULT_RTOL` = 1e-8, :data:`DEFAULT_ATOL` =
        1e-10); the local error of each state component stays below ``atol + rtol·|x|``;
        ``RTOL_MIN`` (1e-14) <= rtol < 1; 0 < atol <= ``ATOL_MAX`` (1e3); ``atol`` may be a
        vector of length 2f (y then ẏ)
    t_eval : output times (continuous extension), finite, sorted, within ``t_span``, at most
        ``MAX_SAMPLES`` (and ``MAX_OUTPUT_BYTES`` of results); default: every accepted step
    events : :class:`Event` objects
    max_step, first_step : step size limits; ``max_step`` asks for at most ``MAX_STEPS`` steps
        over ``t_span``
    progress : True prints the progress to stderr (every 0.5 s); a callable gets ``(t, t1)``
        after every chunk of the C loop (about 0.1 s of work, at most 1024 output points)
    output : path of a results file (``.csv``, ``.h5``) written as the run goes (accepted steps
        or ``t_eval`` samples appended under ``status: running``), then complete
    raise_on_interrupt : re-raise KeyboardInterrupt after keeping the results

    Returns
    -------
    Results
        ``t`` (N,), ``y``, ``yd``, ``ydd`` (N, f), ``u`` (N, inputs), ``W`` (N,) the work of the
        generalized applied forces, ``events``, ``status`` and counters.

    Raises
    ------
    SingularMassMatrix
        ``M`` lost positive definiteness (the time and state are in the message).
    IntegrationError
        a NaN/inf in the state or a step size underflow (time and state in the message).
        Both carry the motion up to the failure as ``exc.results`` (C methods).
    EvaluationError
        bad arguments (wrong sizes, NaN initial values, unknown names).
    """
    from ..numeric import _vector

    f = system.f
    t0, t1 = check_t_span(t_span)
    yv = _vector(y0, f, "y0", system.coordinate_names)
    ydv = _vector(yd0, f, "yd0", [f"{n}_d" for n in system.coordinate_names])
    method = check_method(method)
    rtol = check_rtol(rtol)
    a = check_atol(atol, 2 * f)
    atol_x = np.concatenate([a, [a.min()]])
    max_step = check_max_step(max_step, t0, t1)
    if first_step is not None:
        first_step = _real(first_step, "first_step")
        if not (first_step > 0 and math.isfinite(first_step)):
            raise EvaluationError(f"first_step must be a positive number, got {first_step!r}")
    te = None if t_eval is None else check_t_eval(t_eval, t0, t1, f, len(system.inputs))
    if output is not None and not str(output).lower().endswith(OUTPUT_SUFFIXES):
        raise EvaluationError(f"output = {_shown(str(output))}: a results file ends in "
                              f"{', '.join(OUTPUT_SUFFIXES)}")
    p = parameter_vector(system, parameters)
    mkq = mkq_function(system)
    setup = _Setup(system, mkq, p, inputs, events, C_METHODS.get(method, 1), rtol, atol_x,
                   max_step, first_step or 0.0)
    x0 = np.concatenate([yv, ydv, [0.0]])
    integrator_library()  # built or loaded once per process, outside the timed run
    wall = time.perf_counter()
    if method in C_METHODS:
        run = _run_c(setup, t0, t1, x0, te, progress, output)
    else:
        run = _run_scipy(setup, method, t0, t1, x0, te, rtol, atol_x, max_step, first_step)
    run["wall_time"] = time.perf_counter() - wall
    res = _results(setup, run, method, rtol, a, p)
    if output is not None:
        res.save(output)
    if run.get("error") is not None:
        # the motion up to the failure is kept on the exception (and in ``output``)
        run["error"].results = res
        raise run["error"]
    if res.interrupted and raise_on_interrupt and isinstance(run.get("exception"),
                                                             KeyboardInterrupt):
        raise run["exception"]
    return res


def _run_c(setup: _Setup, t0: float, t1: float, x0: np.ndarray, te: np.ndarray | None,
           progress: bool | Callable[[float, float], None], output: str | None) -> dict:
    lib = integrator_library()
    system = setup.system
    f = system.f
    n = 2 * f + 1
    nev = len(setup.events)
    st = np.array([t0, 0.0, 0.0, 0.0])  # t, step size, last trial rejected, last error
    x = x0.copy()
    k0 = np.zeros(n)
    g_old = np.zeros(max(nev, 1))
    cnt = np.zeros(5, dtype=np.int_)
    i_eval = np.zeros(1, dtype=np.int_)
    n_out = np.zeros(1, dtype=np.int_)
    n_ev = np.zeros(1, dtype=np.int_)
    fail = np.zeros(n + 1)
    ev_cap = 100000 if nev else 1  # crossings recorded (the message says if more were dropped)
    ev_t = np.empty(ev_cap)
    ev_x = np.empty((ev_cap, n))
    ev_i = np.empty(ev_cap, dtype=np.int_)
    if te is not None:
        cap = te.size
        out_t = np.empty(cap)
        out_x = np.empty((cap, n))
        out_dx = np.empty((cap, n))
    chunks_t: list[np.ndarray] = []
    chunks_x: list[np.ndarray] = []
    chunks_dx: list[np.ndarray] = []
    if te is None:
        cap = 1024
    writer = (_Writer(output, system)
              if output and str(output).lower().endswith(OUTPUT_SUFFIXES) else None)
    status = "finished"
    message = "reached the end of t_span"
    exception: BaseException | None = None
    error: JourdainError | None = None
    written = 0
    id_chunk = kept = 0

    def _keep_chunk() -> None:
        nonlocal kept
        chunks_t.append(out_t[:n_out[0]])
        chunks_x.append(out_x[:n_out[0]])
        chunks_dx.append(out_dx[:n_out[0], f:2 * f].copy())  # ÿ only: half the memory
        kept = id_chunk
    max_steps = steps_per_call(f)
    t_last_report = time.perf_counter()
    # Ctrl-C sets a flag that is looked at between calls of the C loop, so it never lands in
    # the middle of bookkeeping; a second Ctrl-C raises at once
    interrupted = [False]
    old_handler = None
    if threading.current_thread() is threading.main_thread():
        def on_sigint(signum: int, frame: Any) -> None:
            if interrupted[0]:
                raise KeyboardInterrupt
            interrupted[0] = True

        try:
            old_handler = signal.signal(signal.SIGINT, on_sigint)
        except ValueError:  # not the main interpreter
            old_handler = None
    try:
        while True:
            if te is None:
                out_t = np.empty(cap)
                out_x = np.empty((cap, n))
                out_dx = np.empty((cap, n))
                n_out[0] = 0
            id_chunk += 1
            code = lib.jd_integrate(
                ctypes.byref(setup.problem), t1, _ptr(st), _ptr(x), _ptr(k0), _ptr(g_old),
                _ptr(cnt), _ptr(te), 0 if te is None else te.size, _ptr(i_eval), _ptr(out_t),
                _ptr(out_x), _ptr(out_dx), cap, _ptr(n_out), _ptr(ev_t), _ptr(ev_x), _ptr(ev_i),
                ev_cap, _ptr(n_ev), max_steps, _ptr(fail))
            if te is None:
                _keep_chunk()
                if writer:
                    writer.append(chunks_t[-1], chunks_x[-1])
            elif writer:
                writer.append(out_t[written:n_out[0]], out_x[written:n_out[0]])
                written = int(n_out[0])
            if code < 0:
                if code == _ECALLBACK and isinstance(setup.callback_error, KeyboardInterrupt):
                    raise setup.callback_error
                err = _error(code, setup, fail)
                if code == _ECALLBACK:
                    status, message, exception = "interrupted", str(err), setup.callback_error
                    break
                status, message, error = "failed", str(err), err
                break
            if code == _EVENT:
                k = int(ev_i[n_ev[0] - 1])
                status = "event"
                message = f"terminal event {setup.events[k].label!r} at t = {st[0]:.9g}"
                break
            if code == _DONE:
                break
            if interrupted[0]:
                raise KeyboardInterrupt
            now = time.perf_counter()
            if callable(progress):
                progress(float(st[0]), t1)
            elif progress and now - t_last_report > 0.5:
                t_last_report = now
                print(f"\rsimulating {system.name}: t = {st[0]:.4g} of {t1:.4g} "
                      f"({100 * (st[0] - t0) / (t1 - t0):.0f} %)", end="", file=sys.stderr)
    except KeyboardInterrupt as exc:
        if te is None and kept < id_chunk:  # Ctrl-C came right after a call returned
            _keep_chunk()
        status = "interrupted"
        message = "interrupted by the user (Ctrl-C); the motion up to there is kept"
        exception = exc
    finally:
        if old_handler is not None:
            signal.signal(signal.SIGINT, old_handler)
        if writer:
            writer.handle.close()
    if progress is True:
        print(file=sys.stderr)
    if te is not None:
        t_out, x_out = out_t[:n_out[0]], out_x[:n_out[0]]
        dx_out = out_dx[:n_out[0], f:2 * f]
    elif chunks_t and sum(len(c) for c in chunks_t):
        t_out, x_out = np.concatenate(chunks_t), np.concatenate(chunks_x)
        dx_out = np.concatenate(chunks_dx)
    else:  # failed or interrupted at the start: the initial state only
        t_out, x_out, dx_out = np.array([t0]), x0[None, :].copy(), None
    if isinstance(exception, KeyboardInterrupt):
        message = (f"interrupted by the user (Ctrl-C) at t = {t_out[-1]:.9g}; the motion up "
                   "to there is kept")
    m = int(n_ev[0])
    if nev and m == ev_cap:
        message += f"; only the first {ev_cap} event crossings were recorded"
    return {"t": t_out, "x": x_out, "ydd": dx_out, "status": status, "message": message,
            "exception": exception, "error": error, "nfev": int(cnt[0]), "nstep": int(cnt[1]),
            "naccept": int(cnt[2]), "nreject": int(cnt[3]),
            "events": (ev_t[:m].copy(), ev_x[:m].copy(), ev_i[:m].copy())}


def _run_scipy(setup: _Setup, method: str, t0: float, t1: float, x0: np.ndarray,
               te: np.ndarray | None, rtol: float, atol: np.ndarray, max_step: float,
               first_step: float | None) -> dict:
    from scipy.integrate import solve_ivp

    lib = integrator_library()
    n = x0.size
    fail = np.zeros(n + 1)
    nfev = [0]

    def fun(t: float, x: np.ndarray) -> np.ndarray:
        xc = np.ascontiguousarray(x, dtype=float)
        dx = np.empty(n)
        nfev[0] += 1
        code = lib.jd_rhs(ctypes.byref(setup.problem), float(t), xc.ctypes.data, dx.ctypes.data,
                          fail.ctypes.data)
        if code:
            if code == _ECALLBACK and setup.callback_error is not None:
                raise setup.callback_error
            raise _error(code, setup, fail)
        return dx

    ev_funcs = []
    f = setup.system.f
    for k, ev in enumerate(setup.events):
        def g(t: float, x: np.ndarray, k: int = k) -> float:
            u = setup.inputs_at(np.array([t]), x[None, :])[0]
            return float(setup.ev_fn(x[:f], x[f:2 * f], t, setup.p, u)["g"][k, 0])
        g.terminal = ev.terminal  # type: ignore[attr-defined]
        g.direction = ev.direction  # type: ignore[attr-defined]
        ev_funcs.append(g)
    status, message, exception = "finished", "reached the end of t_span", None
    kw: dict[str, Any] = {"max_step": max_step}
    if first_step:
        kw["first_step"] = first_step
    try:
        sol = solve_ivp(fun, (t0, t1), x0, method=method.removeprefix("scipy:"), t_eval=te, rtol=rtol, atol=atol,
                        events=ev_funcs or None, **kw)
    except KeyboardInterrupt as exc:
        raise IntegrationError(f"{method} run interrupted; the SciPy methods keep no partial "
                               "results (use DOP853 or RK45 for that)") from exc
    if sol.status == -1:
        raise IntegrationError(f"{method}: {sol.message}")
    ev_t, ev_x, ev_i = [], [], []
    if ev_funcs:
        for k, (tt, xx) in enumerate(zip(sol.t_events, sol.y_events, strict=True)):
            ev_t.extend(tt)
            ev_x.extend(xx)
            ev_i.extend([k] * len(tt))
        order = np.argsort(ev_t)
        ev_t = list(np.asarray(ev_t)[order])
        ev_x = list(np.asarray(ev_x).reshape(-1, n)[order])
        ev_i = list(np.asarray(ev_i)[order])
    if sol.status == 1:
        status, message = "event", f"terminal event at t = {sol.t[-1]:.9g}"
    return {"t": sol.t, "x": sol.y.T, "status": status, "message": message,
            "exception": exception, "nfev": nfev[0], "nstep": len(sol.t), "naccept": len(sol.t),
            "nreject": 0,
            "events": (np.asarray(ev_t, dtype=float), np.asarray(ev_x, dtype=float).reshape(-1, n),
                       np.asarray(ev_i, dtype=int))}


def _results(setup: _Setup, run: dict, method: str, rtol: float, atol: np.ndarray,
             p: np.ndarray) -> Results:
    system = setup.system
    f = system.f
    t, x = run["t"], run["x"]
    U = setup.inputs_at(t, x) if len(t) else np.zeros((0, len(system.inputs)))
    ydd = run.get("ydd")
    if ydd is not None and len(ydd) == len(t):  # from the C loop (NaN where M was singular)
        ydd = np.ascontiguousarray(ydd)
    else:
        ydd = accelerations(setup.mkq, x[:, :f], x[:, f:2 * f], t, p, U)
    ev_t, ev_x, ev_i = run["events"]
    events = {ev.label: [] for ev in setup.events}
    for tt, xx, k in zip(ev_t, ev_x, ev_i, strict=True):
        events[setup.events[int(k)].label].append((float(tt), xx[:f].copy(), xx[f:2 * f].copy()))
    return Results(
        system=system, t=t, y=x[:, :f].copy(), yd=x[:, f:2 * f].copy(), ydd=ydd, u=U,
        W=x[:, 2 * f].copy(), parameters=dict(zip((k for k, _ in system.parameters), p.tolist(),
                                                  strict=True)),
        method=method, rtol=rtol, atol=atol, status=run["status"], message=run["message"],
        nfev=run["nfev"], nsteps=run["nstep"], n_accepted=run["naccept"],
        n_rejected=run["nreject"], wall_time=run["wall_time"],
        events={k: _event_arrays(v, f) for k, v in events.items()},
        exception=run["exception"])


def _event_arrays(items: list, f: int) -> dict[str, np.ndarray]:
    return {"t": np.array([i[0] for i in items]),
            "y": np.array([i[1] for i in items]).reshape(-1, f),
            "yd": np.array([i[2] for i in items]).reshape(-1, f)}


def accelerations(mkq: CompiledFunction, y: np.ndarray, yd: np.ndarray, t: np.ndarray,
                  p: np.ndarray, u: np.ndarray) -> np.ndarray:
    """``ÿ = M⁻¹(q - k)`` at many states (one batched evaluation, one batched solve)."""
    n, f = y.shape
    if n == 0:
        return np.zeros((0, f))
    out = mkq.batch(y, yd, t, p, u if u.shape[1] else None)
    M, k, q = out["M"], out["k"][:, :, 0], out["q"][:, :, 0]
    try:
        return np.linalg.solve(M, (q - k)[:, :, None])[:, :, 0]
    except np.linalg.LinAlgError:  # a singular state (kept by a failed run): NaN there
        ydd = np.full((n, f), np.nan)
        for i in range(n):
            try:
                ydd[i] = np.linalg.solve(M[i], q[i] - k[i])
            except np.linalg.LinAlgError:
                pass
        return ydd


class _Writer:
    """Appends accepted steps to an HDF5 results file while the run goes."""

    def __init__(self, path: str, system: System) -> None:
        from .results import open_incremental

        self.path = path
        self.handle = open_incremental(path, system)

    def append(self, t: np.ndarray, x: np.ndarray) -> None:
        from .results import append_incremental

        append_incremental(self.handle, t, x)
