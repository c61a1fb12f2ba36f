"""jourdain's C integrator (:mod:`jourdain.numeric.integrator_c`) driven with a loop
right-hand side through its ``jd_accel`` hook: the compiled coordinate partitioning
(:mod:`jourdain.loops.simulate`) and the compiled augmented-Lagrangian form
(:mod:`jourdain.loops.redundant`). One ctypes call runs the whole step loop."""

from __future__ import annotations

from ..simulation.options import C_METHODS  # the C integrator's methods (jd_problem.method)
from ..simulation.problem import Segment  # one run of the C integrator with its own accel

FAILED = {-2: "NaN or inf in the state or its derivative", -3: "step size underflow",
           -5: "out of memory"}


__all__ = ["C_METHODS", "FAILED", "Segment"]
