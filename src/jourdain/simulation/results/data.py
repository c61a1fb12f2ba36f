"""The sampled motion of a simulation run (``docs/method.md``, "Numbers, simulation,
files"): the time histories and the run's metadata, their units, the motion between the samples
(quintic Hermite interpolation), and the reaction forces and positions of points along it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING, Any

import numpy as np

from ...errors import EvaluationError, JourdainError
from ...stages.kinematics import kinematics  # the model has no stage methods (issue 16)
from ...units import axis_label, model_units, per_time, unit_of

if TYPE_CHECKING:
    from ...model.system import System

#: plots draw the interpolated motion at this many evenly spaced times plus every sample: a run
#: over n periods of its motion gets at least PLOT_POINTS / n points per period
PLOT_POINTS = 2000


@dataclass(frozen=True)
class ConstraintHistories:
    """The closing joints' rows along a closed system's motion (METHOD.md §7): ``labels`` (r
    names), ``Phi``, ``Phi_dot`` (N, r) the residuals of ``Φ = 0``, ``Φ̇ = 0``, ``multipliers``
    (N, r) the λ of ``M_tree·ÿ + k_tree − q_tree = Φ_yᵀλ``, ``partitions``: ``[(t_start,
    independent names), ...]``, ``singular``: the exception that stopped the run, or None."""

    labels: tuple[str, ...]
    Phi: np.ndarray
    Phi_dot: np.ndarray
    multipliers: np.ndarray
    partitions: tuple[tuple[float, tuple[str, ...]], ...] = ()
    singular: BaseException | None = None


@lru_cache(maxsize=32)
def _positions_function(system: System) -> Any:
    from ...numeric import lambdify

    kin = kinematics(system.tree)  # a closed system's bodies move as its tree's at the same y
    mats = {}
    for bk in kin.bodies:
        mats[f"{bk.name}.r_O"] = bk.r_O
        mats[f"{bk.name}.r"] = bk.r
    return lambdify(system, mats, lean=True)



class TimeHistories:
    """The sampled motion of a run and what it carries: times, coordinates, rates,
    accelerations, inputs, work, the run's metadata; the motion between the samples, reaction
    forces and positions of points along it (the base of :class:`jourdain.simulation.results.Results`)."""

    def __init__(self, system: System | None, t: np.ndarray, y: np.ndarray, yd: np.ndarray,
                 ydd: np.ndarray, u: np.ndarray, W: np.ndarray, parameters: dict[str, float],
                 method: str = "", rtol: float = float("nan"), atol: Any = None,
                 status: str = "finished", message: str = "", nfev: int = 0, nsteps: int = 0,
                 n_accepted: int = 0, n_rejected: int = 0, wall_time: float = 0.0,
                 events: dict | None = None, exception: BaseException | None = None,
                 coordinate_names: Sequence[str] | None = None,
                 input_names: Sequence[str] | None = None,
                 units: dict[str, str] | None = None, energies: dict | None = None,
                 name: str | None = None,
                 constraints: ConstraintHistories | None = None) -> None:
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
        self.constraints = constraints

    # --- the closing joints' rows (width 0 for a tree) -------------------------------------
    @property
    def constraint_labels(self) -> list[str]:
        """Names of the closing joints' rows (empty for a tree)."""
        return list(self.constraints.labels) if self.constraints is not None else []

    @property
    def Phi(self) -> np.ndarray:
        """Residuals of the closing joints' rows ``Φ``, (N, r); r = 0 for a tree."""
        c = self.constraints
        return c.Phi if c is not None else np.zeros((len(self.t), 0))

    @property
    def Phi_dot(self) -> np.ndarray:
        """Residuals of ``Φ̇ = 0``, (N, r); r = 0 for a tree."""
        c = self.constraints
        return c.Phi_dot if c is not None else np.zeros((len(self.t), 0))

    @property
    def multipliers(self) -> np.ndarray:
        """The closing rows' multipliers λ, (N, r) (their reactions; r = 0 for a tree)."""
        c = self.constraints
        return c.multipliers if c is not None else np.zeros((len(self.t), 0))

    @property
    def closure_residual(self) -> tuple[float, float]:
        """``(max |Φ|, max |Φ̇|)`` along the motion (0, 0 for a tree)."""
        return (float(np.max(np.abs(self.Phi), initial=0.0)),
                float(np.max(np.abs(self.Phi_dot), initial=0.0)))

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


    def coordinate(self, name: str) -> np.ndarray:
        """Time history of one coordinate (or ``<name>_d`` / ``<name>_dd`` for its rates)."""
        for suffix, arr in (("_dd", self.ydd), ("_d", self.yd), ("", self.y)):
            base = name[: len(name) - len(suffix)] if suffix and name.endswith(suffix) else name
            if (not suffix or name.endswith(suffix)) and base in self.coordinate_names:
                return arr[:, self.coordinate_names.index(base)]
        raise EvaluationError(f'unknown coordinate "{name}"; coordinates are '
                              f"{self.coordinate_names}")


    # --- units ---------------------------------------------------------------------------
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


    def _need_system(self, what: str) -> System:
        if self.system is None:
            raise JourdainError(f"{what} needs the system: these results were loaded from a "
                                "file; pass system= to Results.load")
        return self.system

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
        if system.closing:  # every joint's, the closing joints' included (METHOD.md §7)
            from ...loops.evaluation import closed_reactions_along

            self._energies["g"], self._energies["g_names"] = closed_reactions_along(system, self)
            return
        if system.groups:  # the ordinary joints' (jourdain.analysis.group_reactions)
            from ...analysis.group_reactions import group_reactions_along

            self._energies["g"], self._energies["g_names"] = group_reactions_along(system, self)
            return
        from ...analysis.reactions import _reactions_function, reactions_along

        lay, fn = _reactions_function(system)
        p = np.array([self.parameters[k] for k, _ in system.parameters])
        U = self.u if self.u.shape[1] else None
        out = fn.batch(self.y, self.yd, self.t, p, U)
        self._energies["g"] = reactions_along(lay, out["M_bar"], out["Q_bar"],
                                              out["q_c"][:, :, 0], out["q_e"][:, :, 0])
        self._energies["g_names"] = list(lay.g_names)

    @property
    def joint_wrenches(self) -> dict[str, Any]:
        """The wrench of every joint along the motion, ``{joint: JointWrench}`` with (N, 3)
        arrays: force and torque (about the joint point) on the child body, in the joint frame
        and in the inertial frame (:mod:`jourdain.wrenches`; from :attr:`g`)."""
        if "joint_wrenches" not in self._energies:
            from ...wrenches import joint_wrenches_along

            system = self._need_system("the joint wrenches")
            p = np.array([self.parameters[k] for k, _ in system.parameters])
            if system.groups and not system.closing:
                from ...analysis.group_reactions import group_wrenches_along

                self._energies["joint_wrenches"] = group_wrenches_along(
                    system, self.g, self.t, self.y, self.yd, p)
                return self._energies["joint_wrenches"]
            tree = system.tree  # a closed system's tree joints come first in g
            q = len(self.g_names) - len(self._closing_g_names())
            self._energies["joint_wrenches"] = joint_wrenches_along(tree, self.g[:, :q], self.t,
                                                                    self.y, self.yd, p)
        return self._energies["joint_wrenches"]

    def _closing_g_names(self) -> list[str]:
        labels = set(self.constraint_labels)
        return [n for n in self.g_names if n in labels]

    def joint_wrench_table(self, joint: str) -> tuple[list[str], np.ndarray]:
        """One joint's wrench along the motion as a table: column names and an (N, 13) array
        (t; ``<joint>.F_x`` … ``<joint>.T_z`` in the joint frame; the same with ``_inertial``)."""
        from ...wrenches import wrench_table

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

