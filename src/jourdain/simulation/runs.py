"""One run of the integrator: the compiled step loop called in chunks (progress, Ctrl-C, output
written as it goes, the motion kept on failure) or SciPy's ``solve_ivp`` with the same compiled
right-hand side, and the errors of a run, with the time, state and cause in their messages.
"""

from __future__ import annotations

import ctypes
import signal
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


def _run_c(setup: _Setup, t0: float, t1: float, x0: np.ndarray, te: np.ndarray | None,
           progress: bool | Callable[[float, float], None], output: str | None) -> dict:
    lib = integrator_library()
    system = setup.system
    f = system.f
    n = 2 * f + 1
    nev = len(setup.events)
    ev_cap = 100000 if nev else 1  # crossings recorded (the message says if more were dropped)
    # the loop's state and counters in one buffer of doubles and one of C longs, their
    # addresses computed from two (a run's set-up is counted in microseconds)
    dbl = np.zeros(4 + 3 * n + 1 + max(nev, 1))
    # st (t, h, last trial rejected, last error), x, k0 (the derivative at x), fail, g_old
    st, x, fail = dbl[0:4], dbl[4:4 + n], dbl[4 + 2 * n:5 + 3 * n]
    st[0] = t0
    x[:] = x0
    ints = np.zeros(8 + ev_cap, dtype=np.int_)
    # cnt (5), i_eval, n_out, n_ev, ev_i (ev_cap)
    cnt, n_out, n_ev, ev_i = ints[0:5], ints[6:7], ints[7:8], ints[8:]
    a_dbl, a_int, di = address(dbl) or 0, address(ints) or 0, ints.itemsize
    p_st, p_x, p_k0, p_fail, p_g = (a_dbl + 8 * o for o in (0, 4, 4 + n, 4 + 2 * n, 5 + 3 * n))
    p_cnt, p_ieval, p_nout, p_nev, p_evi = (a_int + di * o for o in (0, 5, 6, 7, 8))
    ev_t = np.empty(ev_cap)
    ev_x = np.empty((ev_cap, n))
    p_evt, p_evx = address(ev_t), address(ev_x)
    if te is not None:
        cap = te.size
        out = np.empty(cap * (1 + 2 * n))
        out_t, out_x = out[:cap], out[cap:cap * (1 + n)].reshape(cap, n)
        out_dx = out[cap * (1 + n):].reshape(cap, n)
        a_out = address(out) or 0
        p_te: int | None = address(te)
        n_te = te.size
    chunks_t: list[np.ndarray] = []
    chunks_x: list[np.ndarray] = []
    chunks_dx: list[np.ndarray] = []
    if te is None:
        cap, p_te, n_te = 1024, None, 0
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
    # the middle of bookkeeping; a second Ctrl-C raises at once. Without Python input functions
    # the handler is installed after the first call, and only when the run goes on: no Python
    # runs during that call, so Python's own handler does the same (KeyboardInterrupt as the
    # call returns, its chunk kept below), and a run done in one call (most runs of ordinary
    # length) saves the two signal() calls. An input function is Python called from the loop,
    # where Python's handler would raise: then the handler comes first.
    interrupted = [False]
    old_handler = None
    handler_due = threading.current_thread() is threading.main_thread()

    def on_sigint(signum: int, frame: Any) -> None:
        if interrupted[0]:
            raise KeyboardInterrupt
        interrupted[0] = True

    def install() -> None:
        nonlocal handler_due, old_handler
        handler_due = False
        try:
            old_handler = signal.signal(signal.SIGINT, on_sigint)
        except ValueError:  # not the main interpreter
            old_handler = None

    problem = ctypes.byref(setup.problem)
    stiffness = StiffnessCheck(lib, setup, setup.problem.method)
    try:
        if handler_due and setup.callables:
            install()
        while True:
            if te is None:
                out = np.empty(cap * (1 + 2 * n))
                out_t, out_x = out[:cap], out[cap:cap * (1 + n)].reshape(cap, n)
                out_dx = out[cap * (1 + n):].reshape(cap, n)
                a_out = address(out) or 0
                n_out[0] = 0
            id_chunk += 1
            code = lib.jd_integrate(
                problem, t1, p_st, p_x, p_k0, p_g, p_cnt, p_te, n_te, p_ieval, a_out,
                a_out + 8 * cap, a_out + 8 * cap * (1 + n), cap, p_nout, p_evt, p_evx, p_evi,
                ev_cap, p_nev, max_steps, p_fail)
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
            stiffness.after_call(float(st[0]), float(st[1]), x.copy(), int(cnt[2]))
            if handler_due:
                install()
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
