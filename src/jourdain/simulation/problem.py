"""What the compiled step loop integrates: the events to record, the inputs (numbers, tables,
compiled expressions, Python callables), the ``jd_problem`` structure that the C library reads,
and the library itself (:mod:`jourdain.numeric.integrator_c`, compiled once and cached).
"""

from __future__ import annotations

import ctypes
import inspect
import math
import numbers
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, overload

import numpy as np
import symengine as se

from ..errors import EvaluationError, JourdainError
from ..model.expressions import as_expr
from ..numeric import CompiledFunction, lambdify
from ..numeric.integrator_c import integrator_library
from ..numeric.toolchain import build_soon
from ..symbolic import SymMatrix
from .options import C_METHODS

if TYPE_CHECKING:
    from ..model.system import System


_DONE, _CONTINUE, _EVENT = 0, 1, 2
_ESINGULAR, _ENAN, _ESTEP, _ECALLBACK, _ENOMEM = -1, -2, -3, -4, -5


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
        ("accel_ctx", ctypes.c_void_p), ("ctx", ctypes.c_void_p),
    ]


_CALLBACK = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_double, ctypes.POINTER(ctypes.c_double),
                             ctypes.POINTER(ctypes.c_double), ctypes.POINTER(ctypes.c_double))


def build_integrator_soon() -> None:
    """Start compiling the integrator library in a thread and return at once
    (:func:`jourdain.numeric.toolchain.build_soon`): for a caller that will simulate after
    other work, such as ``jourdain run``, which derives, compiles and evaluates the model
    meanwhile (the thread loads a library cached or prebuilt). Where this process has loaded
    it, nothing is done. A later :func:`integrator_library` waits for the build, or builds it
    itself where this one failed, and raises its error then. Call it after any ``fork`` of
    this process (a child forked meanwhile would compile it again)."""
    if not integrator_library.cache_info().currsize:
        build_soon(integrator_library, name="jourdain-integrator-build")


def integrate_accel(accel: int, f: int, p: np.ndarray, n_inputs: int, x0: np.ndarray,
                    t_span: tuple[float, float], rtol: float, atol: float) -> np.ndarray:
    """The state at ``t_span[1]`` of ``ẍ = accel(x, ẋ, t)`` from ``x0 = [x, ẋ, W]`` (2f + 1
    numbers) by the compiled DOP853: a problem that is not a model's, whose ``accel``
    (the address of a C function with ``jd_accel``'s signature) is given with its parameters
    ``p``, inputs held at zero (the monodromy matrix of :mod:`jourdain.analysis.floquet`).
    Raises EvaluationError with the integrator's reason and the time where it stopped."""
    pv = np.ascontiguousarray(p, dtype=float).reshape(-1)  # alive while the run reads it
    t1 = float(t_span[1])
    seg = Segment(f, np.zeros(n_inputs), None, address(pv), accel, float(t_span[0]),
                  np.ascontiguousarray(x0, dtype=float), np.array([t1]), C_METHODS["DOP853"],
                  rtol, atol, math.inf)
    code = seg.run(t1)
    if code != _DONE or seg.n_out[0] != 1:
        reason = {_ESINGULAR: "the mass matrix is not positive definite",
                  _ENAN: "NaN or inf in the state or its derivative",
                  _ESTEP: "the step size fell below the round-off limit"}.get(
                      code, f"the integrator failed with code {code}")
        raise EvaluationError(f"{reason} at t = {seg.fail[0]:.9g}")
    return seg.out_x[0].copy()


