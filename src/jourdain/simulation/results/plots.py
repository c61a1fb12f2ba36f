"""Plots of simulation results (matplotlib, imported when a plot is drawn): time histories
with units, energies, paths of points and phase portraits, drawn on the interpolated motion at
:data:`~jourdain.simulation.results.data.PLOT_POINTS` times plus every sample.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ...errors import EvaluationError
from ...units import (
    axis_label,
    base_units,
    energy_unit,
    reactions_label,
    shared_label,
)
from .data import _hermite
from .energies import _energy_function, _potential_rate_function
from .files import WithFiles


class WithPlots(WithFiles):
    """Plots of results (matplotlib), with units and labels."""

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
        from ...numeric import mkq_function

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


