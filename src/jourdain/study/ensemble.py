"""Ensembles of simulations: a block of cases of one compiled model integrated in one C call.

A Monte-Carlo study simulates one model many times with other parameters and initial states.
:func:`simulate` (the per-case path) spends a third of a small model's run in Python: checking
the arguments, building the C problem, collecting the results. An :class:`Ensemble` builds the
problem once (:class:`jourdain.simulation.simulate._Setup`, the very structure the per-case run
builds) and integrates a block of cases with one call of a small C driver (``jd_ensemble``,
below) that loops over the cases: for each, a copy of the problem whose parameter pointer is
the case's row, the integrator's own entry point ``jd_integrate``
(:mod:`jourdain.numeric.integrator_c`) called in chunks of :func:`steps_per_call` steps until
the run ends, exactly as the per-case loop calls it. Every case keeps its own adaptive steps,
so its numbers are bit for bit those of :func:`jourdain.simulation.simulate.simulate`
(``tests/test_study_ensemble.py``).

The driver holds no Python object and ctypes releases the GIL around it: a block cut into
``threads`` slices runs on that many cores in one process.

Cases advanced in lock-step (one vectorized right-hand side for all cases per stage) were
considered and not built, decided by ``benchmarks/study.py`` (its "lock-step bound" line): with
bit-identical results required, each case keeps its own step sizes, error norms, rejections
and dense output, so lock-step could only batch the model's M, k, q; on the quarter-car
Monte-Carlo those take 11–16 ns of the 100–270 ns of C integration per right-hand side
(6–11 %; the rest is each case's step loop), while the ensemble removed the Python work around
each run (2–2.7× the per-case study on one worker).
"""

from __future__ import annotations

import ctypes
import math
import threading
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from ..numeric import mkq_function
from ..numeric.toolchain import build, content_key
from ..simulation.problem import address
from ..simulation.simulate import (
    C_METHODS,
    _Problem,
    _Setup,
    check_atol,
    check_max_step,
    integrator_library,
    steps_per_call,
)

__all__ = ["ENSEMBLE_SOURCE", "Ensemble", "EnsembleRun", "ensemble_library"]

#: the driver: per case, a copy of the problem with its own parameter row, and the integrator
#: called until the run ends (the per-case loop of simulation.simulate._run_c, without Python)
ENSEMBLE_SOURCE = r"""
#include <stdlib.h>
#include <string.h>

typedef int (*jd_integrate_fn)(const void *P, double t_end, double *st, double *x, double *k0,
    double *g_old, long *cnt, const double *t_eval, long n_eval, long *i_eval, double *out_t,
    double *out_x, double *out_dx, long cap, long *n_out, double *ev_t, double *ev_x,
    long *ev_i, long ev_cap, long *n_ev, long max_steps, double *fail);

/* cases lo..hi-1: problem (size bytes) with its parameter pointer at p_offset replaced by
   P + i*n_p; X0 (cases, n) the initial states; out_x (cases, n_eval, n) the states at t_eval;
   out_dx the same for the derivatives (NULL: not kept); code (cases) the last return code;
   cnt (cases, 5) the integrator's counters; fail (cases, n + 1) time and state of a failure.
   Returns 0, or -5 when memory ran out. */
int jd_ensemble(jd_integrate_fn integrate, const char *problem, long size, long p_offset,
                const double *P, long n_p, const double *X0, long n, double t0, double t_end,
                const double *t_eval, long n_eval, long max_steps, double *out_x,
                double *out_dx, int *code, long *cnt, double *fail, long lo, long hi) {
    char *prob = (char *)malloc((size_t)size);
    double *work = (double *)malloc(sizeof(double) * (size_t)(3 * n + n_eval + 8
        + (out_dx ? 0 : n_eval * n)));
    if (!prob || !work) { free(prob); free(work); return -5; }
    memcpy(prob, problem, (size_t)size);
    double *x = work, *k0 = x + n, *ev_x = k0 + n, *out_t = ev_x + n, *st = out_t + n_eval,
           *g_old = st + 4, *ev_t = g_old + 1;
    double *dx_scratch = out_dx ? NULL : ev_t + 1;
    for (long i = lo; i < hi; ++i) {
        const double *p = P + i * n_p;
        memcpy(prob + p_offset, &p, sizeof(p));
        st[0] = t0; st[1] = 0.0; st[2] = 0.0; st[3] = 0.0;
        memcpy(x, X0 + i * n, sizeof(double) * (size_t)n);
        memset(k0, 0, sizeof(double) * (size_t)n);
        g_old[0] = 0.0;
        long *c = cnt + 5 * i, i_eval = 0, n_out = 0, ev_i = 0, n_ev = 0;
        memset(c, 0, 5 * sizeof(long));
        double *ox = out_x + i * n_eval * n;
        double *odx = out_dx ? out_dx + i * n_eval * n : dx_scratch;
        int r;
        do {
            r = integrate(prob, t_end, st, x, k0, g_old, c, t_eval, n_eval, &i_eval, out_t, ox,
                          odx, n_eval, &n_out, ev_t, ev_x, &ev_i, 1, &n_ev, max_steps,
                          fail + i * (n + 1));
        } while (r == 1);
        code[i] = r;
    }
    free(prob);
    free(work);
    return 0;
}
"""


@lru_cache(maxsize=1)
def ensemble_library() -> ctypes.CDLL:
    """The compiled driver (built once, cached on disk like the model code)."""
    lib = build(content_key("study-ensemble", ENSEMBLE_SOURCE), ENSEMBLE_SOURCE)
    vp, lg, db = ctypes.c_void_p, ctypes.c_long, ctypes.c_double
    lib.jd_ensemble.restype = ctypes.c_int
    lib.jd_ensemble.argtypes = [vp, vp, lg, lg, vp, lg, vp, lg, db, db, vp, lg, lg, vp, vp, vp,
                                vp, vp, lg, lg]
    return lib


