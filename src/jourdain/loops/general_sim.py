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
from .general import GeneralEvaluator
from .results import _work

_METHODS = {"DOP853": DOP853, "RK45": RK45, "RK23": RK23, "Radau": Radau, "BDF": BDF,
            "LSODA": LSODA}


def _sample(ev: GeneralEvaluator, x: np.ndarray, t: float) -> tuple:
    s = ev.accelerations(x, t)
    fn = s["fn"]
    phi = np.zeros(len(ev.labels))
    hol = fn["Phi"].reshape(-1)
    phi[:hol.size] = hol
    phid = fn["A"] @ s["yd"] + fn["a"][:, 0]
    return s["y"], s["yd"], s["ydd"], phi, phid, ev.multipliers(s)


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
    from ..simulation.results import Results
    from ..simulation.results.data import ConstraintHistories

    if inputs:
        raise EvaluationError(f"{system.name}: inputs are not available for systems with "
                              "velocity constraints yet")
    progress = options.pop("progress", None)
    output = options.pop("output", None)
    unknown = sorted(set(options))
    if unknown:
        raise EvaluationError(f"simulate: unknown option(s) {', '.join(unknown)} for a system "
                              "with velocity constraints")
    if method not in _METHODS:
        raise EvaluationError(f'simulate: unknown method "{method}"; methods are '
                              f"{', '.join(_METHODS)}")
    t0, t1 = float(t_span[0]), float(t_span[1])
    ev = GeneralEvaluator(system, y0, t0, parameters)
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
    cons = ConstraintHistories(tuple(ev.labels), PHI, PHID, LAM,
                               ((t0, tuple(ev.independent_names)),), failure)
    N = len(ts)
    res = Results(system, np.array(ts), Y, YD, YDD, np.zeros((N, 0)), np.zeros(N),
                  {**system.parameter_values, **dict(parameters or {})}, method=method,
                  rtol=rtol, atol=atol, status=status, message=message, nfev=solver.nfev,
                  nsteps=len(ts), n_accepted=len(ts), n_rejected=0,
                  wall_time=time.perf_counter() - start, constraints=cons)
    if N > 1:  # W = ∫ẏᵀq dt: the contact forces do no work (Jourdain's principle)
        res.W = _work(res, system.tree, parameters, None, system)
    if output is not None:  # at the end, or with the motion so far when interrupted
        res.save(output)
    return res


__all__ = ["simulate_general"]
