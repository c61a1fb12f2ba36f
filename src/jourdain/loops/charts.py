"""Changing the chart of a closed-loop simulation: what to do when the condition number of
``Φ_d`` grows along the motion (shared by the C and the SciPy drivers of
:mod:`jourdain.loops.simulate`).

The chart (y, ẏ) degrades long before Φ_d is singular (the rates ẏ → 0 at a limit position of
y). When the condition number has grown tenfold over its value at the partition, a new
partition is chosen by pivoting at that state; when it passes ``cond_limit`` and no better
partition exists there (Φ_z itself has lost rank: a singular position of the mechanism) or
re-partitioning is off, the run stops with a :class:`SingularConfiguration` naming the time,
the state, the condition number, the rank of Φ_z and a partition that would serve.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .closed_loop import LoopEvaluator, Partition, SingularConfiguration


@dataclass
class ChartDecision:
    """``action``: "switch" (to ``partition``, from the state ``z, zd``), "continue" (same
    partition, the mark raised to ``cond``) or "stop" (``singular``)."""

    action: str
    cond: float
    partition: Partition | None = None
    z: np.ndarray | None = None
    zd: np.ndarray | None = None
    singular: SingularConfiguration | None = None


def decide(ev: LoopEvaluator, te: float, xe: np.ndarray, c_now: float, repartition: bool,
           cond_limit: float, z_probe: np.ndarray | None = None,
           t_probe: float | None = None) -> ChartDecision:
    """The decision at the state ``xe = [y, ẏ, …]`` (time ``te``) of the current partition,
    where Φ_d's condition number reached ``c_now`` — there, or at ``z_probe`` (time
    ``t_probe``: a trial state of the integrator's next step, where it was measured)."""
    loop = ev.loop
    f = ev.part.f
    s = ev.state(xe[:f], xe[f:2 * f], te)
    zp = s["z"] if z_probe is None else np.asarray(z_probe, dtype=float)
    tp = te if t_probe is None else float(t_probe)
    rank = ev.rank(zp, tp)
    new = ev.repartition(zp, tp)
    names = [loop.coordinate_names[j] for j in new.independent]
    better = new.cond < c_now / 10 and names != ev.independent_names
    # a partition of another size (where Φ_z has lost rank) would change the degrees of freedom
    if repartition and better and len(new.rows) == len(ev.part.rows):
        return ChartDecision("switch", new.cond, new, s["z"], s["zd"])
    if c_now <= cond_limit:
        # worse than at the partition, but no better one here: go on, watching for more
        return ChartDecision("continue", c_now, z=s["z"], zd=s["zd"])
    state = ", ".join(f"{n} = {v:.6g}" for n, v in zip(loop.coordinate_names, zp,
                                                        strict=True))
    if rank < len(ev.part.rows):
        cause = (f"the constraint Jacobian Φ_z has rank {rank} of {len(ev.part.rows)} there "
                 "(a singular position of the mechanism: no partition helps)")
    elif better:
        cause = (f"a new partition with independent {', '.join(names)} is well-conditioned "
                 f"there (condition {new.cond:.3g})"
                 + ("" if repartition else "; pass repartition=True to switch"))
    else:
        cause = (f"no partition is better conditioned there (the best: {new.cond:.3g}): Φ_z is "
                 "close to losing rank (a singular position of the mechanism)")
    singular = SingularConfiguration(
        f"{loop.name}: singular configuration at t = {tp:.9g}: Φ_d (dependent "
        f"{', '.join(ev.dependent_names)}) has condition number > {cond_limit:.3g}; "
        f"{cause}; state {state}", t=tp, z=zp, zd=s["zd"], cond=c_now, rank=rank,
        suggestion=tuple(names))
    return ChartDecision("stop", c_now, singular=singular)


__all__ = ["ChartDecision", "decide"]
