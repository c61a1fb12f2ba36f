"""The redundant-coordinate formulations of a closed system's simulation, beside the
coordinate partitioning of :mod:`jourdain.loops.simulate`: the index-1 Lagrange-multiplier
form (``system.simulate(..., formulation="redundant")``, :func:`_simulate_redundant`) and the
augmented-Lagrangian (penalty) form that passes singular positions
(``formulation="penalty"``, :func:`_simulate_penalty`). Both integrate all tree coordinates
and report the constraint residuals as they are; :func:`jourdain.loops.simulate.simulate_closed`
calls them and returns the one :class:`jourdain.Results`."""

from __future__ import annotations

import ctypes
import math
import time
from collections.abc import Callable, Mapping, Sequence
from types import SimpleNamespace
from typing import Any

import numpy as np

from ..errors import EvaluationError
from ..model import System
from ..numeric import mkq_function
from ..simulation.options import check_t_span
from ..simulation.problem import address
from .c_run import C_METHODS, FAILED, Segment
from .closed_loop import LoopEvaluator
from .compiled import loop_library
from .results import _Run


def _simulate_redundant(loop: System, t_span: tuple[float, float], z0: Any,
                        zd0: Any = None, *, samples: int = 501, rtol: float = 1e-10,
                        atol: float = 1e-12, alpha: float = 0.0, beta: float = 0.0,
                        parameters: Mapping[str, float] | None = None,
                        t_eval: Sequence[float] | None = None, method: str = "DOP853",
                        max_step: float = math.inf) -> _Run:
    """The redundant-coordinate (Lagrange multiplier) form beside coordinate partitioning:
    all tree coordinates z, ż integrated (SciPy's ``method``, DOP853 by default) with z̈ and
    λ from
    ``[M_tree −Φ_zᵀ; Φ_z 0]·[z̈; λ] = [q − k; −c − 2αΦ̇ − β²Φ]`` (index 1, Baumgarte's
    stabilization with α, β; 0, 0: none). No partition, so no singular Φ_d; the price is the
    drift of Φ and Φ̇ with the integration error (Baumgarte's terms damp it), which the
    results report as they are (no projection). Assembled first, like the partitioned run.
    Samples at ``t_eval`` (default: ``samples`` equally spaced times).
    """
    from scipy.integrate import solve_ivp

    t0, t1 = check_t_span(t_span)
    ev = LoopEvaluator(loop, z0, t0, parameters)
    asm = ev.assemble(z0, zd0, t0)
    n = loop.f

    def rhs(t: float, x: np.ndarray) -> np.ndarray:  # noqa: D401
        zdd, _ = ev.redundant_accelerations(x[:n], x[n:], t, alpha, beta)
        return np.concatenate([x[n:], zdd])

    tev = _times(t0, t1, samples, t_eval)
    started = time.perf_counter()
    sol = solve_ivp(rhs, (t0, t1), np.concatenate([asm.z, asm.zd]), method=method,
                    rtol=rtol, atol=atol, t_eval=tev, max_step=max_step)
    wall = time.perf_counter() - started

    def sample(z: np.ndarray, zd: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray,
                                                                dict[str, np.ndarray]]:
        zdd, lam = ev.redundant_accelerations(z, zd, t, alpha, beta)
        return zdd, lam, ev._con(z, zd, t)
    return _redundant_results(loop, ev, sol, sample, t0, wall, f"scipy:{method}")


def _times(t0: float, t1: float, samples: int, t_eval: Sequence[float] | None) -> np.ndarray:
    """The sample times: ``t_eval``, or ``samples`` equally spaced ones over [t0, t1]."""
    tev = (np.linspace(t0, t1, samples) if t_eval is None
           else np.asarray(t_eval, dtype=float))
    if tev.size and (tev[0] < t0 or tev[-1] > t1 or np.any(np.diff(tev) <= 0)):
        raise EvaluationError("t_eval must increase within t_span")
    return tev


