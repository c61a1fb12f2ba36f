"""Results of a simulation: time histories, energies, reaction forces, files and plots.

File format (HDF5, written with h5py; readable by h5py, MATLAB ``h5read``, Julia HDF5.jl,
HDFView, ...)::

    /            attributes: format = "jourdain-results", version = 1, system, method, rtol,
                 status, message, coordinates, inputs (JSON lists of names), parameters,
                 units (JSON objects; units: the declared units and the derived ones of the
                 coordinates and inputs), nfev, nsteps, wall_time
    /t           (N,)    time [s]
    /y           (N, f)  coordinates, columns named by the attribute "columns", their units
                         by "units" (JSON list; a string on t, W, T, V: jourdain.units)
    /yd, /ydd    (N, f)  rates and accelerations
    /u           (N, nu) inputs
    /W           (N,)    work of the generalized applied forces q since t0
    /T, /V       (N,)    kinetic and potential energy (when the system was at hand)
    /events/<name>/t, y, yd

A run that writes as it goes (``simulate(..., output=path)``) first fills
``/partial/t`` (N,) and ``/partial/x`` (N, 2f+1: y, ẏ, W) and sets ``status = "running"``; the
complete layout replaces it when the run ends, so a crashed run leaves a readable file.

CSV (``.csv``): one header line of column names (``t, <y>, <y>_d, <y>_dd, <inputs>, W, T, V``)
after comment lines starting with ``#`` that hold the metadata (``status``: finished, event,
interrupted, failed; ``message``: what happened and, for a run cut short, where it ends;
``column_units``: a JSON list of the columns' units, ``""`` where unknown). A run
that writes as it goes appends rows ``t, <y>, <y>_d, W`` under ``status: running``; the complete
file replaces them when the run ends. Both formats are written to a temporary file beside the
target and renamed over it: an interruption while saving leaves the previous file whole.

Sampling: without ``t_eval`` a run keeps the integrator's accepted steps (as many as its
tolerances need: a pendulum swinging for 10 s takes about 100), with the rates and accelerations
there. Between them the motion is the piecewise quintic Hermite polynomial through ``y``, ``ẏ``
and ``ÿ`` at both ends of each step (:meth:`Results.interpolate`), exact at the samples, of
order ``h⁶`` between them. Plots evaluate it on :data:`PLOT_POINTS` evenly spaced times plus
every sample, so they draw smooth curves whatever the step sizes (a pendulum swinging 1 rad at
rtol 1e-8, 98 steps in 10 s: 2e-6 of the amplitude from the exact motion, against 4 % for
straight lines between the steps). For numbers between the steps at the integrator's own
accuracy pass ``t_eval`` to ``simulate``: DOP853's continuous extension is of order 7 (the
pendulum: 8e-8).
"""

from __future__ import annotations

import json
import os
import re
from collections.abc import Callable, Sequence
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import symengine as se

from ..errors import EvaluationError, JourdainError
from ..stages.kinematics import kinematics  # the model has no stage methods (issue 16)
from ..stages.newton_euler import newton_euler
from ..units import (
    axis_label,
    base_units,
    energy_unit,
    model_units,
    per_time,
    reactions_label,
    shared_label,
    unit_of,
)

if TYPE_CHECKING:
    from ..model.system import System

FORMAT = "jourdain-results"
VERSION = 1
#: plots draw the interpolated motion at this many evenly spaced times plus every sample: a run
#: over n periods of its motion gets at least PLOT_POINTS / n points per period
PLOT_POINTS = 2000
#: Gauss–Legendre nodes and weights on [0, 1] (exact for polynomials of degree 5), for the work
#: of a prescribed motion along the interpolated motion
_GAUSS_S = np.array([0.5 - np.sqrt(15) / 10, 0.5, 0.5 + np.sqrt(15) / 10])
_GAUSS_W = np.array([5.0, 8.0, 5.0]) / 18.0


@lru_cache(maxsize=32)
def _energy_function(system: System) -> tuple[Any, bool, tuple[str, ...], bool]:
    from ..analysis.energy import energy
    from ..numeric import lambdify
    from ..symbolic import SymMatrix

    e = energy(kinematics(system))
    fn = lambdify(system, {"T": SymMatrix.column([e.T]), "V": SymMatrix.column([e.V])})
    return fn, e.conservative, e.nonconservative, e.rheonomic


@lru_cache(maxsize=32)
def _potential_rate_function(system: System) -> Any:
    """Compiled ``∂V/∂t`` (the explicit change of the potential with t), or None where V does
    not depend on t."""
    from ..analysis.energy import energy
    from ..numeric import lambdify
    from ..symbolic import SymMatrix

    rate = se.diff(energy(kinematics(system)).V, system.t)
    if rate.is_Number and rate == 0:
        return None
    return lambdify(system, {"dVdt": SymMatrix.column([rate])})


@lru_cache(maxsize=32)
def _drive_power_function(system: System) -> Any:
    """Compiled ``a`` (f×1) and ``b`` (1×1) of the power of a prescribed (rheonomic) motion,
    ``P = aᵀ·ÿ + b``: with ``ṽ = [v̄_1; …; v̄_p; ω̄_1; …; ω̄_p]`` the explicitly time-dependent
    part of the body velocities (centres of mass, inertial; angular, body frames),
    ``P = ṽᵀ·(M̄·J̄·ÿ + q̄^c) + ∂V/∂t``, so ``a = J̄ᵀ·M̄·ṽ`` and ``b = ṽᵀ·q̄^c + ∂V/∂t``.

    Why: ``dT/dt = (J̄ẏ + ṽ)ᵀ·(M̄J̄ÿ + q̄^c)`` along any motion (the gyroscopic moments do no
    work), so ``d(T + V)/dt − ẏᵀq_nc − P = ẏᵀ·(Mÿ + k − q)``: with P the balance checks the
    equations of motion along ẏ just as it does for a scleronomic model, where ṽ = 0.
    """
    from ..analysis.energy import energy
    from ..numeric import lambdify
    from ..symbolic import SymMatrix

    kin = kinematics(system)
    ne = newton_euler(kin)
    zero = se.Integer(0)
    v = [e for bk in kin.bodies for e in bk.v_bar.entries()]
    v += [e for bk in kin.bodies for e in bk.omega_bar.entries()]
    n6 = len(v)
    Mv = [se.Add(*(ne.M_bar[r, c] * v[c] for c in range(n6)
                   if v[c] != zero and ne.M_bar[r, c] != zero)) for r in range(n6)]
    a = [se.Add(*(ne.J_bar[r, j] * Mv[r] for r in range(n6)
                  if Mv[r] != zero and ne.J_bar[r, j] != zero)) for j in range(system.f)]
    b = se.Add(*(v[r] * ne.q_c[r] for r in range(n6) if v[r] != zero),
               se.diff(energy(kin).V, system.t))
    return lambdify(system, {"a": SymMatrix.column(a), "b": SymMatrix.column([b])})


