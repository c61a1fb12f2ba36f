"""One run of the integrator: the compiled step loop called in chunks (progress, Ctrl-C, output
written as it goes, the motion kept on failure) or SciPy's ``solve_ivp`` with the same compiled
right-hand side, and the errors of a run, with the time, state and cause in their messages.
"""

from __future__ import annotations

import ctypes
import signal
import struct
import sys
import threading
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import JourdainError, SingularMassMatrix
from ..numeric import CompiledFunction
from ..numeric.diagnose import nonfinite_sources

if TYPE_CHECKING:
    from ..model.system import System

from .options import C_METHODS, OUTPUT_SUFFIXES, steps_per_call
from .problem import (
    _DONE,
    _ECALLBACK,
    _ENAN,
    _ESINGULAR,
    _ESTEP,
    _EVENT,
    _Setup,
    address,
    integrator_library,
)
from .results import append_incremental, open_incremental
from .stiffness import StiffnessCheck


class IntegrationError(JourdainError, RuntimeError):
    """The integration failed: a NaN in the state, a step size below the round-off limit."""


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


#: the loop's counters in the state buffer (C longs): cnt (nfev, nstep, naccept, nreject,
#: have_k0), i_eval, n_out, n_ev; read and written with struct (one call, no array made; an
#: ndarray has the buffer protocol, which its stubs do not tell struct)
_LONG, _COUNTERS = struct.Struct("l"), struct.Struct("8l")


class _Sigint:
    """Ctrl-C during a run (installed from the main thread only): the first sets a flag that is
    looked at between calls of the C loop, so it never lands in the middle of bookkeeping; a
    second raises at once. :meth:`restore` puts the previous handler back."""

    __slots__ = ("interrupted", "old")

    def __init__(self) -> None:
        self.interrupted = False
        self.old: Any = None
        if threading.current_thread() is threading.main_thread():
            try:
                self.old = signal.signal(signal.SIGINT, self.handle)
            except ValueError:  # not the main interpreter
                pass

    def handle(self, signum: int, frame: Any) -> None:
        if self.interrupted:
            raise KeyboardInterrupt
        self.interrupted = True

    def restore(self) -> None:
        if self.old is not None:
            signal.signal(signal.SIGINT, self.old)