def _simulate_penalty(loop: System, t_span: tuple[float, float], z0: Any,
                      zd0: Any = None, *, samples: int = 501, rtol: float = 1e-10,
                      atol: float = 1e-12, alpha: float = 1e7, xi: float = 1.0,
                      omega: float = 30.0, iterations: int = 4,
                      parameters: Mapping[str, float] | None = None,
                      engine: str = "c", t_eval: Sequence[float] | None = None,
                      method: str = "DOP853", max_step: float = math.inf) -> _Run:
    """The augmented-Lagrangian (penalty) form in all tree coordinates, for singular
    positions and redundant constraints, where Φ_d of a partition or the bordered matrix of
    :func:`_simulate_redundant` is singular (Bayo & Ledesma's formulation):

        (M_tree + α·Φ_zᵀΦ_z)·z̈ = q − k − Φ_zᵀ·λ − α·Φ_zᵀ·(c + 2ξωΦ̇ + ω²Φ),
        λ ← λ + α·(Φ_z·z̈ + c + 2ξωΦ̇ + ω²Φ)   (``iterations`` times, from λ = 0)

    The leading matrix stays positive definite when Φ_z loses rank. The stabilization must
    be firm where the mechanism can bifurcate (the N four-bar's flat positions): with ω = 10
    the 5 four-bar left its branch within 20 s, with ω = 30 (the default) it stayed on it to
    7e-6 rad (``benchmarks/n_four_bar.py``). The constraints hold to
    the penalty's accuracy (about ‖M‖/α) and the integration error; the residuals are
    reported as they are. ``λ`` of the results are the multipliers of the last iteration.
    ``engine="c"`` (default): the right-hand side in C (``jd_penalty_accel``) run by jourdain's
    C integrator (``method``: DOP853, RK45, Radau); "scipy": the same formula in NumPy under
    SciPy's ``method``. Samples at ``t_eval`` (default: ``samples`` equally spaced times).
    """
    from scipy.integrate import solve_ivp
    from scipy.linalg import cho_factor, cho_solve

    t0, t1 = check_t_span(t_span)
    if engine not in ("c", "scipy"):
        raise EvaluationError(f'engine must be "c" or "scipy", got {engine!r}')
    if engine == "c" and method not in C_METHODS:
        raise EvaluationError(f"the C engine's methods are {', '.join(C_METHODS)}, got "
                              f"{method!r}")
    ev = LoopEvaluator(loop, z0, t0, parameters)
    asm = ev.assemble(z0, zd0, t0)
    n = loop.f

    def accel(z: np.ndarray, zd: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray,
                                                               dict[str, np.ndarray]]:
        z = np.ascontiguousarray(z)
        zd = np.ascontiguousarray(zd)
        tr = ev.tree_mkq.split(ev.tree_mkq.raw(z, zd, t, ev.p, ev.u))
        cd = ev._con(z, zd, t)
        G = cd["Phi_z"]
        Phi_dot = G @ zd + cd["Phi_t"][:, 0]
        stab = cd["c"][:, 0] + 2 * xi * omega * Phi_dot + omega ** 2 * cd["Phi"][:, 0]
        fac = cho_factor(tr["M"] + alpha * (G.T @ G))
        rhs0 = tr["q"][:, 0] - tr["k"][:, 0] - alpha * (G.T @ stab)
        lam = np.zeros(G.shape[0])
        zdd = cho_solve(fac, rhs0)
        for _ in range(iterations):
            lam = lam + alpha * (G @ zdd + stab)
            zdd = cho_solve(fac, rhs0 - G.T @ lam)
        return zdd, lam, cd

    def rhs(t: float, x: np.ndarray) -> np.ndarray:
        return np.concatenate([x[n:], accel(x[:n], x[n:], t)[0]])

    tev = _times(t0, t1, samples, t_eval)
    started = time.perf_counter()
    if engine == "c":  # the same right-hand side in C (loop_c.h), in jourdain's C integrator
        sol = _penalty_c(ev, t0, t1, np.concatenate([asm.z, asm.zd]), tev, rtol, atol,
                         (alpha, xi, omega, iterations), method, max_step)
        ran = method
    else:
        sol = solve_ivp(rhs, (t0, t1), np.concatenate([asm.z, asm.zd]), method=method,
                        rtol=rtol, atol=atol, t_eval=tev, max_step=max_step)
        ran = f"scipy:{method}"
    wall = time.perf_counter() - started

    def sample(z: np.ndarray, zd: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray,
                                                                dict[str, np.ndarray]]:
        zdd, lam, cd = accel(z, zd, t)
        # the sign of λ in M·z̈ = … − Φ_zᵀλ: −λ is the multiplier of the other forms
        return zdd, -lam, cd
    return _redundant_results(loop, ev, sol, sample, t0, wall, ran)