@lru_cache(maxsize=32)
def _positions_function(system: System) -> Any:
    from ..numeric import lambdify

    kin = kinematics(system)
    mats = {}
    for bk in kin.bodies:
        mats[f"{bk.name}.r_O"] = bk.r_O
        mats[f"{bk.name}.r"] = bk.r
    return lambdify(system, mats)


class Results:
    """Time histories of a simulation (see :func:`jourdain.simulation.simulate.simulate`).

    Attributes
    ----------
    t : (N,) times: the integrator's accepted steps, or ``t_eval`` where given (see the module
        docs on sampling; :meth:`interpolate` gives the motion in between)
    y, yd, ydd : (N, f) coordinates, rates, accelerations
    u : (N, nu) inputs
    W : (N,) work of the generalized applied forces ``∫ ẏᵀq dt`` since t0
    parameters : parameter values used
    status : "finished", "event" (stopped by a terminal event), "interrupted" (Ctrl-C or an
        exception in an input function), "failed" (on the exception's ``results``)
    message : what happened, in words
    events : dict
        One entry per :class:`jourdain.simulation.simulate.Event` of the run, keyed by its label (its
        ``name``, else its expression as text), also where it never fired:
        ``{"t": (m,), "y": (m, f), "yd": (m, f)}``, the times of its zero crossings in the
        direction asked for (located on the integrator's continuous extension, in order) and
        the state there. A terminal event's crossing is the last one: the run stops there and
        ``status`` is "event". Saved with the results (``/events/<label>/t, y, yd`` in HDF5;
        not in CSV).
    nfev, nsteps, n_accepted, n_rejected, wall_time : cost of the run

    Energies (need the system; computed on first use): :attr:`kinetic_energy`,
    :attr:`potential_energy`, :attr:`total_energy`, :attr:`work_nonconservative`,
    :attr:`work_drive` and the checks of a run, :attr:`energy_balance_error` (a number for
    every model) and :attr:`energy_drift` (its conservative special case, None otherwise).
    """

    def __init__(self, system: System | None, t: np.ndarray, y: np.ndarray, yd: np.ndarray,
                 ydd: np.ndarray, u: np.ndarray, W: np.ndarray, parameters: dict[str, float],
                 method: str = "", rtol: float = float("nan"), atol: Any = None,
                 status: str = "finished", message: str = "", nfev: int = 0, nsteps: int = 0,
                 n_accepted: int = 0, n_rejected: int = 0, wall_time: float = 0.0,
                 events: dict | None = None, exception: BaseException | None = None,
                 coordinate_names: Sequence[str] | None = None,
                 input_names: Sequence[str] | None = None,
                 units: dict[str, str] | None = None, energies: dict | None = None,
                 name: str | None = None) -> None:
        self.system = system
        self.t, self.y, self.yd, self.ydd, self.u, self.W = t, y, yd, ydd, u, W
        self.parameters = parameters
        self.method, self.rtol, self.atol = method, rtol, atol
        self.status, self.message = status, message
        self.nfev, self.nsteps = nfev, nsteps
        self.n_accepted, self.n_rejected = n_accepted, n_rejected
        self.wall_time = wall_time
        self.events = events or {}
        self.exception = exception
        self.coordinate_names = list(coordinate_names if coordinate_names is not None
                                     else system.coordinate_names)  # type: ignore[union-attr]
        self.input_names = list(input_names if input_names is not None
                                else system.input_names)  # type: ignore[union-attr]
        # declared units with the derived ones of coordinates and inputs (jourdain.units)
        self.units = dict(units if units is not None
                          else model_units(system))  # type: ignore[arg-type]
        self.name = name if name is not None else (system.name if system else "")
        self._energies = dict(energies or {})

    # --- state ---------------------------------------------------------------------------
    @property
    def interrupted(self) -> bool:
        """True when the run was cut short (Ctrl-C, an exception in an input function)."""
        return self.status == "interrupted"

    @property
    def y_final(self) -> np.ndarray:
        return self.y[-1]

    @property
    def yd_final(self) -> np.ndarray:
        return self.yd[-1]

    def __len__(self) -> int:
        return len(self.t)

    def __repr__(self) -> str:
        return (f"Results({self.name!r}: {len(self.t)} points, t = {self.t[0]:.4g} .. "
                f"{self.t[-1]:.4g}, status={self.status!r}, method={self.method}, "
                f"nfev={self.nfev})")

    def summary(self) -> str:
        """What happened, in a few lines: status, cost and, when the system is at hand, the
        relative energy drift (conservative model) or the energy balance error."""
        lines = [f"{self.name}: {self.status} - {self.message}",
                 f"  t = {self.t[0]:.6g} .. {self.t[-1]:.6g} s, {len(self.t)} points, method "
                 f"{self.method}, rtol {self.rtol:g}",
                 f"  {self.n_accepted} steps accepted, {self.n_rejected} rejected, "
                 f"{self.nfev} right-hand sides, {1e3 * self.wall_time:.3f} ms"]
        try:
            if self.conservative:
                lines.append(f"  relative energy drift {self.energy_drift:.3e} (conservative model)")
            else:
                why = [*self._energies["nonconservative"]]
                if self._energies.get("rheonomic"):
                    why.append("the prescribed (rheonomic) motion's drive")
                lines.append(f"  energy balance error {self.energy_balance_error:.3e} "
                             f"(work included of: {', '.join(why)})")
        except JourdainError:
            pass
        return "\n".join(lines)

    def coordinate(self, name: str) -> np.ndarray:
        """Time history of one coordinate (or ``<name>_d`` / ``<name>_dd`` for its rates)."""
        for suffix, arr in (("_dd", self.ydd), ("_d", self.yd), ("", self.y)):
            base = name[: len(name) - len(suffix)] if suffix and name.endswith(suffix) else name
            if (not suffix or name.endswith(suffix)) and base in self.coordinate_names:
                return arr[:, self.coordinate_names.index(base)]
        raise EvaluationError(f'unknown coordinate "{name}"; coordinates are '
                              f"{self.coordinate_names}")

    # --- energies ---------------------------------------------------------------------------
    def _need_system(self, what: str) -> System:
        if self.system is None:
            raise JourdainError(f"{what} needs the system: these results were loaded from a "
                                "file; pass system= to Results.load")
        return self.system

    def _energy(self) -> None:
        if "T" in self._energies:
            return
        system = self._need_system("the energies")
        fn, cons, noncons, rheonomic = _energy_function(system)
        p = np.array([self.parameters[k] for k, _ in system.parameters])
        out = fn.batch(self.y, self.yd, self.t, p, None)
        self._energies.update(T=out["T"][:, 0, 0].copy(), V=out["V"][:, 0, 0].copy(),
                              conservative=cons, nonconservative=noncons, rheonomic=rheonomic)

    @property
    def kinetic_energy(self) -> np.ndarray:
        """``T = ½ Σ (m vᵀv + ωᵀIω)`` from the body velocities, (N,)."""
        self._energy()
        return self._energies["T"]

    @property
    def potential_energy(self) -> np.ndarray:
        """Potential of gravity, linear springs and linear generalized springs, (N,)."""
        self._energy()
        return self._energies["V"]

    @property
    def total_energy(self) -> np.ndarray:
        return self.kinetic_energy + self.potential_energy

    @property
    def work_nonconservative(self) -> np.ndarray:
        """Work of the non-conservative forces since t0: ``W + V − V(t0) − ∫∂V/∂t dt``, (N,).

        ``W`` (integrated with the motion) is the work of all generalized applied forces; the
        conservative ones did ``−∫ẏᵀ·∂V/∂y dt = −(V − V0) + ∫∂V/∂t dt`` of it. The last term,
        the explicit change of a potential with t (gravity on a support moved by a prescribed
        motion), is the drive's and is in :attr:`work_drive`.
        """
        V = self.potential_energy
        return self.W + V - V[0] - self._potential_time_work()

    def _potential_time_work(self) -> np.ndarray:
        """``∫∂V/∂t dt`` since t0 along the motion (three-point Gauss–Legendre per step, as
        :attr:`work_drive`); zeros where V does not depend on t explicitly, and for results
        loaded without the system (which do not know it either, like :attr:`work_drive`)."""
        if "W_Vt" in self._energies:
            return self._energies["W_Vt"]
        system = self.system
        fn = None if system is None else _potential_rate_function(system)
        if system is None or fn is None or len(self.t) < 2:
            W = np.zeros(len(self.t))
        else:
            p = np.array([self.parameters[k] for k, _ in system.parameters])
            W = self._integral(lambda tq, m: fn.batch(m["y"], m["yd"], tq, p, None)["dVdt"]
                               [:, 0, 0])
        self._energies["W_Vt"] = W
        return W

    def _integral(self, rate: Callable[[np.ndarray, dict[str, np.ndarray]], np.ndarray]
                  ) -> np.ndarray:
        """``∫ rate dt`` since t0 at the samples, (N,): three-point Gauss–Legendre per step,
        ``rate(t, motion)`` evaluated at the nodes ``t`` on :meth:`interpolate`'s motion."""
        T = self.t
        h = np.diff(T)
        tq = (T[:-1, None] + h[:, None] * _GAUSS_S[None, :]).reshape(-1)
        r = rate(tq, self.interpolate(tq)).reshape(-1, 3)
        return np.concatenate([[0.0], np.cumsum(h * (r @ _GAUSS_W))])

    @property
    def conservative(self) -> bool:
        self._energy()
        return bool(self._energies["conservative"])

    @property
    def energy_drift(self) -> float | None:
        """Relative drift of ``T + V`` for a conservative model:
        ``max |E(t) − E(t0)| / max(|E(t0)|, max T)``; None for non-conservative models, whose
        check is :attr:`energy_balance_error` (for a conservative model the two measure the same
        balance, with ``W_nc = W_drive = 0``)."""
        if not self.conservative:
            return None
        E = self.total_energy
        scale = max(abs(E[0]), float(np.max(np.abs(self.kinetic_energy))), 1e-300)
        return float(np.max(np.abs(E - E[0])) / scale)

    @property
    def rheonomic(self) -> bool:
        """The kinematics depends on time explicitly (a prescribed motion)."""
        self._energy()
        return bool(self._energies.get("rheonomic"))

    @property
    def work_drive(self) -> np.ndarray:
        """Work done on the bodies by the drive of a prescribed (rheonomic) motion since t0, (N,);
        zeros for a scleronomic model.

        The drive's power is ``P = ṽᵀ·(M̄·J̄·ÿ + q̄^c) + ∂V/∂t`` with ``ṽ`` the explicitly
        time-dependent part of the body velocities (the power of the reaction forces, which only
        that part of the velocities feels, written with the Newton–Euler equations; the
        gravity potential's explicit change). It is integrated along :meth:`interpolate`'s
        motion by three-point Gauss–Legendre quadrature per step.
        """
        if "W_drive" in self._energies:
            return self._energies["W_drive"]
        if not self.rheonomic:
            self._energies["W_drive"] = np.zeros(len(self.t))
            return self._energies["W_drive"]
        system = self._need_system("the work of a prescribed motion")
        W = self._integral(lambda tq, m: self._drive_power(system, tq, **m))
        self._energies["W_drive"] = W
        return W

    def _drive_power(self, system: System, t: np.ndarray, y: np.ndarray, yd: np.ndarray,
                     ydd: np.ndarray) -> np.ndarray:
        fn = _drive_power_function(system)
        p = np.array([self.parameters[k] for k, _ in system.parameters])
        out = fn.batch(y, yd, t, p, None)
        return np.einsum("ni,ni->n", out["a"][:, :, 0], ydd) + out["b"][:, 0, 0]

    @property
    def energy_balance_error(self) -> float:
        """Relative error of the energy balance ``T + V − W_nc − W_drive = const``, a number
        for every model: ``max |B(t) − B(t0)|`` over the largest of ``|T + V|``, ``T``,
        ``|W_nc|`` and ``|W_drive|``.

        ``W_nc`` (:attr:`work_nonconservative`) is the work of the force elements that ``V``
        does not hold (dampers, applied forces and torques, inputs), ``W_drive``
        (:attr:`work_drive`) that of a prescribed motion. For a conservative model this is the
        drift of ``T + V`` (:attr:`energy_drift`). The balance follows from the equations of
        motion (its rate is ``ẏᵀ·(Mÿ + k − q)``), with T and V computed from the body
        velocities and positions apart from M and k, so it checks the integration and the
        equations together. Results loaded from a file without the system hold T and V but
        not whether a prescribed motion did work: pass ``system=`` to :meth:`load` for models
        with one.
        """
        E = self.total_energy
        W_nc = self.work_nonconservative
        W_drive = self.work_drive
        bal = E - W_nc - W_drive
        scale = max(float(np.max(np.abs(E))), float(np.max(np.abs(self.kinetic_energy))),
                    float(np.max(np.abs(W_nc))), float(np.max(np.abs(W_drive))), 1e-300)
        return float(np.max(np.abs(bal - bal[0])) / scale)

    # --- the motion between the samples ----------------------------------------------------
    def interpolate(self, t: Any) -> dict[str, np.ndarray]:
        """The motion at times ``t`` within the run: ``{"y", "yd", "ydd"}``, each (n, f).

        On each step ``[t_i, t_i+1]`` the quintic polynomial that matches ``y``, ``ẏ`` and ``ÿ``
        at both ends (a cubic in ``y`` and ``ẏ`` where ``ÿ`` is not known, e.g. a partial file);
        ``ẏ`` and ``ÿ`` are its derivatives. Exact at the samples; between them its error is
        about ``h⁶·max|y⁽⁶⁾|/46080`` in ``y`` (one more power of h lost per derivative). With the
        long steps of DOP853 that is above the integrator's own error (a pendulum at rtol 1e-8:
        2e-6 of the amplitude against 8e-8) and far below what a plot shows; for numbers at the
        integrator's accuracy, simulate with ``t_eval``.
        """
        tt = np.asarray(t, dtype=float).reshape(-1)
        T = self.t
        if not np.all(np.isfinite(tt)) or (tt.size and (tt.min() < T[0] or tt.max() > T[-1])):
            raise EvaluationError(f"interpolate: times must lie within the run, t = {T[0]:.9g} "
                                  f".. {T[-1]:.9g}")
        return dict(zip(("y", "yd", "ydd"), _hermite(T, self.y, self.yd, self.ydd, tt),
                        strict=True))

    def _plot_times(self) -> np.ndarray:
        """Times at which plots draw the motion: :data:`PLOT_POINTS` evenly spaced ones and
        every sample."""
        if len(self.t) < 2:
            return self.t
        return np.union1d(self.t, np.linspace(self.t[0], self.t[-1], PLOT_POINTS))

    # --- reactions and positions ----------------------------------------------------------
    @property
    def g(self) -> np.ndarray:
        """Generalized reaction forces ``g`` along the motion, (N, q) (columns: ``g_names``)."""
        if "g" not in self._energies:
            self._reactions()
        return self._energies["g"]

    @property
    def g_names(self) -> list[str]:
        if "g_names" not in self._energies:
            self._reactions()
        return self._energies["g_names"]

    def _reactions(self) -> None:
        system = self._need_system("the reaction forces")
        from ..stages.reactions.solution import _reactions_function, projected_reactions, solve_g

        lay, fn = _reactions_function(system)
        p = np.array([self.parameters[k] for k, _ in system.parameters])
        U = self.u if self.u.shape[1] else None
        out = fn.batch(self.y, self.yd, self.t, p, U)
        qc, qe = out["q_c"][:, :, 0], out["q_e"][:, :, 0]
        N, kh, qh = projected_reactions(lay, out["M_bar"], out["Q_bar"], qc, qe)
        g = None
        if not lay.singular_rows:  # N̂ g = k̂ − q̂ for all states in one batched solve
            try:
                g = np.linalg.solve(N, (kh - qh)[:, :, None])[:, :, 0]
            except np.linalg.LinAlgError:
                g = None
        if g is None:  # bodies without inertia or redundant directions: state by state
            g = np.empty((len(self.t), N.shape[1]))
            for i in range(len(self.t)):
                g[i], _ = solve_g(out["Q_bar"][i], N[i], kh[i], qh[i], qc[i], qe[i],
                                  lay.singular_rows, lay.g_names)
        self._energies["g"] = g
        self._energies["g_names"] = list(lay.g_names)

    @property
    def joint_wrenches(self) -> dict[str, Any]:
        """The wrench of every joint along the motion, ``{joint: JointWrench}`` with (N, 3)
        arrays: force and torque (about the joint point) on the child body, in the joint frame
        and in the inertial frame (:mod:`jourdain.wrenches`; from :attr:`g`)."""
        if "joint_wrenches" not in self._energies:
            from ..wrenches import joint_wrenches_along

            system = self._need_system("the joint wrenches")
            p = np.array([self.parameters[k] for k, _ in system.parameters])
            self._energies["joint_wrenches"] = joint_wrenches_along(system, self.g, self.t,
                                                                    self.y, self.yd, p)
        return self._energies["joint_wrenches"]

    def joint_wrench_table(self, joint: str) -> tuple[list[str], np.ndarray]:
        """One joint's wrench along the motion as a table: column names and an (N, 13) array
        (t; ``<joint>.F_x`` … ``<joint>.T_z`` in the joint frame; the same with ``_inertial``)."""
        from ..wrenches import wrench_table

        wrenches = self.joint_wrenches
        if joint not in wrenches:
            raise EvaluationError(f'unknown joint "{joint}"; joints are: {", ".join(wrenches)}')
        return wrench_table(wrenches[joint], self.t)

    def positions(self, body: str, point: str = "origin", t: Any = None) -> np.ndarray:
        """Inertial position of a body's frame origin (``point="origin"``) or centre of mass
        (``"com"``) along the motion, (N, 3) — for plots and animations; at the times ``t``
        (within the run, from :meth:`interpolate`) instead of the samples where given."""
        system = self._need_system("positions")
        system.body(body)
        fn = _positions_function(system)
        p = np.array([self.parameters[k] for k, _ in system.parameters])
        if t is not None:
            tt = np.asarray(t, dtype=float).reshape(-1)
            m = self.interpolate(tt)
            out = fn.batch(m["y"], m["yd"], tt, p, None)  # positions do not depend on inputs
        else:
            out = fn.batch(self.y, self.yd, self.t, p, self.u if self.u.shape[1] else None)
        return out[f"{body}.r_O" if point == "origin" else f"{body}.r"][:, :, 0]

    # --- files ----------------------------------------------------------------------------
    def _columns(self) -> tuple[list[str], np.ndarray]:
        cols = ["t", *self.coordinate_names, *(f"{n}_d" for n in self.coordinate_names),
                *(f"{n}_dd" for n in self.coordinate_names), *self.input_names, "W"]
        data = [self.t[:, None], self.y, self.yd, self.ydd, self.u, self.W[:, None]]
        if self.system is not None or "T" in self._energies:
            try:
                T, V = self.kinetic_energy, self.potential_energy
                cols += ["T", "V"]
                data += [T[:, None], V[:, None]]
            except JourdainError:
                pass
        return cols, np.hstack(data)

    def _meta(self) -> dict[str, Any]:
        return {"format": FORMAT, "version": VERSION, "system": self.name,
                "method": self.method, "rtol": float(self.rtol), "status": self.status,
                "message": self.message, "coordinates": json.dumps(self.coordinate_names),
                "inputs": json.dumps(self.input_names),
                "parameters": json.dumps(self.parameters), "units": json.dumps(self.units),
                "nfev": int(self.nfev), "nsteps": int(self.nsteps),
                "wall_time": float(self.wall_time)}

    def to_xarray(self) -> Any:
        """These results as an ``xarray.Dataset`` (time, coordinate; units and the model's
        hash as attributes; ``jourdain[study]``):
        :func:`jourdain.simulation.labelled.results_dataset`."""
        from .labelled import results_dataset  # xarray, optional (labelled arrays on this floor)

        return results_dataset(self)

    def save(self, path: str | Path) -> Path:
        """Write to ``.h5``/``.hdf5`` (HDF5, see module docs) or ``.csv``, through a temporary
        file renamed over ``path`` (an interruption leaves the previous file whole)."""
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix not in (".csv", ".h5", ".hdf5"):
            raise EvaluationError(f"unknown results file type {path.suffix!r}: use .h5 or .csv")
        tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp{suffix}")
        try:
            if suffix == ".csv":
                cols, data = self._columns()
                meta = {**self._meta(),
                        "column_units": json.dumps([self.unit(c) for c in cols])}
                with open(tmp, "w", encoding="utf-8") as fh:
                    fh.write(_csv_header(meta, cols))
                    np.savetxt(fh, data, delimiter=",", fmt="%.17g")
            else:
                self._save_h5(tmp)
            os.replace(tmp, path)
        finally:
            if tmp.exists():
                tmp.unlink()
        return path

    def _save_h5(self, path: Path) -> None:
        import h5py

        with h5py.File(path, "w") as h:
            for k, v in self._meta().items():
                h.attrs[k] = v
            h["t"] = self.t
            for name, arr, cols in (("y", self.y, self.coordinate_names),
                                    ("yd", self.yd, [f"{n}_d" for n in self.coordinate_names]),
                                    ("ydd", self.ydd, [f"{n}_dd" for n in self.coordinate_names]),
                                    ("u", self.u, self.input_names)):
                h[name] = arr
                h[name].attrs["columns"] = json.dumps(cols)
                h[name].attrs["units"] = json.dumps([self.unit(c) for c in cols])
            h["W"] = self.W
            if self.system is not None or "T" in self._energies:
                try:
                    h["T"] = self.kinetic_energy
                    h["V"] = self.potential_energy
                except JourdainError:
                    pass
            for name in ("t", "W", "T", "V"):  # one unit for a column of its own
                if name in h:
                    h[name].attrs["units"] = self.unit(name)
            grp = h.create_group("events")
            for name, ev in self.events.items():
                g = grp.create_group(name.replace("/", "_"))
                for k in ("t", "y", "yd"):
                    g[k] = ev[k]

    @classmethod
    def load(cls, path: str | Path, system: System | None = None) -> Results:
        """Read a results file written by :meth:`save` (``.h5`` or ``.csv``)."""
        path = Path(path)
        if path.suffix.lower() == ".csv":
            return _load_csv(path, system)
        import h5py

        with h5py.File(path, "r") as h:
            if h.attrs.get("format") != FORMAT:
                raise EvaluationError(f"{path} is not a jourdain results file")
            a = dict(h.attrs)
            names = json.loads(a["coordinates"])
            f = len(names)
            if "partial" in h and "t" not in h:
                x = h["partial/x"][()]
                t = h["partial/t"][()]
                y, yd, W = x[:, :f], x[:, f:2 * f], x[:, 2 * f]
                ydd = np.full_like(y, np.nan)
                u = np.zeros((len(t), len(json.loads(a["inputs"]))))
            else:
                t, y, yd, ydd, u, W = (h[k][()] for k in ("t", "y", "yd", "ydd", "u", "W"))
            energies = {k: h[k][()] for k in ("T", "V") if k in h}
            events = {}
            if "events" in h:
                for k, g in h["events"].items():
                    events[k] = {kk: g[kk][()] for kk in ("t", "y", "yd")}
        if energies and system is None:
            energies.update(conservative=False, nonconservative=())
        elif system is not None:
            energies = {}
        return cls(system, t, y, yd, ydd, u, W, json.loads(a["parameters"]),
                   method=str(a["method"]), rtol=float(a["rtol"]), status=str(a["status"]),
                   message=str(a["message"]), nfev=int(a["nfev"]), nsteps=int(a["nsteps"]),
                   wall_time=float(a["wall_time"]), events=events, coordinate_names=names,
                   input_names=json.loads(a["inputs"]), units=json.loads(a["units"]),
                   energies=energies, name=str(a["system"]))

    # --- plots ----------------------------------------------------------------------------
    def unit(self, name: str) -> str:
        """The unit of a column: ``t``, a coordinate, ``<coordinate>_d``, ``_dd``, an input,
        ``T``, ``V``, ``W``, a reaction component ``<joint>.F_x`` / ``.T_x``; ``""`` where
        unknown (:func:`jourdain.units.unit_of`)."""
        return unit_of(name, self.units, self.coordinate_names)

    def label(self, name: str) -> str:
        """``name / unit`` for an axis or a legend (``phi1_d / (rad/s)``)."""
        return axis_label(name, self.unit(name))

    def _unit(self, name: str, order: int = 0) -> str:
        return per_time(self.units.get(name, ""), order)

    def _label(self, name: str, order: int) -> str:
        return self.label(name + ("" if order == 0 else "_d" if order == 1 else "_dd"))

    def plot(self, what: str = "y", coordinates: Sequence[str] | None = None, ax: Any = None
             ) -> Any:
        """Time histories: ``what`` = "y", "yd", "ydd", "u", "energy" or "g" (reaction forces);
        returns the Axes.

        The motion ("y", "yd", "ydd") and, when the system is at hand, the energies are drawn
        on :data:`PLOT_POINTS` evenly spaced times plus every sample, from :meth:`interpolate`
        (so a run stored at its integrator steps draws smooth curves); inputs and reaction
        forces, known at the samples only, are drawn through the samples.
        """
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots()
        names = list(coordinates) if coordinates is not None else self.coordinate_names
        if what in ("y", "yd", "ydd"):
            order = ("y", "yd", "ydd").index(what)
            tp = self._plot_times()
            arr = self.interpolate(tp)[what]
            for n in names:
                if n not in self.coordinate_names:
                    raise EvaluationError(f'unknown coordinate "{n}"; coordinates are '
                                          f"{self.coordinate_names}")
                ax.plot(tp, arr[:, self.coordinate_names.index(n)],
                        label=self._label(n, order))
            suffix = ("", "_d", "_dd")[order]
            ax.set_ylabel(shared_label([(n + suffix, self._unit(n, order)) for n in names],
                                       ["coordinates", "rates", "accelerations"][order]))
        elif what == "u":
            for i, n in enumerate(self.input_names):
                ax.plot(self.t, self.u[:, i], label=self.label(n))
            ax.set_ylabel(shared_label([(n, self.unit(n)) for n in self.input_names],
                                       "inputs"))
        elif what == "energy":
            tp, T, V, W_nc, W_drive = self._energies_to_plot()
            ax.plot(tp, T, label="T (kinetic)")
            ax.plot(tp, V, label="V (potential)")
            ax.plot(tp, T + V, label="T + V")
            ax.plot(tp, W_nc, label="W_nc (non-conservative work)")
            if self.system is not None and self.rheonomic:
                ax.plot(tp, W_drive, label="W_drive (work of the prescribed motion)")
            ax.set_ylabel(axis_label("energy", energy_unit(self.units)))
        elif what == "g":
            for i, n in enumerate(self.g_names):
                ax.plot(self.t, self.g[:, i], label=self.label(n))
            ax.set_ylabel(reactions_label(self.g_names, self.units))
        else:
            raise EvaluationError(f"plot: what must be y, yd, ydd, u, energy or g, got {what!r}")
        ax.set_xlabel(self.label("t"))
        ax.set_title(self.name)
        ax.legend()
        ax.grid(True)
        return ax

    def _energies_to_plot(self) -> tuple[np.ndarray, ...]:
        """``t, T, V, W_nc, W_drive`` on the plot grid when the system is at hand (T and V
        from the interpolated motion; the works by cubic Hermite interpolation through their
        values and rates at the samples: ``Ẇ = ẏᵀq``, ``Ẇ_drive = P``), else at the samples."""
        if self.system is None or len(self.t) < 2:
            return (self.t, self.kinetic_energy, self.potential_energy,
                    self.work_nonconservative, self.work_drive)
        from ..numeric import mkq_function

        system = self.system
        tp = self._plot_times()
        motion = self.interpolate(tp)
        p = np.array([self.parameters[k] for k, _ in system.parameters])
        fn = _energy_function(system)[0]
        out = fn.batch(motion["y"], motion["yd"], tp, p, None)
        T, V = out["T"][:, 0, 0], out["V"][:, 0, 0]
        q = mkq_function(system).batch(self.y, self.yd, self.t, p,
                                       self.u if self.u.shape[1] else None)["q"][:, :, 0]
        W = _hermite(self.t, self.W, np.einsum("ni,ni->n", self.yd, q), None, tp)[0][:, 0]
        W_nc = W + V - self.potential_energy[0]
        dVdt = _potential_rate_function(system)
        if dVdt is not None:  # − ∫∂V/∂t dt, as work_nonconservative (the drive's work)
            rate = dVdt.batch(self.y, self.yd, self.t, p, None)["dVdt"][:, 0, 0]
            W_nc = W_nc - _hermite(self.t, self._potential_time_work(), rate, None, tp)[0][:, 0]
        W_drive = np.zeros_like(tp)
        if self.rheonomic:
            P = self._drive_power(system, self.t, self.y, self.yd, self.ydd)
            W_drive = _hermite(self.t, self.work_drive, P, None, tp)[0][:, 0]
        return tp, T, V, W_nc, W_drive

    def plot_path(self, body: str, plane: str = "xy", point: str = "origin", ax: Any = None
                  ) -> Any:
        """Path of a body's frame origin (or ``point="com"``) projected on a coordinate plane
        of the inertial frame ("xy", "xz", "yz"); returns the Axes."""
        import matplotlib.pyplot as plt

        if len(plane) != 2 or set(plane) - set("xyz"):
            raise EvaluationError(f'plane must be two of "x", "y", "z", got {plane!r}')
        r = self.positions(body, point, self._plot_times())
        i, j = ("xyz".index(plane[0]), "xyz".index(plane[1]))
        if ax is None:
            _, ax = plt.subplots()
        unit = base_units(self.units)[1]
        ax.plot(r[:, i], r[:, j], label=f"{body} ({point})")
        ax.plot(r[:1, i], r[:1, j], "o", label="start")
        ax.set_xlabel(axis_label(plane[0], unit))
        ax.set_ylabel(axis_label(plane[1], unit))
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_title(f"{self.name}: path of {body}")
        ax.legend()
        ax.grid(True)
        return ax

    def plot_phase(self, coordinate: str, ax: Any = None) -> Any:
        """Phase portrait ``ẏ_i`` over ``y_i``; returns the Axes."""
        import matplotlib.pyplot as plt

        if coordinate not in self.coordinate_names:
            raise EvaluationError(f'unknown coordinate "{coordinate}"; coordinates are '
                                  f"{self.coordinate_names}")
        if ax is None:
            _, ax = plt.subplots()
        i = self.coordinate_names.index(coordinate)
        motion = self.interpolate(self._plot_times())
        ax.plot(motion["y"][:, i], motion["yd"][:, i])
        ax.plot(self.y[:1, i], self.yd[:1, i], "o", label="start")
        ax.set_xlabel(self._label(coordinate, 0))
        ax.set_ylabel(self._label(coordinate, 1))
        ax.set_title(f"{self.name}: phase portrait of {coordinate}")
        ax.legend()
        ax.grid(True)
        return ax


