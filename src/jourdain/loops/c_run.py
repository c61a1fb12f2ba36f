"""jourdain's C integrator (:mod:`jourdain.numeric.integrator_c`) driven with a loop
right-hand side through its ``jd_accel`` hook: the compiled coordinate partitioning
(:mod:`jourdain.loops.simulate`) and the compiled augmented-Lagrangian form
(:mod:`jourdain.loops.redundant`). One ctypes call runs the whole step loop."""

from __future__ import annotations

import ctypes

import numpy as np

from ..simulation.options import C_METHODS  # the C integrator's methods (jd_problem.method)
from ..simulation.problem import address
from ..simulation.simulate import _Problem, integrator_library


class Segment:
    """One run of the C integrator (``jd_integrate``) from ``t`` with the state ``x = [y, ẏ,
    W]`` (f coordinates), the right-hand side ``accel`` (a ``jd_accel`` hook) with ``p`` its
    state, constant inputs ``u``, output at ``te``; :meth:`run` to ``t1``."""

    def __init__(self, f: int, u: np.ndarray, mkq: int, p: int, accel: int, t: float,
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

    def run(self, t1: float) -> int:
        lib = integrator_library()
        while True:
            code = int(lib.jd_integrate(
                ctypes.byref(self.problem), t1, address(self.st), address(self.x),
                address(self.k0), address(self.g_old), address(self.cnt), address(self.te),
                self.te.size, address(self.i_eval), address(self.out_t), address(self.out_x),
                address(self.out_dx), self.out_t.size, address(self.n_out), address(self.ev_t),
                address(self.ev_x), address(self.ev_i), 1, address(self.n_ev), 1 << 20,
                address(self.fail)))
            if code != 1:  # JD_CONTINUE: the step budget of one call used
                return code


FAILED = {-2: "NaN or inf in the state or its derivative", -3: "step size underflow",
           -5: "out of memory"}


__all__ = ["C_METHODS", "FAILED", "Segment"]