def _simulate_redundant_form(loop: System, formulation: str, t_span: tuple[float, float],
                             z0: Any, zd0: Any, own: Mapping[str, Any], engine: str, *,
                             inputs: Any = None, method: str = "DOP853", **kw: Any) -> _Run:
    """``simulate_closed(..., formulation="redundant" | "penalty")``: the run of
    :func:`_simulate_redundant` or :func:`_simulate_penalty` with the formulation's own
    options ``own``; refuses inputs (not available in these forms yet) and methods SciPy
    lacks."""
    from ..errors import ClosedSystemError

    if inputs is not None and not (isinstance(inputs, Mapping | Sequence) and not inputs):
        raise ClosedSystemError(loop, f'simulate(..., formulation="{formulation}", '
                                "inputs=...): inputs are not available for the "
                                "redundant-coordinate formulations yet")
    solvers = ("DOP853", "RK45", "Radau", "BDF", "LSODA")
    if method not in solvers:
        raise EvaluationError(f"method must be one of {', '.join(solvers)} or "
                              f'"scipy:<method>", got {method!r}')
    if formulation == "redundant":
        return _simulate_redundant(loop, t_span, z0, zd0, method=method, **kw, **own)
    return _simulate_penalty(loop, t_span, z0, zd0, engine=engine, method=method, **kw, **own)


class _Penalty(ctypes.Structure):
    _fields_ = [("tree", ctypes.c_void_p), ("p", ctypes.c_void_p), ("n", ctypes.c_long),
                ("m", ctypes.c_long), ("iterations", ctypes.c_long),
                ("alpha", ctypes.c_double), ("xi", ctypes.c_double),
                ("omega", ctypes.c_double), ("work", ctypes.c_void_p),
                ("lam", ctypes.c_void_p)]


def _penalty_c(ev: LoopEvaluator, t0: float, t1: float, x0: np.ndarray, tev: np.ndarray,
               rtol: float, atol: float, settings: tuple[float, float, float, int],
               method: str = "DOP853", max_step: float = math.inf) -> SimpleNamespace:
    """The penalty form's run in the C integrator (``method``): SciPy's solution's fields."""
    lib = loop_library(ev.loop)
    tree = mkq_function(ev.loop.tree)
    n, m = ev.n, len(ev.labels)
    alpha, xi, omega, iterations = settings
    lib.jd_penalty_work.restype = ctypes.c_long
    lib.jd_penalty_work.argtypes = [ctypes.c_long, ctypes.c_long]
    work = np.zeros(int(lib.jd_penalty_work(n, m)))
    lam = np.zeros(max(m, 1))
    st = _Penalty(tree.address, address(ev.p), n, m, int(iterations), float(alpha), float(xi),
                  float(omega), address(work), address(lam))
    accel = int(ctypes.cast(lib.jd_penalty_accel, ctypes.c_void_p).value or 0)
    seg = Segment(n, ev.u, tree.address, ctypes.addressof(st), accel, t0,
                  np.concatenate([x0, [0.0]]), tev, C_METHODS[method], rtol, atol, max_step)
    code = seg.run(t1)
    k = int(seg.n_out[0])
    message = ("the integration reached t_end" if code == 0 else
               f"the integration failed at t = {seg.fail[0]:.9g}: "
               f"{FAILED.get(code, 'the penalty matrix is not positive definite')}")
    return SimpleNamespace(t=seg.out_t[:k].copy(), y=seg.out_x[:k, :2 * n].T.copy(),
                           status=0 if code == 0 else -1, message=message,
                           nfev=int(seg.cnt[0]))


def _redundant_results(loop: System, ev: Any, sol: Any,
                       sample: Callable[[np.ndarray, np.ndarray, float], tuple], t0: float,
                       wall: float, method: str = "scipy:DOP853") -> _Run:
    """The record of a redundant-coordinate run (:func:`_simulate_redundant`,
    :func:`_simulate_penalty`) from SciPy's solution, each sample evaluated by ``sample(z, ż, t)``
    → ``(z̈, λ, constraint data)``."""
    n = loop.f
    out: dict[str, list] = {k: [] for k in ("z", "zd", "zdd", "Phi", "Phi_dot", "lam")}
    for k in range(len(sol.t)):
        z, zd, t = sol.y[:n, k], sol.y[n:, k], float(sol.t[k])
        zdd, lam, cd = sample(np.ascontiguousarray(z), np.ascontiguousarray(zd), t)
        out["z"].append(z)
        out["zd"].append(zd)
        out["zdd"].append(zdd)
        out["Phi"].append(cd["Phi"][:, 0])
        out["Phi_dot"].append(cd["Phi_z"] @ zd + cd["Phi_t"][:, 0])
        out["lam"].append(lam)
    status = "finished" if sol.status == 0 else "failed"
    return _Run(
        loop, sol.t, np.array(out["z"]), np.array(out["zd"]), np.array(out["zdd"]),
        np.array(out["Phi"]), np.array(out["Phi_dot"]), np.array(out["lam"]),
        list(ev.labels), [(t0, ())], status,
        str(sol.message), int(sol.nfev), wall, None,
        dict(zip([k for k, _ in loop.tree.parameters], ev.p.tolist(), strict=True)),
        method)


__all__: list[str] = []
