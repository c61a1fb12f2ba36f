"""Energies along a simulated motion (``docs/method.md``, "Numbers, simulation, files"):
T, V, the work of the non-conservative forces and of a prescribed (rheonomic) motion's drive,
compiled once per system, and the energy balance of a run.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import lru_cache
from typing import TYPE_CHECKING, Any

import numpy as np
import symengine as se

from ...stages.kinematics import kinematics  # the model has no stage methods (issue 16)
from ...stages.newton_euler import newton_euler
from .data import TimeHistories

if TYPE_CHECKING:
    from ...model.system import System


#: Gauss–Legendre nodes and weights on [0, 1] (exact for polynomials of degree 5), for the work
#: of a prescribed motion along the interpolated motion
_GAUSS_S = np.array([0.5 - np.sqrt(15) / 10, 0.5, 0.5 + np.sqrt(15) / 10])
_GAUSS_W = np.array([5.0, 8.0, 5.0]) / 18.0


@lru_cache(maxsize=32)
def _energy_function(system: System) -> tuple[Any, bool, tuple[str, ...], bool]:
    from ...analysis.energy import energy
    from ...numeric import lambdify
    from ...symbolic import SymMatrix

    system = system.tree  # a closed system's energies are its tree's at the same state
    e = energy(kinematics(system))
    fn = lambdify(system, {"T": SymMatrix.column([e.T]), "V": SymMatrix.column([e.V])},
                  lean=True)
    return fn, e.conservative, e.nonconservative, e.rheonomic


@lru_cache(maxsize=32)
def _potential_rate_function(system: System) -> Any:
    """Compiled ``∂V/∂t`` (the explicit change of the potential with t), or None where V does
    not depend on t."""
    from ...analysis.energy import energy
    from ...numeric import lambdify
    from ...symbolic import SymMatrix

    system = system.tree  # a closed system's potential is its tree's at the same state
    rate = se.diff(energy(kinematics(system)).V, system.t)
    if rate.is_Number and rate == 0:
        return None
    return lambdify(system, {"dVdt": SymMatrix.column([rate])}, lean=True)


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
    from ...analysis.energy import energy
    from ...numeric import lambdify
    from ...symbolic import SymMatrix

    system = system.tree  # a closed system's bodies move as its tree's at the same state
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
    return lambdify(system, {"a": SymMatrix.column(a), "b": SymMatrix.column([b])},
                    lean=True)



class WithEnergies(TimeHistories):
    """Energies along the motion and the checks of a run: kinetic and potential energy, the
    work of the non-conservative forces and of a prescribed motion's drive, the energy balance
    error and the drift."""

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