def _hermite(T: np.ndarray, Y: np.ndarray, YD: np.ndarray, YDD: np.ndarray | None,
             t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Piecewise Hermite interpolation through the samples ``(T, Y, YD, YDD)`` at ``t``
    (within ``T[0] .. T[-1]``): on each interval the quintic matching value, first and second
    derivative at both ends, the cubic matching value and first derivative where ``YDD`` is
    None or not finite at an end. Returns the value and its first and second derivatives, each
    (n, columns)."""
    Y = Y.reshape(len(T), -1)
    YD = YD.reshape(len(T), -1)
    if len(T) < 2:
        rows = np.zeros(len(t), dtype=int)
        acc = np.full_like(Y, np.nan) if YDD is None else YDD.reshape(len(T), -1)
        return Y[rows], YD[rows], acc[rows]
    i = np.clip(np.searchsorted(T, t, side="right") - 1, 0, len(T) - 2)
    dt = T[i + 1] - T[i]
    h = np.where(dt > 0, dt, 1.0)[:, None]  # a repeated time: s = 0, the sample itself
    s = np.where(dt > 0, (t - T[i]) / h[:, 0], 0.0)[:, None]
    y0, y1 = Y[i], Y[i + 1]
    v0, v1 = YD[i] * h, YD[i + 1] * h
    # coefficients of p(s) = Σ c_k s^k on the interval, s = (t − t_i)/h
    c0, c1 = y0, v0
    if YDD is None:
        quintic = np.zeros_like(y0, dtype=bool)
        a0 = a1 = np.zeros_like(y0)
    else:
        A0, A1 = YDD.reshape(len(T), -1)[i], YDD.reshape(len(T), -1)[i + 1]
        quintic = np.isfinite(A0) & np.isfinite(A1)
        a0 = np.where(quintic, A0, 0.0) * h**2
        a1 = np.where(quintic, A1, 0.0) * h**2
    c2 = a0 / 2
    A = y1 - c0 - c1 - c2
    B = v1 - c1 - 2 * c2
    C = a1 - 2 * c2
    c3 = np.where(quintic, 10 * A - 4 * B + C / 2, 2 * (y0 - y1) + v0 + v1)
    c4 = np.where(quintic, -15 * A + 7 * B - C, 0.0)
    c5 = np.where(quintic, 6 * A - 3 * B + C / 2, 0.0)
    c2 = np.where(quintic, c2, 3 * (y1 - y0) - 2 * v0 - v1)
    y = c0 + s * (c1 + s * (c2 + s * (c3 + s * (c4 + s * c5))))
    yd = (c1 + s * (2 * c2 + s * (3 * c3 + s * (4 * c4 + s * 5 * c5)))) / h
    ydd = (2 * c2 + s * (6 * c3 + s * (12 * c4 + s * 20 * c5))) / h**2
    return y, yd, ydd


def _load_csv(path: Path, system: System | None) -> Results:
    meta: dict[str, str] = {}
    header = ""
    with path.open() as fh:
        for line in fh:
            if line.startswith("# "):
                k, _, v = line[2:].rstrip("\n").partition(": ")
                meta[k] = v
            else:
                header = line.strip()
                break
    if meta.get("format") != FORMAT:
        raise EvaluationError(f"{path} is not a jourdain results CSV file")
    cols = header.split(",")
    data = np.loadtxt(path, delimiter=",", comments="#", skiprows=len(meta) + 1, ndmin=2)
    names = json.loads(meta["coordinates"])
    inputs = json.loads(meta["inputs"])
    col = {c: i for i, c in enumerate(cols)}

    def block(keys: list[str], missing: float = 0.0) -> np.ndarray:
        if all(k in col for k in keys):
            return data[:, [col[k] for k in keys]] if keys else np.zeros((len(data), 0))
        return np.full((len(data), len(keys)), missing)  # a partial file: t, y, ẏ, W only

    energies = {}
    if "T" in col and system is None:
        energies = {"T": data[:, col["T"]], "V": data[:, col["V"]], "conservative": False,
                    "nonconservative": ()}
    return Results(system, data[:, 0], block(names), block([f"{n}_d" for n in names]),
                   block([f"{n}_dd" for n in names], np.nan), block(inputs), data[:, col["W"]],
                   json.loads(meta["parameters"]), method=meta.get("method", ""),
                   rtol=float(meta.get("rtol", "nan")), status=meta.get("status", ""),
                   message=meta.get("message", ""), nfev=int(meta.get("nfev", 0)),
                   nsteps=int(meta.get("nsteps", 0)),
                   wall_time=float(meta.get("wall_time", 0.0)), coordinate_names=names,
                   input_names=inputs, units=json.loads(meta["units"]), energies=energies,
                   name=meta.get("system", ""))


# --- incremental writing ------------------------------------------------------------------------
_CONTROL = re.compile("[\x00-\x1f\x7f-\x9f\u2028\u2029]")


def _csv_header(meta: dict[str, Any], cols: Sequence[str]) -> str:
    """The comment lines of a results CSV, one per item (a line break in a name or message
    becomes a space, other control characters are written escaped, so that no value shifts
    the header), and the line of column names."""
    lines = [f"# {k}: " + _CONTROL.sub(lambda m: repr(m.group())[1:-1],
                                       " ".join(str(v).splitlines()))
             for k, v in meta.items()]
    return "\n".join([*lines, ",".join(cols)]) + "\n"


class _PartialCsv:
    """A results CSV filled row by row while a run goes: ``t, <y>, <y>_d, W`` under
    ``status: running``; :meth:`Results.save` replaces it with the complete file."""

    def __init__(self, path: str | Path, system: System) -> None:
        names = system.coordinate_names
        units = model_units(system)
        cols = ["t", *names, *(f"{n}_d" for n in names), "W"]
        meta = {"format": FORMAT, "version": VERSION, "system": system.name, "method": "",
                "rtol": float("nan"), "status": "running",
                "message": "run in progress (or killed): the rows hold the accepted steps "
                           "(t, y, ẏ, W)",
                "coordinates": json.dumps(names), "inputs": json.dumps(system.input_names),
                "parameters": json.dumps(system.parameter_values),
                "units": json.dumps(units), "nfev": 0, "nsteps": 0,
                "wall_time": 0.0,
                "column_units": json.dumps([unit_of(c, units, names) for c in cols])}
        self.fh = open(path, "w", encoding="utf-8")  # noqa: SIM115 - closed by close()
        self.fh.write(_csv_header(meta, cols))
        self.fh.flush()

    def append(self, t: np.ndarray, x: np.ndarray) -> None:
        np.savetxt(self.fh, np.column_stack([t, x]), delimiter=",", fmt="%.17g")
        self.fh.flush()

    def close(self) -> None:
        self.fh.close()


def open_incremental(path: str | Path, system: System) -> Any:
    """Create a results file (``.h5``, ``.hdf5`` or ``.csv``) that :func:`append_incremental`
    fills while a run goes."""
    if Path(path).suffix.lower() == ".csv":
        return _PartialCsv(path, system)
    import h5py

    n = 2 * system.f + 1
    h = h5py.File(path, "w")
    h.attrs["format"] = FORMAT
    h.attrs["version"] = VERSION
    h.attrs["system"] = system.name
    h.attrs["status"] = "running"
    h.attrs["message"] = "run in progress (or killed): /partial holds the accepted steps"
    h.attrs["coordinates"] = json.dumps(system.coordinate_names)
    h.attrs["inputs"] = json.dumps(system.input_names)
    h.attrs["parameters"] = json.dumps(system.parameter_values)
    h.attrs["units"] = json.dumps(model_units(system))
    for k, v in (("method", ""), ("rtol", float("nan")), ("nfev", 0), ("nsteps", 0),
                 ("wall_time", 0.0)):
        h.attrs[k] = v
    g = h.create_group("partial")
    g.create_dataset("t", shape=(0,), maxshape=(None,), dtype=float, chunks=(1024,))
    g.create_dataset("x", shape=(0, n), maxshape=(None, n), dtype=float, chunks=(1024, n))
    h.flush()
    return h


def append_incremental(h: Any, t: np.ndarray, x: np.ndarray) -> None:
    """Append accepted steps and flush, so the file is readable if the process dies."""
    if len(t) == 0:
        return
    if isinstance(h, _PartialCsv):
        h.append(t, x)
        return
    dt, dx = h["partial/t"], h["partial/x"]
    m = dt.shape[0]
    dt.resize((m + len(t),))
    dx.resize((m + len(t), dx.shape[1]))
    dt[m:] = t
    dx[m:] = x
    h.flush()