@dataclass
class EnsembleRun:
    """The motions of a block of cases at the output times ``t`` (samples,): ``y``, ``yd``
    (cases, samples, f), ``W`` (cases, samples) the work of the applied forces, ``ydd`` (cases,
    samples, f) where kept; ``code`` (cases,) the integrator's return code (0: finished,
    negative: failed, its output rows past the failure undefined); ``nfev``, ``nsteps``
    (cases,)."""

    t: np.ndarray
    y: np.ndarray
    yd: np.ndarray
    W: np.ndarray
    ydd: np.ndarray | None
    code: np.ndarray
    nfev: np.ndarray
    nsteps: np.ndarray

    @property
    def ok(self) -> np.ndarray:
        """True where the case ran to the end."""
        return self.code == 0


class Ensemble:
    """Simulations of one model from ``t0`` to ``t_end``, sampled at ``t_eval``, with the
    inputs, method and tolerances fixed and the parameters and initial states per case.

    Only the methods whose step loop runs in C (``DOP853``, ``RK45``, ``Radau``) and inputs that
    run in C (numbers, tables, expressions) can be advanced together: :meth:`supports` says
    whether these settings can (else simulate case by case). Arguments as for
    :func:`jourdain.simulation.simulate.simulate`; they are checked by the same functions.
    """

    def __init__(self, system: Any, t_span: tuple[float, float], t_eval: Any,
                 inputs: Any = None, method: str = "DOP853", rtol: float = 1e-8,
                 atol: float | Any = 1e-10) -> None:
        from ..simulation.simulate import check_method, check_rtol, check_t_eval, check_t_span

        self.system = system
        f = system.f
        self.t0, self.t1 = check_t_span(t_span)
        self.t_eval = check_t_eval(t_eval, self.t0, self.t1, f, len(system.inputs))
        self.method = check_method(method)
        if not self.supports(self.method, inputs):
            raise ValueError(f"method {self.method!r} or Python callables among the inputs: "
                             "these runs cannot be advanced together in C")
        a = check_atol(atol, 2 * f)
        atol_x = np.concatenate([a, [a.min()]])
        max_step = check_max_step(math.inf, self.t0, self.t1)
        p0 = np.array([v for _, v in system.parameters], dtype=float)
        # the per-case run's own problem structure (inputs, events, tolerances), built once
        self.setup = _Setup(system, mkq_function(system), p0, inputs, (),
                            C_METHODS[self.method], check_rtol(rtol), atol_x, max_step, 0.0)
        self._template = ctypes.string_at(ctypes.addressof(self.setup.problem),
                                           ctypes.sizeof(_Problem))
        self._integrate = ctypes.cast(integrator_library().jd_integrate, ctypes.c_void_p).value
        self._lib = ensemble_library()

    @staticmethod
    def supports(method: str, inputs: Any) -> bool:
        """Whether runs with this method and these inputs can be advanced together in C."""
        values = inputs.values() if hasattr(inputs, "values") else (inputs or ())
        return method in C_METHODS and not any(
            callable(v) and not hasattr(v, "free_symbols") for v in values)

    def run(self, P: Any, Y0: Any, YD0: Any, threads: int = 1, accelerations: bool = False
            ) -> EnsembleRun:
        """Integrate the cases ``P`` (cases, parameters), ``Y0``, ``YD0`` (cases, f), cut into
        ``threads`` slices run side by side (the GIL released); ``accelerations``: keep ÿ."""
        f = self.system.f
        n = 2 * f + 1
        P = np.ascontiguousarray(P, dtype=float)
        m = len(P)
        X0 = np.zeros((m, n))
        X0[:, :f] = np.asarray(Y0, dtype=float).reshape(m, f)
        X0[:, f:2 * f] = np.asarray(YD0, dtype=float).reshape(m, f)
        if P.shape != (m, len(self.system.parameters)):
            raise ValueError(f"P: expected ({m}, {len(self.system.parameters)}), got {P.shape}")
        ns = self.t_eval.size
        out_x = np.empty((m, ns, n))
        out_dx = np.empty((m, ns, n)) if accelerations else None
        code = np.zeros(m, dtype=np.intc)
        cnt = np.zeros((m, 5), dtype=np.int_)
        fail = np.zeros((m, n + 1))
        te = self.t_eval
        max_steps = steps_per_call(f)
        status = [0] * max(1, threads)

        def work(k: int, lo: int, hi: int) -> None:
            status[k] = self._lib.jd_ensemble(
                self._integrate, self._template, len(self._template), _Problem.p.offset,
                address(P), P.shape[1], address(X0), n, self.t0, self.t1, address(te), ns,
                max_steps, address(out_x), address(out_dx), address(code), address(cnt),
                address(fail), lo, hi)

        cuts = np.linspace(0, m, max(1, min(threads, m)) + 1).round().astype(int)
        slices = [(k, int(a), int(b)) for k, (a, b) in enumerate(zip(cuts[:-1], cuts[1:],
                                                                      strict=True))]
        if len(slices) == 1:
            work(*slices[0])
        else:
            pool = [threading.Thread(target=work, args=s) for s in slices]
            for th in pool:
                th.start()
            for th in pool:
                th.join()
        if any(status):
            raise MemoryError("the ensemble driver ran out of memory")
        return EnsembleRun(t=te.copy(), y=out_x[:, :, :f], yd=out_x[:, :, f:2 * f],
                           W=out_x[:, :, 2 * f],
                           ydd=None if out_dx is None else out_dx[:, :, f:2 * f],
                           code=code, nfev=cnt[:, 0].copy(), nsteps=cnt[:, 1].copy())
