"""Simulation of a general system (velocity constraints, METHOD.md §7) in its state
``x = (y_i, z)`` (:class:`jourdain.loops.general.GeneralEvaluator`): ``ẏ_i = (L·z + l)_i``,
``ż = M⁻¹(q − k)``, by SciPy's steppers one step at a time (so an interrupted run keeps its
motion so far). The holonomic rows hold to rounding at every sample (Newton on the dependent
coordinates), the velocity rows by construction (``ẏ = L·z + l`` with ``A·L = 0``,
``A·l + a = 0``): the residuals recorded are those of rounding, over any length of run.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from typing import Any

import numpy as np
from scipy.integrate import BDF, DOP853, LSODA, RK23, RK45, Radau

from ..errors import EvaluationError, JourdainError
from ..model import System
from ..simulation.options import C_METHODS, steps_per_call
from ..simulation.problem import Segment
from .general import VEL, GeneralEvaluator, functions
from .general_choice import least_norm
from .general_kernel import GeneralKernel, supported
from .results import _work

_METHODS = {"DOP853": DOP853, "RK45": RK45, "RK23": RK23, "Radau": Radau, "BDF": BDF,
            "LSODA": LSODA, "DOPRI5": RK45}
_METHODS.update({f"scipy:{k}": v for k, v in list(_METHODS.items())})
#: samples of a run in C without t_eval (the C integrator writes at given times)
C_SAMPLES = 501


def _sample(ev: GeneralEvaluator, x: np.ndarray, t: float) -> tuple:
    s = ev.accelerations(x, t)
    hol, phid = ev.residuals(s, t)
    return s["y"], s["yd"], s["ydd"], hol, phid, ev.multipliers(s)


def simulate_general(system: System, t_span: tuple[float, float], y0: Any, yd0: Any = None,
                     parameters: Mapping[str, float] | None = None, inputs: Any = None,
                     method: str = "DOP853", rtol: float = 1e-8, atol: Any = 1e-10,
                     t_eval: Any = None, max_step: float = np.inf, **options: Any) -> Any:
    """Integrate the general ``system`` from ``y0`` (the independent coordinates held, the
    dependent ones solved) with the speeds taken from ``yd0`` over ``t_span``; returns
    :class:`jourdain.Results` with the tree's ``y, yd, ydd`` and, in ``constraints``, the
    rows' residuals (``Phi``: holonomic rows, ``Phi_dot``: every row's ``A·ẏ + a``) and
    multipliers (the contact forces along the rows' directions). Options: ``progress`` (a
    callable ``progress(t, t_end)`` after each step), ``output`` (a results file, written at
    the end or with the motion so far when interrupted)."""
    if inputs:
        raise EvaluationError(f"{system.name}: inputs are not available for systems with "
                              "velocity constraints yet")
    progress = options.pop("progress", None)
    output = options.pop("output", None)
    unknown = sorted(set(options))
    if unknown:
        raise EvaluationError(f"simulate: unknown option(s) {', '.join(unknown)} for a system "
                              "with velocity constraints")
    if method not in C_METHODS and method not in _METHODS:
        raise EvaluationError(f'simulate: unknown method "{method}"; methods are '
                              f"{', '.join(_METHODS)}")
    t0, t1 = float(t_span[0]), float(t_span[1])
    ev = GeneralEvaluator(system, y0, t0, parameters)
    run = _Run(system, ev, t0, parameters, method, rtol, atol, output)
    if method in C_METHODS and supported(ev):
        return _simulate_c(run, (t0, t1), y0, yd0, t_eval, max_step, progress)
    x0 = ev.initial(y0, yd0, t0)

    def rhs(t: float, x: np.ndarray) -> np.ndarray:
        return ev.accelerations(x, t)["xd"]

    start = time.perf_counter()
    solver = _METHODS[method](rhs, t0, x0, t1, rtol=rtol, atol=atol, max_step=max_step)
    te = None if t_eval is None else np.asarray(t_eval, dtype=float).reshape(-1)
    if te is None:
        ts, xs = [t0], [x0.copy()]
    else:
        ts = [t0] if te.size and te[0] == t0 else []
        xs = [x0.copy()] if ts else []
    status, message, failure = "finished", "integrated to the end", None
    try:
        while solver.status == "running":
            t_prev = solver.t
            msg = solver.step()
            if solver.status == "failed":
                status, message = "failed", f"the integrator failed at t = {solver.t:.6g}: {msg}"
                break
            if callable(progress):
                progress(float(solver.t), t1)
            if te is None:
                ts.append(solver.t)
                xs.append(solver.y.copy())
                continue
            sel = te[(te > t_prev) & (te <= solver.t)]
            if sel.size:
                dense = solver.dense_output()
                for tt in sel:
                    ts.append(float(tt))
                    xs.append(dense(tt))
    except KeyboardInterrupt:
        status, message = "interrupted", f"interrupted (Ctrl-C) at t = {solver.t:.6g}"
    except JourdainError as exc:
        status, message, failure = "failed", str(exc), exc
    samples = [_sample(ev, x, t) for t, x in zip(ts, xs, strict=True)]
    Y, YD, YDD, PHI, PHID, LAM = (np.array([s[i] for s in samples]) for i in range(6))
    return run.results(np.array(ts), Y, YD, YDD, PHI, PHID, LAM, status, message, failure,
                       (solver.nfev, len(ts), len(ts), 0), start)


class _Run:
    """What a general run's results are made of besides the motion (the system, its
    evaluator, the settings and the output file): :meth:`results` builds them."""

    def __init__(self, system: System, ev: GeneralEvaluator, t0: float,
                 parameters: Mapping[str, float] | None, method: str, rtol: float, atol: Any,
                 output: Any) -> None:
        self.system, self.ev, self.t0, self.parameters = system, ev, t0, parameters
        self.method, self.rtol, self.atol, self.output = method, rtol, atol, output

    def results(self, T: np.ndarray, Y: np.ndarray, YD: np.ndarray, YDD: np.ndarray,
                PHI: np.ndarray, PHID: np.ndarray, LAM: np.ndarray, status: str, message: str,
                failure: BaseException | None, counts: tuple[int, int, int, int], start: float,
                W: np.ndarray | None = None) -> Any:
        """:class:`jourdain.Results` of the samples (``PHI`` of the holonomic rows, padded to
        every row), ``counts`` = (right-hand sides, steps, accepted, rejected); ``W`` the
        integrator's, else ``∫ẏᵀq dt`` over the samples (the contact forces do no work:
        Jourdain's principle); written to the output file where one was asked for."""
        from ..simulation.results import Results
        from ..simulation.results.data import ConstraintHistories

        ev, N = self.ev, len(T)
        phi = np.zeros((N, len(ev.labels)))
        if N:
            phi[:, :PHI.shape[1]] = PHI
        cons = ConstraintHistories(tuple(ev.labels), phi, PHID, LAM,
                                   ((self.t0, tuple(ev.independent_names)),), failure)
        res = Results(self.system, T, Y, YD, YDD, np.zeros((N, 0)), np.zeros(N),
                      {**self.system.parameter_values, **dict(self.parameters or {})},
                      method=self.method, rtol=self.rtol, atol=self.atol, status=status,
                      message=message, nfev=int(counts[0]), nsteps=int(counts[1]),
                      n_accepted=int(counts[2]), n_rejected=int(counts[3]),
                      wall_time=time.perf_counter() - start, constraints=cons)
        if N > 1:
            res.W = W if W is not None else _work(res, self.system.tree, self.parameters,
                                                  None, self.system)
        if self.output is not None:  # at the end, or with the motion so far (interrupted)
            res.save(self.output)
        return res


