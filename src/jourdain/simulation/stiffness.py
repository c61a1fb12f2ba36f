"""Stiffness of a run, judged between the calls of the compiled step loop.

An explicit method (DOP853, RK45) whose step size is held at its stability limit by a fast
motion takes ever so many tiny steps whatever the tolerances (a 1e12 N/m spring: a million
steps per simulated second, and no word about it): then ``h·|λ|``, the step times the largest
eigenvalue of the Jacobian of the motion's right-hand side, stays near 1 or above, where steps
limited by accuracy keep it far below (0.1–0.5 for the examples, and for a fast oscillation
that the tolerances make the method follow). Radau steps over such a motion when it is not
excited beyond the tolerances; where it is, Radau must follow every oscillation too, and with
its third-order error estimate it takes many more steps than DOP853 (``h·|λ|`` below 0.1).

:class:`StiffnessCheck` looks after each call of the step loop once the run has taken
:data:`MIN_STEPS` steps, and warns once per run (:class:`StiffnessWarning`, one line
on the command line): "stiff: try --method Radau", or that Radau resolves the fastest motion
and DOP853 is faster. It reads the state; the run's numbers are the same with or without it.
"""

from __future__ import annotations

import ctypes
from typing import Any

import numpy as np

from ..errors import StiffnessWarning, warn
from .options import C_METHODS

#: an explicit step with h·|λ| at or above this is held by stability, not accuracy (by the
#: method's code; measured: a 1e12 N/m spring between two masses, DOP853 holds h·|λ| at 1.2-1.7
#: and RK45 at 1.0, where the accuracy-limited steps of an oscillation the tolerances make them
#: follow stay at 0.35-0.5 and 0.1)
EXPLICIT_LIMIT = {C_METHODS["DOP853"]: 0.8, C_METHODS["RK45"]: 0.6}
#: the explicit verdict needs that many calls of the loop in a row (a transient is no verdict)
HELD_CALLS = 2
#: a Radau step with h·|λ| below this resolves the fastest motion
RESOLVED = 0.1
#: a run is judged once it has taken that many steps (a short run is not worth a word: a
#: robot arm's overdamped wrist holds DOP853 at its stability limit for 16 000 steps over 20 s)
MIN_STEPS = 50_000


def spectral_radius(lib: Any, problem: Any, t: float, x: np.ndarray) -> float:
    """The largest |eigenvalue| of ∂f/∂x of the compiled right-hand side at (t, x) (forward
    differences; the work W, last, enters nothing), or NaN where it cannot be formed."""
    n = x.size
    J = np.zeros((n, n))
    xs, f0, fx, fail = x.copy(), np.empty(n), np.empty(n), np.empty(n + 1)
    if lib.jd_rhs(problem, float(t), xs.ctypes.data, f0.ctypes.data, fail.ctypes.data):
        return float("nan")
    for j in range(n - 1):
        d = 1.4901161193847656e-08 * max(1.0, abs(x[j]))
        xs[j] = x[j] + d
        code = lib.jd_rhs(problem, float(t), xs.ctypes.data, fx.ctypes.data, fail.ctypes.data)
        xs[j] = x[j]
        if code:
            return float("nan")
        J[:, j] = (fx - f0) / d
    if not np.isfinite(J).all():
        return float("nan")
    return float(np.abs(np.linalg.eigvals(J)).max(initial=0.0))


class StiffnessCheck:
    """The judgement of one run of a C method (:mod:`jourdain.simulation.runs`)."""

    def __init__(self, lib: Any, setup: Any, method_code: int) -> None:
        self.lib, self.setup = lib, setup
        self.radau = method_code == C_METHODS["Radau"]
        self.limit = EXPLICIT_LIMIT.get(method_code, 0.8)
        self.held = 0  # consecutive calls that ended with the explicit step at its limit
        # Python input functions are the user's: called at the run's own states only
        self.done = bool(getattr(setup, "callables", None))

    def after_call(self, t: float, h: float, x: np.ndarray, steps: int) -> None:
        """After a call of the step loop that left the run unfinished: the state ``x`` at
        ``t``, the step size ``h`` proposed next and the steps taken so far."""
        if self.done or steps < MIN_STEPS:
            return
        rho = spectral_radius(self.lib, ctypes.byref(self.setup.problem), t, x)
        if not (rho > 0 and h > 0):
            return
        hl = h * rho
        where = (f"h = {h:.2g} s against the fastest eigenvalue |λ| = {rho:.3g} 1/s of the "
                 f"linearized motion at t = {t:.6g}: h·|λ| = {hl:.2g}")
        if not self.radau:
            self.held = self.held + 1 if hl >= self.limit else 0
        if self.held >= HELD_CALLS:
            why = (f": the explicit method's step size is held at its stability limit by a fast "
                   f"motion ({where}), so the run takes about {1 / h:.3g} steps per simulated "
                   "second; an implicit method steps over a fast motion that is not excited "
                   "beyond the tolerances (where it is, Radau says so)")
            self._warn('stiff: try method="Radau"' + why, "stiff: try `--method Radau`" + why)
        elif self.radau and hl < RESOLVED:
            why = (f": Radau follows every oscillation of the fastest motion here ({where}; "
                   "excited beyond the tolerances, no method can step over it), and an "
                   "explicit method does that in fewer, cheaper steps")
            self._warn('not stiff: try method="DOP853"' + why,
                       "not stiff: try `--method DOP853`" + why)

    def _warn(self, message: str, command_line: str) -> None:
        self.done = True
        warn(StiffnessWarning(message, command_line))
