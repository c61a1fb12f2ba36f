"""Simulation of closed-loop systems on the constraint manifold (coordinate partitioning).

The state is the independent ``(y, ẏ)``; at every evaluation the dependent coordinates are
solved by Newton on ``Φ(y, d, t) = 0`` (to ``|Φ| ≲ 1e-13·scale``, warm-started from the last
solution) and the dependent rates from ``Φ̇ = 0`` by a linear solve with ``Φ_d``, so every
reported state lies on the manifold to rounding, whatever the integrator's error: the error
of the integration is an error *along* the manifold (in y), never a drift off it. ``ÿ`` comes
from ``M(y, ẏ, t)·ÿ = q − k`` in the independent coordinates
(:class:`jourdain.loops.closed_loop.LoopEvaluator`); the integrator is one of SciPy's
explicit or implicit Runge–Kutta/BDF steppers (DOP853 by default), driven step by step.

Singular configurations: after every accepted step the condition number of ``Φ_d`` is
computed. When it has grown tenfold over its value at the partition (``repartition=True``,
the default) a new partition is chosen by pivoting at that state and the run goes on in it:
the chart (y, ẏ) degrades long before Φ_d is singular (ẏ → 0 at a limit position of y). When
it passes ``cond_limit`` (default 1e6) and no better partition exists there — ``Φ_z`` itself
has lost rank, a singular position of the mechanism — or re-partitioning is off, the run
stops with status "singular" and a :class:`SingularConfiguration` naming the time, the state,
the condition number, the rank of ``Φ_z`` and a partition that would serve (if any). The
augmented-Lagrangian form :func:`simulate_penalty` passes singular positions.

Why not SUNDIALS IDA (scikit-sundae) here, measured (``python benchmarks/loops.py``, the
four-bar of :func:`jourdain.loops.models.four_bar` over 5 s, error of z(5 s) against a run at
rtol 1e-13, on the shared 2-core development machine): this module took 0.68 s at rtol 1e-8
(error 1.9e-7, |Φ| ≤ 3e-15 throughout) and 1.5 s at rtol 1e-10 (error 3.4e-10); IDA 1.2.0 on
the index-1 redundant form in (z, ż, λ), with jourdain's compiled tree and constraints in its
Python residual and its own finite-difference Jacobian, took 18.5 s at rtol 1e-8 (error
1.2e-3, |Φ(5 s)| = 1.2e-4: the index-1 form lets the positions drift) and 479 s at rtol 1e-10
(error 1.2e-4). Every residual is a Python call, like this module's right-hand side, but
IDA needs many more of them (Newton iterations with a finite-difference Jacobian), and
keeping it on the manifold would need the index-2 (GGL) or projected form on top. The
index-1 form stays available for comparisons
(:meth:`LoopEvaluator.redundant_accelerations`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.integrate import BDF, DOP853, RK45, Radau

from ..errors import EvaluationError
from ..simulation.simulate import check_t_span
from .closed_loop import ClosedLoopSystem, LoopEvaluator, SingularConfiguration

#: the steppers :func:`simulate_loop` drives, by ``method``
SOLVERS = {"DOP853": DOP853, "RK45": RK45, "Radau": Radau, "BDF": BDF}


@dataclass
class LoopResults:
    """Time histories of a closed-loop simulation.

    ``t`` (N,); ``z, zd, zdd`` (N, n): the tree's coordinates (on the manifold); ``Phi``,
    ``Phi_dot`` (N, m): the constraint residuals; ``lam`` (N, m): the closing joints'
    multipliers (labels in ``labels``); ``T``, ``V`` (N,): kinetic and potential energy;
    ``partitions``: ``[(t_start, independent names), ...]``; ``status``, ``message``;
    ``singular``: the :class:`SingularConfiguration` that stopped the run, or None;
    ``method``: the integrator that ran.
    """

    loop: ClosedLoopSystem
    t: np.ndarray
    z: np.ndarray
    zd: np.ndarray
    zdd: np.ndarray
    Phi: np.ndarray
    Phi_dot: np.ndarray
    lam: np.ndarray
    T: np.ndarray
    V: np.ndarray
    labels: list[str]
    partitions: list[tuple[float, tuple[str, ...]]]
    status: str = "finished"
    message: str = ""
    nfev: int = 0
    wall_time: float = 0.0
    singular: SingularConfiguration | None = None
    parameters: dict[str, float] = field(default_factory=dict)
    method: str = "DOP853"

    @property
    def coordinate_names(self) -> list[str]:
        return self.loop.coordinate_names

    @property
    def max_Phi(self) -> float:
        """Largest |Φ_i| along the motion."""
        return float(np.max(np.abs(self.Phi))) if self.Phi.size else 0.0

    @property
    def max_Phi_dot(self) -> float:
        """Largest |Φ̇_i| along the motion."""
        return float(np.max(np.abs(self.Phi_dot))) if self.Phi_dot.size else 0.0

    @property
    def total_energy(self) -> np.ndarray:
        return self.T + self.V

    @property
    def energy_drift(self) -> float:
        """max |E − E₀| / max(|E₀|, max T) (meaningful for a conservative model)."""
        E = self.total_energy
        return float(np.max(np.abs(E - E[0])) / max(abs(E[0]), float(np.max(self.T)), 1e-300))

    def coordinate(self, name: str) -> np.ndarray:
        """Time history of a tree coordinate (``<name>_d``, ``<name>_dd``: its rates)."""
        for suffix, arr in (("_dd", self.zdd), ("_d", self.zd), ("", self.z)):
            base = name[: len(name) - len(suffix)] if suffix and name.endswith(suffix) else name
            if (not suffix or name.endswith(suffix)) and base in self.coordinate_names:
                return arr[:, self.coordinate_names.index(base)]
        raise EvaluationError(f'unknown coordinate "{name}"; coordinates are '
                              f"{self.coordinate_names}")

    def reaction(self, label: str) -> np.ndarray:
        """Multiplier history of one constraint row (``closure.Fx``, ...)."""
        if label not in self.labels:
            raise EvaluationError(f'unknown constraint row "{label}"; rows are {self.labels}')
        return self.lam[:, self.labels.index(label)]

    def summary(self) -> str:
        parts = "; ".join(f"t ≥ {t0:.6g}: {', '.join(n)}" for t0, n in self.partitions)
        return "\n".join([
            f"{self.loop.name}: {self.status} - {self.message}",
            f"  t = {self.t[0]:.6g} .. {self.t[-1]:.6g} s, {len(self.t)} points, "
            f"{self.nfev} right-hand sides, {self.wall_time:.3f} s",
            f"  independent coordinates: {parts}",
            f"  constraint residuals: max |Φ| = {self.max_Phi:.3e}, max |Φ̇| = "
            f"{self.max_Phi_dot:.3e}",
            f"  relative energy drift {self.energy_drift:.3e} (meaningful when conservative)"])

    def tree_results(self) -> Any:
        """The motion as :class:`jourdain.Results` of the tree (its coordinates z), for the
        report, CSV/HDF5 and the plots of tree models."""
        from ..simulation.results import Results

        tree = self.loop.tree
        n_u = len(tree.inputs)
        return Results(tree, self.t, self.z, self.zd, self.zdd, np.zeros((len(self.t), n_u)),
                       np.zeros(len(self.t)), dict(self.parameters), method=self.method,
                       status=self.status, message=self.message, nfev=self.nfev,
                       wall_time=self.wall_time)


def simulate_loop(loop: ClosedLoopSystem, t_span: tuple[float, float], z0: Any,
                  zd0: Any = None, *, t_eval: Sequence[float] | None = None,
                  samples: int = 501, rtol: float = 1e-10, atol: float = 1e-12,
                  method: str = "DOP853", parameters: Mapping[str, float] | None = None,
                  inputs: Callable[[float], Any] | Sequence[float] | None = None,
                  repartition: bool = True, cond_limit: float = 1e6,
                  max_step: float = math.inf) -> LoopResults:
    """Integrate a closed-loop system from approximate ``z0, zd0`` (assembled first, the
    independent coordinates of the partition held) over ``t_span``.

    Returns :class:`LoopResults` at ``t_eval`` (default: ``samples`` equally spaced times).
    A singular configuration stops the run with ``status="singular"`` and the exception in
    ``singular`` (the results up to there are kept) unless a new partition resolves it.
    """
    t0, t1 = check_t_span(t_span)
    if not cond_limit > 1:
        raise EvaluationError(f"cond_limit must be > 1, got {cond_limit}")
    n_u = len(loop.tree.inputs)
    if callable(inputs):
        u_of = inputs
    else:
        u_const = np.zeros(n_u) if inputs is None else np.asarray(inputs, dtype=float)
        if u_const.size != n_u:
            raise EvaluationError(f"inputs must have {n_u} entries")

        def u_of(_t: float) -> Any:
            return u_const
    ev = LoopEvaluator(loop, z0, t0, parameters, u_of(t0))
    asm = ev.assemble(z0, zd0, t0)
    tev = (np.linspace(t0, t1, samples) if t_eval is None
           else np.asarray(t_eval, dtype=float))
    if tev.size and (tev[0] < t0 or tev[-1] > t1 or np.any(np.diff(tev) <= 0)):
        raise EvaluationError("t_eval must increase within t_span")
    started = time.perf_counter()
    nfev = 0
    out: dict[str, list] = {k: [] for k in ("t", "z", "zd", "zdd", "Phi", "Phi_dot", "lam",
                                             "T", "V")}
    partitions = [(t0, tuple(ev.independent_names))]
    status, message, singular = "finished", "the integration reached t_end", None
    ind = list(ev.part.independent)
    x = np.concatenate([asm.z[ind], asm.zd[ind]])
    t = t0

    def rhs(tt: float, xx: np.ndarray) -> np.ndarray:
        f = ev.part.f
        s = ev.accelerations(xx[:f], xx[f:], tt, u_of(tt))
        return np.concatenate([xx[f:], s["ydd"]])

    def record(tt: float, xx: np.ndarray) -> None:
        f = ev.part.f
        s = ev.accelerations(xx[:f], xx[f:], tt, u_of(tt))
        out["t"].append(tt)
        for k in ("z", "zd", "zdd", "Phi", "Phi_dot", "T", "V"):
            out[k].append(s[k])
        out["lam"].append(ev.multipliers(s))

    if method not in SOLVERS:
        raise EvaluationError(f"method must be one of {', '.join(SOLVERS)}, got {method!r}")
    k_eval = 0
    # a new partition is sought when Φ_d's condition grows tenfold over this mark: the chart
    # (y, ẏ) degrades long before Φ_d is singular (the rates ẏ → 0 at a limit position of y)
    watermark = max(ev.part.cond, 10.0)
    while True:
        solver = SOLVERS[method](rhs, t, x, t1, rtol=rtol, atol=atol, max_step=max_step)
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
        # the condition of Φ_d passed cond_limit: a new partition, or a report
        te, xe, c_now = event
        f = ev.part.f
        s = ev.state(xe[:f], xe[f:], te)
        rank = ev.rank(s["z"], te)
        new = ev.repartition(s["z"], te)
        old_names = ev.independent_names
        names = [loop.coordinate_names[j] for j in new.independent]
        state = ", ".join(f"{n} = {v:.6g}" for n, v in zip(loop.coordinate_names, s["z"],
                                                            strict=True))
        if repartition and new.cond < c_now / 10 and names != old_names:
            ev.set_partition(new)
            watermark = max(new.cond, 10.0)
            partitions.append((te, tuple(names)))
            ind = list(new.independent)
            x = np.concatenate([s["z"][ind], s["zd"][ind]])
            t = te
            continue
        if c_now <= cond_limit:
            # worse than at the partition, but no better one here: go on, watching for more
            watermark = c_now
            x, t = xe, te
            continue
        cause = (f"the constraint Jacobian Φ_z has rank {rank} of {len(ev.part.rows)} there "
                 "(a singular position of the mechanism: no partition helps)"
                 if rank < len(ev.part.rows) else
                 f"a new partition with independent {', '.join(names)} is well-conditioned "
                 f"there (condition {new.cond:.3g})" + ("" if repartition else
                                                         "; pass repartition=True to switch"))
        singular = SingularConfiguration(
            f"{loop.name}: singular configuration at t = {te:.9g}: Φ_d (dependent "
            f"{', '.join(ev.dependent_names)}) has condition number > {cond_limit:.3g}; "
            f"{cause}; state {state}", t=te, z=s["z"], zd=s["zd"], cond=cond_limit, rank=rank,
            suggestion=tuple(names))
        status, message = "singular", str(singular)
        break
    n = loop.tree.f
    m = len(ev.labels)

    def arr(k: str, w: int) -> np.ndarray:
        return np.array(out[k]).reshape(-1, w) if out[k] else np.zeros((0, w))
    return LoopResults(
        loop, np.array(out["t"]), arr("z", n), arr("zd", n), arr("zdd", n), arr("Phi", m),
        arr("Phi_dot", m), arr("lam", m), np.array(out["T"]), np.array(out["V"]),
        list(ev.labels), partitions, status, message, nfev, time.perf_counter() - started,
        singular, dict(zip([k for k, _ in loop.tree.parameters], ev.p.tolist(), strict=True)),
        method)




def simulate_redundant(loop: ClosedLoopSystem, t_span: tuple[float, float], z0: Any,
                       zd0: Any = None, *, samples: int = 501, rtol: float = 1e-10,
                       atol: float = 1e-12, alpha: float = 0.0, beta: float = 0.0,
                       parameters: Mapping[str, float] | None = None) -> LoopResults:
    """The redundant-coordinate (Lagrange multiplier) form side by side with
    :func:`simulate_loop`: all tree coordinates z, ż integrated (DOP853) with z̈ and λ from
    ``[M_tree −Φ_zᵀ; Φ_z 0]·[z̈; λ] = [q − k; −c − 2αΦ̇ − β²Φ]`` (index 1, Baumgarte's
    stabilization with α, β; 0, 0: none). No partition, so no singular Φ_d; the price is the
    drift of Φ and Φ̇ with the integration error (Baumgarte's terms damp it), which the
    results report as they are (no projection). Assembled first like :func:`simulate_loop`.
    """
    from scipy.integrate import solve_ivp

    t0, t1 = check_t_span(t_span)
    ev = LoopEvaluator(loop, z0, t0, parameters)
    asm = ev.assemble(z0, zd0, t0)
    n = loop.n

    def rhs(t: float, x: np.ndarray) -> np.ndarray:  # noqa: D401
        zdd, _ = ev.redundant_accelerations(x[:n], x[n:], t, alpha, beta)
        return np.concatenate([x[n:], zdd])

    started = time.perf_counter()
    tev = np.linspace(t0, t1, samples)
    sol = solve_ivp(rhs, (t0, t1), np.concatenate([asm.z, asm.zd]), method="DOP853",
                    rtol=rtol, atol=atol, t_eval=tev)
    wall = time.perf_counter() - started

    def sample(z: np.ndarray, zd: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray,
                                                                dict[str, np.ndarray]]:
        zdd, lam = ev.redundant_accelerations(z, zd, t, alpha, beta)
        return zdd, lam, ev._con(z, zd, t)
    return _redundant_results(loop, ev, sol, sample, t0, wall)


def simulate_penalty(loop: ClosedLoopSystem, t_span: tuple[float, float], z0: Any,
                     zd0: Any = None, *, samples: int = 501, rtol: float = 1e-10,
                     atol: float = 1e-12, alpha: float = 1e7, xi: float = 1.0,
                     omega: float = 30.0, iterations: int = 4,
                     parameters: Mapping[str, float] | None = None) -> LoopResults:
    """The augmented-Lagrangian (penalty) form in all tree coordinates, for singular
    positions and redundant constraints, where Φ_d of a partition or the bordered matrix of
    :func:`simulate_redundant` is singular (Bayo & Ledesma's formulation):

        (M_tree + α·Φ_zᵀΦ_z)·z̈ = q − k − Φ_zᵀ·λ − α·Φ_zᵀ·(c + 2ξωΦ̇ + ω²Φ),
        λ ← λ + α·(Φ_z·z̈ + c + 2ξωΦ̇ + ω²Φ)   (``iterations`` times, from λ = 0)

    The leading matrix stays positive definite when Φ_z loses rank. The stabilization must
    be firm where the mechanism can bifurcate (the N four-bar's flat positions): with ω = 10
    the 5 four-bar left its branch within 20 s, with ω = 30 (the default) it stayed on it to
    7e-6 rad (``benchmarks/n_four_bar.py``). The constraints hold to
    the penalty's accuracy (about ‖M‖/α) and the integration error; the residuals are
    reported as they are. ``λ`` of the results are the multipliers of the last iteration.
    """
    from scipy.integrate import solve_ivp
    from scipy.linalg import cho_factor, cho_solve

    t0, t1 = check_t_span(t_span)
    ev = LoopEvaluator(loop, z0, t0, parameters)
    asm = ev.assemble(z0, zd0, t0)
    n = loop.n

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

    started = time.perf_counter()
    sol = solve_ivp(rhs, (t0, t1), np.concatenate([asm.z, asm.zd]), method="DOP853",
                    rtol=rtol, atol=atol, t_eval=np.linspace(t0, t1, samples))
    wall = time.perf_counter() - started

    def sample(z: np.ndarray, zd: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray,
                                                                dict[str, np.ndarray]]:
        zdd, lam, cd = accel(z, zd, t)
        # the sign of λ in M·z̈ = … − Φ_zᵀλ: −λ is the multiplier of the other forms
        return zdd, -lam, cd
    return _redundant_results(loop, ev, sol, sample, t0, wall)


__all__ = ["LoopResults", "simulate_loop", "simulate_penalty", "simulate_redundant"]


def _redundant_results(loop: ClosedLoopSystem, ev: Any, sol: Any,
                       sample: Callable[[np.ndarray, np.ndarray, float], tuple], t0: float,
                       wall: float) -> LoopResults:
    """The results of a redundant-coordinate run (``simulate_redundant``,
    ``simulate_penalty``) from SciPy's solution, each sample evaluated by ``sample(z, ż, t)``
    → ``(z̈, λ, constraint data)``."""
    n = loop.n
    out: dict[str, list] = {k: [] for k in ("z", "zd", "zdd", "Phi", "Phi_dot", "lam", "T",
                                             "V")}
    for k in range(len(sol.t)):
        z, zd, t = sol.y[:n, k], sol.y[n:, k], float(sol.t[k])
        zdd, lam, cd = sample(np.ascontiguousarray(z), np.ascontiguousarray(zd), t)
        out["z"].append(z)
        out["zd"].append(zd)
        out["zdd"].append(zdd)
        out["Phi"].append(cd["Phi"][:, 0])
        out["Phi_dot"].append(cd["Phi_z"] @ zd + cd["Phi_t"][:, 0])
        out["lam"].append(lam)
        out["T"].append(float(cd["T"][0, 0]))
        out["V"].append(float(cd["V"][0, 0]))
    status = "finished" if sol.status == 0 else "failed"
    return LoopResults(
        loop, sol.t, np.array(out["z"]), np.array(out["zd"]), np.array(out["zdd"]),
        np.array(out["Phi"]), np.array(out["Phi_dot"]), np.array(out["lam"]),
        np.array(out["T"]), np.array(out["V"]), list(ev.labels), [(t0, ())], status,
        str(sol.message), int(sol.nfev), wall, None,
        dict(zip([k for k, _ in loop.tree.parameters], ev.p.tolist(), strict=True)),
        "scipy:DOP853")