def _multipliers(ev: GeneralEvaluator, t: np.ndarray, Y: np.ndarray, YD: np.ndarray,
                 R: np.ndarray) -> np.ndarray:
    """λ at every sample: the least-norm solution of ``Aᵀλ = r`` (as
    :meth:`GeneralEvaluator.multipliers`), batched."""
    if not len(t):
        return np.zeros((0, len(ev.labels)))
    A = functions(ev.system).fns[VEL].batch(Y, YD, t, ev.p, ev.u)["A"]
    return least_norm(A, R, len(ev.choice.rows_v))[0]


def _simulate_c(run: _Run, span: tuple[float, float], y0: Any, yd0: Any, t_eval: Any,
                max_step: float, progress: Any) -> Any:
    """The run in C (:mod:`jourdain.loops.general_kernel`): jourdain's integrator on
    ``(y_i, ẏ_i)`` through the kernel's ``jd_accel``; the samples taken back onto the rows."""
    ev = run.ev
    t0, t1 = span
    x0 = ev.initial(y0, yd0, t0)
    s0 = ev.accelerations(x0, t0)
    ind = list(ev.choice.independent)
    ni = len(ind)
    kernel = GeneralKernel(ev)
    kernel.y[:] = np.real(s0["y"])
    te = (np.linspace(t0, t1, C_SAMPLES) if t_eval is None
          else np.asarray(t_eval, dtype=float).reshape(-1))
    state = np.concatenate([s0["y"][ind], s0["yd"][ind], [0.0]])
    start = time.perf_counter()
    seg = Segment(ni, ev.u, kernel.tree.address, kernel.state_address, kernel.accel_address,
                  t0, state, te, C_METHODS[run.method], run.rtol, float(np.max(run.atol)),
                  max_step)
    seg.atol[-1] = 1e300  # W out of the error norm (as the closed systems' runs)

    def on_chunk(t: float) -> None:
        if callable(progress):
            progress(t, t1)

    status, message = "finished", "integrated to the end"
    try:
        code = seg.run(t1, steps_per_call(ni), on_chunk)
    except KeyboardInterrupt:  # between two calls: the samples so far are consistent
        code, status = 0, "interrupted"
    k = int(seg.n_out[0])
    if status == "interrupted":
        message = f"interrupted (Ctrl-C) at t = {float(seg.st[0]):.6g}"
    elif code != 0:
        status = "failed"
        message = (f"the integration failed at t = {float(seg.fail[0]):.6g}: "
                   f"{kernel.reason() or f'integrator code {code}'}")
    kernel.y[:] = np.real(s0["y"])
    smp, bad = kernel.samples(seg.out_t[:k], seg.out_x[:k, :2 * ni])
    T = np.array(seg.out_t[:k])
    if bad >= 0:
        T = T[:bad]
        smp = {key: v[:bad] for key, v in smp.items()}
        status, message = "failed", f"no configuration at t = {float(seg.out_t[bad]):.6g}"
    lam = smp["lam"]
    if len(T) and np.isnan(lam).any():  # redundant rows: the least-norm multipliers
        lam = _multipliers(ev, T, smp["y"], smp["yd"], smp["r"])
    # W: the power's integral along the integrator's own steps (it integrates W)
    c = [int(v) for v in seg.cnt[:4]]
    return run.results(T, smp["y"], smp["yd"], smp["ydd"], smp["Phi"], smp["Phi_dot"], lam,
                       status, message, None, (c[0], c[1], c[2], c[3]), start,
                       W=np.array(seg.out_x[:len(T), -1]) - float(state[-1]))


__all__ = ["simulate_general"]