class Segment:
    """One run of the C integrator (``jd_integrate``) from ``t`` with the state ``x = [y, ẏ,
    W]`` (f coordinates), the right-hand side ``accel`` (a ``jd_accel`` hook) with ``p`` its
    state, constant inputs ``u``, output at ``te``; :meth:`run` to ``t1``. For problems that
    are not a model's: the closed loops' drivers (:mod:`jourdain.loops.c_run`) and the
    monodromy matrix (:func:`integrate_accel`)."""

    def __init__(self, f: int, u: np.ndarray, mkq: int | None, p: int, accel: int, t: float,
                 x: np.ndarray, te: np.ndarray, method: int, rtol: float, atol: float,
                 max_step: float) -> None:
        n = 2 * f + 1
        nu = len(u)
        self.u_const = np.zeros(max(nu, 1))
        self.u_const[:nu] = u
        self.u_kind = np.zeros(max(nu, 1), dtype=np.intc)
        self.tab_off = np.zeros(nu + 1, dtype=np.int_)
        self.atol = np.full(n, float(atol))
        # by field name: the integrator's problem struct (simulation.simulate) may grow
        self.problem = _Problem(
            f=f, nu=nu, nev=0, mkq=mkq, uexpr=None, events=None, ucb=None,
            p=p, u_const=address(self.u_const), u_kind=address(self.u_kind),
            tab_off=address(self.tab_off), tab_t=None, tab_v=None, ev_dir=None, ev_term=None,
            method=method, rtol=float(rtol), atol=address(self.atol),
            h_max=float(max_step), h_first=0.0, accel=accel)
        self.st = np.array([t, 0.0, 0.0, 0.0])
        self.x = x.copy()
        self.k0 = np.zeros(n)
        self.g_old = np.zeros(1)
        self.cnt = np.zeros(5, dtype=np.int_)
        self.te = np.ascontiguousarray(te, dtype=float)
        self.i_eval = np.zeros(1, dtype=np.int_)
        cap = max(self.te.size, 1)
        self.out_t = np.empty(cap)
        self.out_x = np.empty((cap, n))
        self.out_dx = np.empty((cap, n))
        self.n_out = np.zeros(1, dtype=np.int_)
        self.ev_t, self.ev_x = np.empty(1), np.empty((1, n))
        self.ev_i, self.n_ev = np.empty(1, dtype=np.int_), np.zeros(1, dtype=np.int_)
        self.fail = np.zeros(n + 1)

    def run(self, t1: float, steps: int = 1 << 20,
            on_chunk: Callable[[float], None] | None = None) -> int:
        """Integrate to ``t1`` in calls of at most ``steps`` steps; ``on_chunk(t)`` between
        calls (progress, a Ctrl-C looked at there: an exception it raises leaves the state,
        the counters and the samples so far consistent)."""
        lib = integrator_library()
        while True:
            code = int(lib.jd_integrate(
                ctypes.byref(self.problem), t1, address(self.st), address(self.x),
                address(self.k0), address(self.g_old), address(self.cnt), address(self.te),
                self.te.size, address(self.i_eval), address(self.out_t), address(self.out_x),
                address(self.out_dx), self.out_t.size, address(self.n_out), address(self.ev_t),
                address(self.ev_x), address(self.ev_i), 1, address(self.n_ev), steps,
                address(self.fail)))
            if code != _CONTINUE:  # else the step budget of one call used
                return code
            if on_chunk is not None:
                on_chunk(float(self.st[0]))


