"""The SciPy driver of the coordinate partitioning of
:func:`jourdain.loops.simulate.simulate_closed`: SciPy's steppers (``DOP853``, ``RK45``,
``Radau``, ``BDF``) stepped from Python, the right-hand side evaluated by
:class:`~jourdain.loops.closed_loop.LoopEvaluator` (Newton on the dependent coordinates in
Python, about 0.3 ms per evaluation). It serves the method the C integrator lacks (BDF) and
inputs given as Python functions of time; ``method="scipy:<method>"`` asks for it."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from .charts import decide
from .closed_loop import LoopEvaluator, SingularConfiguration

#: the steppers, by ``method`` (SciPy's classes, imported when a run needs them: scipy.integrate
#: takes 0.1–0.4 s to import, which the C engine does not need)
SOLVERS = ("DOP853", "RK45", "Radau", "BDF")


def run_scipy(ev: LoopEvaluator, t0: float, t1: float, x: np.ndarray, tev: np.ndarray,
              method: str, rtol: float, atol: float, max_step: float,
              u_of: Callable[[float], Any], repartition: bool, cond_limit: float) -> dict:
    """Integrate from ``x = [y, ẏ]`` at ``t0``; the samples at ``tev`` (evaluated on the
    manifold by the evaluator), the partitions, status, message and the singularity."""
    import scipy.integrate  # noqa: PLC0415 (heavy, needed by this driver only)

    stepper = getattr(scipy.integrate, method)
    out: dict[str, list] = {k: [] for k in ("t", "z", "zd", "zdd", "Phi", "Phi_dot", "lam")}
    partitions = [(t0, tuple(ev.independent_names))]
    status, message, singular = "finished", "the integration reached t_end", None
    t, nfev, k_eval = t0, 0, 0

    def rhs(tt: float, xx: np.ndarray) -> np.ndarray:
        f = ev.part.f
        s = ev.accelerations(xx[:f], xx[f:], tt, u_of(tt))
        return np.concatenate([xx[f:], s["ydd"]])

    def record(tt: float, xx: np.ndarray) -> None:
        f = ev.part.f
        s = ev.accelerations(xx[:f], xx[f:], tt, u_of(tt))
        out["t"].append(tt)
        for k in ("z", "zd", "zdd", "Phi", "Phi_dot"):
            out[k].append(s[k])
        out["lam"].append(ev.multipliers(s))

    watermark = max(ev.part.cond, 10.0)
    while True:
        solver = stepper(rhs, t, x, t1, rtol=rtol, atol=atol, max_step=max_step)
        if k_eval < len(tev) and tev[k_eval] == t:
            record(t, x)
            k_eval += 1
        event = None
        try:
            while solver.status == "running":
                z_start = ev.z_guess.copy()
                msg = solver.step()
                if solver.status == "failed":
                    status, message = "failed", str(msg)
                    break
                # samples inside the step, Newton started from the step's beginning (the
                # integrator's trial stages may have left the guess elsewhere)
                z_end = ev.z_guess.copy()
                if k_eval < len(tev) and tev[k_eval] <= solver.t:
                    dense = solver.dense_output()
                    while k_eval < len(tev) and tev[k_eval] <= solver.t:
                        ev.z_guess = z_start.copy()
                        ev._last = None
                        record(float(tev[k_eval]), dense(tev[k_eval]))
                        z_start = ev.z_guess.copy()
                        k_eval += 1
                # the accepted state: its configuration starts the next step, its Φ_d is
                # watched for singularity
                f = ev.part.f
                ev.z_guess = z_end
                ev._last = None
                z_acc, cd, _ = ev.solve_positions(solver.y[:f], solver.t)
                ev.z_guess = z_acc
                c_now = ev.cond(z_acc, solver.t, cd["Phi_z"])
                if c_now > cond_limit or (repartition and c_now > 10 * watermark):
                    event = (float(solver.t), solver.y.copy(), c_now)
                    break
        except SingularConfiguration as exc:
            status, message, singular = "singular", str(exc), exc
            break
        nfev += int(solver.nfev)
        if event is None:
            break
        te, xe, c_now = event
        d = decide(ev, te, xe, c_now, repartition, cond_limit)
        if d.action == "switch":
            assert d.partition is not None and d.z is not None and d.zd is not None
            ev.set_partition(d.partition)
            watermark = max(d.cond, 10.0)
            partitions.append((te, tuple(ev.independent_names)))
            ind = list(d.partition.independent)
            x, t = np.concatenate([d.z[ind], d.zd[ind]]), te
            continue
        if d.action == "continue":
            watermark, x, t = d.cond, xe, te
            continue
        singular = d.singular
        status, message = "singular", str(singular)
        break
    return {"out": out, "partitions": partitions, "status": status, "message": message,
            "singular": singular, "nfev": nfev}


__all__ = ["SOLVERS", "run_scipy"]