def _chunk(out: np.ndarray, o: int, cap: int, n: int, f: int, m: int, copy: bool = True
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The ``m`` samples that a call wrote to ``out`` from ``o`` on (``cap`` times, ``cap``
    states, ``cap`` derivatives of the state): views of t and x, and of ÿ only, copied with
    ``copy`` (half the memory of the derivatives kept)."""
    e = o + cap * (1 + n)
    ydd = out[e:e + m * n].reshape(m, n)[:, f:2 * f]
    return out[o:o + m], out[o + cap:o + cap + m * n].reshape(m, n), ydd.copy() if copy else ydd


def _run_c(setup: _Setup, t0: float, t1: float, x0: np.ndarray, te: np.ndarray | None,
           progress: bool | Callable[[float, float], None], output: str | None) -> dict:
    lib = integrator_library()
    system = setup.system
    n = x0.size
    f = (n - 1) // 2
    nev = len(setup.events)
    ev_cap = 100000 if nev else 1  # crossings recorded (the message says if more were dropped)
    cap = 1024 if te is None else te.size  # output samples per call
    # One buffer of doubles (a run's set-up is counted in microseconds: each array and each
    # address costs about half of one), its addresses computed from the first: the loop's
    # state, zeroed (st: t, h, last trial rejected, last error; x; k0, the derivative at x;
    # fail; g_old), its counters as C longs (cnt (5), i_eval, n_out, n_ev) and, without
    # events, the record of one crossing (ev_i, ev_t, ev_x) that the loop never writes; then
    # the output (cap times, states and their derivatives) of the first call, or with t_eval
    # of all calls. With events their record of ev_cap crossings has arrays of its own.
    o_fail, o_g = 4 + 2 * n, 5 + 3 * n
    o_int = o_g + max(nev, 1)
    o_ev = o_int + 9
    o_out = o_ev if nev else o_ev + 1 + n
    buf = np.empty(o_out + cap * (1 + 2 * n))
    buf[:o_out] = 0.0
    buf[0] = t0
    buf[4:4 + n] = x0
    a = address(buf) or 0
    p_st, p_x, p_k0, p_g, p_fail = a, a + 32, a + 8 * (4 + n), a + 8 * o_g, a + 8 * o_fail
    p_cnt, di = a + 8 * o_int, _LONG.size
    if nev:
        ev_t, ev_x = np.empty(ev_cap), np.empty((ev_cap, n))
        ev_i = np.empty(ev_cap, dtype=np.int_)
        p_evt, p_evx, p_evi = address(ev_t), address(ev_x), address(ev_i)
    else:
        p_evi, p_evt = p_cnt + 8 * di, a + 8 * o_ev
        p_evx = p_evt + 8
    p_te, n_te = (None, 0) if te is None else (address(te), te.size)
    out, o, a_out = buf, o_out, a + 8 * o_out
    # without t_eval, each call's accepted steps: (t, x, ÿ); ``pending`` the output buffer of
    # a call not yet kept (a Ctrl-C may come right after the call returns)
    chunks: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    pending = None
    writer = (_Writer(output, system)
              if output and str(output).lower().endswith(OUTPUT_SUFFIXES) else None)
    status = "finished"
    message = "reached the end of t_span"
    exception: BaseException | None = None
    error: JourdainError | None = None
    written = 0
    max_steps = steps_per_call(f)
    t_last_report = time.perf_counter() if progress is True else 0.0
    # Ctrl-C: without Python input functions the handler is installed after the first call,
    # and only when the run goes on: no Python runs during that call, so Python's own handler
    # does the same (KeyboardInterrupt as the call returns, its chunk kept below), and a run
    # done in one call (most runs of ordinary length) saves the two signal() calls. An input
    # function is Python called from the loop, where Python's handler would raise: then the
    # handler comes first.
    sigint: _Sigint | None = None
    stiffness: StiffnessCheck | None = None  # judged from the second call on
    problem = setup.problem_ref
    try:
        if setup.callables:
            sigint = _Sigint()
        while True:
            if te is None:
                if chunks:  # the first call's output is in buf; each later one's in its own
                    out, o = np.empty(cap * (1 + 2 * n)), 0
                    a_out = address(out) or 0
                    _LONG.pack_into(buf, 8 * o_int + 6 * di, 0)  # type: ignore[arg-type]
                pending = out
            code = lib.jd_integrate(
                problem, t1, p_st, p_x, p_k0, p_g, p_cnt, p_te, n_te, p_cnt + 5 * di, a_out,
                a_out + 8 * cap, a_out + 8 * cap * (1 + n), cap, p_cnt + 6 * di, p_evt, p_evx,
                p_evi, ev_cap, p_cnt + 7 * di, max_steps, p_fail)
            cnt = _COUNTERS.unpack_from(buf, 8 * o_int)  # type: ignore[arg-type]
            if setup.pending is not None:  # a first run interpreted: the library once built
                setup.take_compiled()
            if te is None:
                chunks.append(_chunk(out, o, cap, n, f, cnt[6]))
                pending = None
                if writer:
                    writer.append(chunks[-1][0], chunks[-1][1])
            elif writer:
                m = cnt[6]
                ts, xs, _ = _chunk(out, o, cap, n, f, m)
                writer.append(ts[written:], xs[written:])
                written = m
            if code < 0:
                if code == _ECALLBACK and isinstance(setup.callback_error, KeyboardInterrupt):
                    raise setup.callback_error
                err = _error(code, setup, buf[o_fail:o_fail + n + 1])
                if code == _ECALLBACK:
                    status, message, exception = "interrupted", str(err), setup.callback_error
                    break
                status, message, error = "failed", str(err), err
                break
            if code == _EVENT:
                k = int(ev_i[cnt[7] - 1])
                status = "event"
                message = f"terminal event {setup.events[k].label!r} at t = {buf[0]:.9g}"
                break
            if code == _DONE:
                break
            if stiffness is None:
                stiffness = StiffnessCheck(lib, setup, setup.problem.method)
            stiffness.after_call(float(buf[0]), float(buf[1]), buf[4:4 + n].copy(),
                                 cnt[2])
            if sigint is None:
                sigint = _Sigint()
            if sigint.interrupted:
                raise KeyboardInterrupt
            if callable(progress):
                progress(float(buf[0]), t1)
            elif progress:
                now = time.perf_counter()
                if now - t_last_report > 0.5:
                    t_last_report = now
                    print(f"\rsimulating {system.name}: t = {buf[0]:.4g} of {t1:.4g} "
                          f"({100 * (buf[0] - t0) / (t1 - t0):.0f} %)", end="", file=sys.stderr)
    except KeyboardInterrupt as exc:
        if pending is not None:  # Ctrl-C came right after a call returned
            m = _COUNTERS.unpack_from(buf, 8 * o_int)[6]  # type: ignore[arg-type]
            chunks.append(_chunk(pending, o, cap, n, f, m))
        status = "interrupted"
        message = "interrupted by the user (Ctrl-C); the motion up to there is kept"
        exception = exc
    finally:
        if sigint is not None:
            sigint.restore()
        if writer:
            writer.handle.close()
    if progress is True:
        print(file=sys.stderr)
    cnt = _COUNTERS.unpack_from(buf, 8 * o_int)  # type: ignore[arg-type]
    dx_out: np.ndarray | None
    if te is not None:
        t_out, x_out, dx_out = _chunk(out, o, cap, n, f, cnt[6], copy=False)
    elif len(chunks) == 1 and len(chunks[0][0]):  # a run done in one call: t copied off
        t_out, x_out, dx_out = chunks[0][0].copy(), chunks[0][1], chunks[0][2]
    elif sum(len(c[0]) for c in chunks):
        t_out = np.concatenate([c[0] for c in chunks])
        x_out = np.concatenate([c[1] for c in chunks])
        dx_out = np.concatenate([c[2] for c in chunks])
    else:  # failed or interrupted at the start: the initial state only
        t_out, x_out, dx_out = np.array([t0]), x0[None, :].copy(), None
    if isinstance(exception, KeyboardInterrupt):
        message = (f"interrupted by the user (Ctrl-C) at t = {t_out[-1]:.9g}; the motion up "
                   "to there is kept")
    nfev, nstep, naccept, nreject = cnt[:4]
    if nev:
        m = cnt[7]
        if m == ev_cap:
            message += f"; only the first {ev_cap} event crossings were recorded"
        events = (ev_t[:m].copy(), ev_x[:m].copy(), ev_i[:m].copy())
    else:
        events = _NO_EVENTS
    return {"t": t_out, "x": x_out, "ydd": dx_out, "status": status, "message": message,
            "exception": exception, "error": error, "nfev": nfev, "nstep": nstep,
            "naccept": naccept, "nreject": nreject, "events": events}


#: a run's crossings where it has no events (read only: nothing is appended to them)
_NO_EVENTS = (np.empty(0), np.empty((0, 0)), np.empty(0, dtype=np.int_))


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
    ev_fn = setup.ev_fn
    for k, ev in enumerate(setup.events):
        assert ev_fn is not None  # compiled whenever there are events

        def g(t: float, x: np.ndarray, k: int = k, ev_fn: CompiledFunction = ev_fn) -> float:
            u = setup.inputs_at(np.array([t]), x[None, :])[0]
            return float(ev_fn(x[:f], x[f:2 * f], t, setup.p, u)["g"][k, 0])
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


class _Writer:
    """Appends accepted steps to an HDF5 results file while the run goes."""

    def __init__(self, path: str, system: System) -> None:
        self.path = path
        self.handle = open_incremental(path, system)

    def append(self, t: np.ndarray, x: np.ndarray) -> None:
        append_incremental(self.handle, t, x)