@overload
def address(a: np.ndarray) -> int: ...
@overload
def address(a: None) -> None: ...
def address(a: np.ndarray | None) -> int | None:
    """The address of ``a``'s data (contiguous), for the C code's arguments and structures
    (the step loop here, the closed loops' and the ensembles' drivers).
    ``ctypes.c_char.from_buffer``: 0.5 µs, against 2.1 µs for ``a.ctypes.data`` and 2.6 µs for
    ``__array_interface__`` (NumPy 2.4), and a run's set-up takes about eight; read-only or
    empty arrays take the slow way."""
    if a is None:
        return None
    try:
        # an ndarray has the buffer protocol; its stubs do not say so to ctypes.from_buffer
        return ctypes.addressof(ctypes.c_char.from_buffer(a))  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return int(a.__array_interface__["data"][0])


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
        exprs: list[se.Basic] = [_ZERO] * nu
        kinds: set[int] = set()
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
                self.feedback[i] = takes_state(v)
            else:
                try:
                    e = as_expr(v, f'input "{name}"')
                except JourdainError as exc:
                    raise EvaluationError(str(exc)) from None
                bad = {str(s) for s in e.free_symbols} - _allowed_symbols(system)
                if bad:
                    raise EvaluationError(
                        f'input "{name}": expression {e} uses {sorted(bad)}; input expressions '
                        "may use t, coordinates, rates and parameters")
                self.u_kind[i] = 2
                kinds.add(2)
                exprs[i] = e
            self.tab_off[i + 1] = n_tab
        self.tab_t = np.concatenate(tab_t) if tab_t else np.zeros(1)
        self.tab_v = np.concatenate(tab_v) if tab_v else np.zeros(1)
        self.uexpr = (lambdify(system, {"u": SymMatrix.column(exprs)})
                      if 2 in kinds else None)
        ev_exprs = []
        for ev in events:
            if not isinstance(ev, Event):
                raise EvaluationError(f"events: expected jourdain.Event objects, got {ev!r}")
            try:
                e = as_expr(ev.expr, f"event {ev.label}")
            except JourdainError as exc:
                raise EvaluationError(str(exc)) from None
            bad = {str(s) for s in e.free_symbols} - _allowed_symbols(system) - set(names)
            if bad:
                raise EvaluationError(f"event {ev.label}: unknown symbol(s) {sorted(bad)}")
            if ev.direction not in (-1, 0, 1):
                raise EvaluationError(f"event {ev.label}: direction must be -1, 0 or +1")
            ev_exprs.append(e)
        self.events = list(events)
        self.ev_fn = lambdify(system, {"g": SymMatrix.column(ev_exprs)}) if ev_exprs else None
        # what the C loop reads, packed into one buffer of doubles and one of ints (each
        # address costs about a microsecond, and a run's set-up is counted in microseconds);
        # the attributes are views of the buffers
        dbl_parts = (self.p.reshape(-1), self.u_const, self.tab_t, self.tab_v,
                     np.ascontiguousarray(atol, dtype=float).reshape(-1))
        self._f64 = np.concatenate(dbl_parts)
        o = [0]
        for a in dbl_parts:
            o.append(o[-1] + a.size)
        self.p, self.u_const, self.tab_t, self.tab_v, self.atol = (
            self._f64[o[i]:o[i + 1]] for i in range(5))
        m_ev = max(len(events), 1)
        self._i32 = np.zeros(self.u_kind.size + 2 * m_ev, dtype=np.intc)
        self._i32[:self.u_kind.size] = self.u_kind
        self.u_kind = self._i32[:self.u_kind.size]
        self.ev_dir = self._i32[self.u_kind.size:self.u_kind.size + m_ev]
        self.ev_term = self._i32[self.u_kind.size + m_ev:]
        for i, ev in enumerate(events):
            self.ev_dir[i], self.ev_term[i] = ev.direction, int(ev.terminal)
        a64, a32 = address(self._f64) or 0, address(self._i32) or 0
        d = [a64 + 8 * x for x in o]
        w = self._i32.itemsize
        i_dir = a32 + w * self.u_kind.size
        self.mkq = mkq
        #: a provisional function's slot for its compiled one (None: compiled already)
        self.pending: list | None = getattr(mkq, "compiled", None)
        self._cb = _CALLBACK(self._callback) if self.callables else None
        self.problem = _Problem(
            f, nu, len(ev_exprs), mkq.address, self.uexpr.address if self.uexpr else None,
            self.ev_fn.address if self.ev_fn else None,
            ctypes.cast(self._cb, ctypes.c_void_p).value if self._cb else None,
            d[0], d[1], a32, address(self.tab_off), d[2], d[3], i_dir, i_dir + w * m_ev, method,
            float(rtol), d[4], float(max_step), float(first_step), mkq.accel_address,
            mkq.accel_ctx_address, mkq.ctx_address)
        self.problem_ref = ctypes.byref(self.problem)  # the C loop's argument, made once

    def take_compiled(self) -> None:
        """Where this problem's M, k, q are provisional while their library compiles
        (:class:`jourdain.numeric.functions.ProvisionalFunction`: interpreted, or built at -O0)
        and the build is done, the library's right-hand side from the next call of the C loop
        on: the same numbers to the bit, so a run may change between its calls. Only ``accel``
        is set (the loop takes it before the provisional one, which stays valid for a thread
        that read it a moment ago)."""
        if self.pending:
            self.problem.accel = self.pending[0].accel_address
            self.pending = None

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


_ZERO = se.Integer(0)


def _allowed_symbols(system: System) -> set[str]:
    """The names an input expression may use: t, coordinates, rates and parameters (formed
    only where an expression is given: a run with numbers as inputs never needs them)."""
    names = system.coordinate_names
    return {"t", *names, *(f"{n}_d" for n in names), *(k for k, _ in system.parameters)}


def takes_state(fn: Callable[..., Any]) -> bool:
    """True for ``u(t, y, yd)`` (state feedback), False for ``u(t)``."""
    try:
        params = inspect.signature(fn).parameters.values()
    except (TypeError, ValueError):
        return False
    positional = [p for p in params if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    return len(positional) >= 3 or any(p.kind == p.VAR_POSITIONAL for p in params)
