"""First derivatives of the dynamics of a closed system (closing joints, contacts, speeds of
its own; METHOD.md §7) per state: the counterpart of :mod:`jourdain.numeric.derivatives` for
trees, in the closed system's own state.

The state is ``x = (y_i, z)`` (:mod:`jourdain.loops.general`): the independent coordinates
and the generalized velocities (for closing joints alone, the rates of the independent
coordinates), with ``ẋ = (ẏ_i, ż)``, ``M·ż + k = q``. Given as for ``System.evaluate`` by the
tree's coordinates and rates (the dependent ones are solved near those given, the speeds taken
from the rates):

* :meth:`ClosedDerivatives.forward`: ``ẋ``, ``∂ẋ/∂x`` and ``∂ẋ/∂u``;
* :meth:`ClosedDerivatives.inverse`: ``τ = M·ż + k − q`` (along the speeds) and ``∂τ/∂x``,
  ``∂τ/∂ż = M``, ``∂τ/∂u``.

Every number comes from the closed system's evaluation run in complex arithmetic (Newton on the
holonomic rows, the velocity map, the projection) and the complex step
``∂F/∂x_j = Im F(x + iη·e_j)/η``: exact to rounding, as the linearization of a general system
(:mod:`jourdain.loops.general_linear`). It is evaluated in Python, walking the expression
graph in complex arithmetic (:class:`jourdain.graph.complex_step.ComplexTape`, one evaluation
per variable), not compiled: 3 ms per state for the four-bar (x of 2), 0.2–0.4 s for the
benchmark bicycle (x of 10), where a tree's compiled derivatives take microseconds.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import EvaluationError
from ..model import System
from ..numeric.state import state_vectors
from .general import GeneralEvaluator
from .general_choice import Choice

#: the complex step (any tiny number: no difference is formed)
STEP = 1e-60


@dataclass(frozen=True)
class ClosedForwardDerivatives:
    """``xd = (ẏ_i, ż)`` at the state ``x`` (names ``x_names``) and its derivatives ``xd_x``
    (∂ẋ/∂x) and ``xd_u`` (∂ẋ/∂u); ``y, yd, ydd``: the tree's coordinates, rates and
    accelerations there."""

    x_names: tuple[str, ...]
    x: np.ndarray
    xd: np.ndarray
    xd_x: np.ndarray
    xd_u: np.ndarray
    y: np.ndarray
    yd: np.ndarray
    ydd: np.ndarray


@dataclass(frozen=True)
class ClosedInverseDerivatives:
    """``tau = M·ż + k − q`` along the speeds at the state ``x`` and its derivatives
    ``tau_x`` (∂τ/∂x), ``tau_zd`` (∂τ/∂ż = M) and ``tau_u`` (∂τ/∂u)."""

    x_names: tuple[str, ...]
    x: np.ndarray
    tau: np.ndarray
    tau_x: np.ndarray
    tau_zd: np.ndarray
    tau_u: np.ndarray


@dataclass(frozen=True, eq=False)
class ClosedDerivatives:
    """The derivatives of a closed system's dynamics: :meth:`forward`, :meth:`inverse`."""

    system: Any

    def _setup(self, y: Any, yd: Any, u: Any, t: float,
               parameters: Mapping[str, float] | None) -> tuple:
        system = self.system
        tree = system.tree
        names = system.input_names
        inputs = None if u is None else list(np.asarray(u, dtype=float).reshape(-1))
        if inputs is not None and len(inputs) != len(names):
            raise EvaluationError(f"{system.name}: {len(names)} inputs expected, got "
                                  f"{len(inputs)}")
        yv, ydv, tv, _, uv = state_vectors(tree, y, yd, t, parameters, inputs)
        values = {**system.parameter_values, **dict(parameters or {})}
        ev = GeneralEvaluator(system, yv, tv, values, inputs=uv)
        if not system.is_general:  # closing joints alone: the independent coordinates' rates
            ch = ev.choice
            coords = system.coordinate_names
            ev.choice = Choice(ch.independent, ch.dependent, ch.rows_h, ch.rows_v,
                               tuple(f"{coords[j]}_d" for j in ch.independent),
                               ch.independent)
        x0 = ev.initial(yv, ydv, tv)
        s0 = ev.accelerations(x0, tv)
        evc = GeneralEvaluator(system, np.real(s0["y"]), tv, values, inputs=uv,
                               complex_=True, choice=ev.choice)
        coords = system.coordinate_names
        x_names = (*(coords[j] for j in ev.choice.independent), *ev.choice.speeds)
        return ev, evc, x0, s0, uv, tv, x_names

    def _steps(self, evc: GeneralEvaluator, x0: np.ndarray, s0: dict, uv: np.ndarray,
               value: Any, n: int) -> tuple[np.ndarray, np.ndarray]:
        """The complex-step derivatives of ``value(state)`` (``n`` numbers) by x and by u."""
        yref = np.asarray(s0["y"]).astype(complex)
        cols_x = []
        for j in range(len(x0)):
            xc = x0.astype(complex)
            xc[j] += 1j * STEP
            evc.y_guess = yref.copy()
            evc.u = uv.astype(complex)
            cols_x.append(np.imag(value(evc, xc)) / STEP)
        cols_u = []
        for k in range(len(uv)):
            uc = uv.astype(complex)
            uc[k] += 1j * STEP
            evc.y_guess = yref.copy()
            evc.u = uc
            cols_u.append(np.imag(value(evc, x0.astype(complex))) / STEP)
        return (np.array(cols_x).T.reshape(n, len(x0)),
                np.array(cols_u).T.reshape(n, len(uv)))

    def forward(self, y: Any, yd: Any, u: Any = None, t: float = 0.0,
                parameters: Mapping[str, float] | None = None) -> ClosedForwardDerivatives:
        """``ẋ`` and its derivatives at the state given by the tree's ``y``, ``yd``."""
        ev, evc, x0, s0, uv, tv, x_names = self._setup(y, yd, u, t, parameters)
        xd_x, xd_u = self._steps(evc, x0, s0, uv,
                                 lambda e, x: e.accelerations(x, tv)["xd"], len(x0))
        return ClosedForwardDerivatives(x_names, x0, np.real(s0["xd"]), xd_x, xd_u,
                                        np.real(s0["y"]), np.real(s0["yd"]),
                                        np.real(s0["ydd"]))

    def inverse(self, y: Any, yd: Any, zd: Any, u: Any = None, t: float = 0.0,
                parameters: Mapping[str, float] | None = None) -> ClosedInverseDerivatives:
        """``τ = M·ż + k − q`` for the speeds' rates ``zd`` and its derivatives at the state
        given by the tree's ``y``, ``yd``."""
        ev, evc, x0, s0, uv, tv, x_names = self._setup(y, yd, u, t, parameters)
        g = len(ev.choice.speeds)
        zdv = np.asarray(zd, dtype=float).reshape(-1)
        if zdv.size != g or not np.all(np.isfinite(zdv)):
            raise EvaluationError(f"{self.system.name}: zd must be {g} finite numbers (the "
                                  f"rates of the speeds {', '.join(ev.choice.speeds)})")

        def tau(e: GeneralEvaluator, x: np.ndarray) -> np.ndarray:
            s = e.state(x, tv)
            return s["M"] @ zdv + s["k"] - s["q"]

        tau_x, tau_u = self._steps(evc, x0, s0, uv, tau, g)
        M = np.real(s0["M"])
        return ClosedInverseDerivatives(x_names, x0,
                                        M @ zdv + np.real(s0["k"] - s0["q"]), tau_x, M, tau_u)


def closed_derivatives(system: System) -> ClosedDerivatives:
    """:class:`ClosedDerivatives` of a closed system (see the module docstring)."""
    return ClosedDerivatives(system)


__all__ = ["ClosedDerivatives", "ClosedForwardDerivatives", "ClosedInverseDerivatives",
           "closed_derivatives"]
