"""Results of a simulation: time histories, energies, reaction forces, files and plots.

Modules: :mod:`.data` (the sampled motion, interpolation, reactions and positions along it),
:mod:`.energies`, :mod:`.files` (HDF5, CSV, incremental writing), :mod:`.plots`;
:class:`Results` composes them.

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

import numpy as np

from ...errors import JourdainError
from .data import PLOT_POINTS, TimeHistories
from .files import FORMAT, VERSION, append_incremental, mark_interrupted, open_incremental
from .plots import WithPlots


class Results(WithPlots):
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

    def summary(self) -> str:
        """What happened, in a few lines: status, cost and, when the system is at hand, the
        relative energy drift (conservative model) or the energy balance error."""
        lines = [f"{self.name}: {self.status} - {self.message}",
                 f"  t = {self.t[0]:.6g} .. {self.t[-1]:.6g} s, {len(self.t)} points, method "
                 f"{self.method}, rtol {self.rtol:g}",
                 (f"  {self.n_accepted} steps accepted, {self.n_rejected} rejected, "
                  if self.n_accepted or self.n_rejected else "  ")
                 + f"{self.nfev} right-hand sides, {1e3 * self.wall_time:.3f} ms"]
        c = self.constraints
        if c is not None:  # a closed system's: its partitions, residuals and closing joints
            parts = "; ".join(f"t ≥ {t0:.6g}: {', '.join(n)}" for t0, n in c.partitions)
            phi, phid = self.closure_residual
            lines += [f"  independent coordinates: {parts}",
                      f"  closure residuals: max |Φ| = {phi:.3e}, max |Φ̇| = {phid:.3e}"]
            lines += self._closing_lines()
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

    def _closing_lines(self) -> list[str]:
        """The largest force and torque of each closing joint along the motion (in its body
        A's axes), from the multipliers."""
        if not len(self.t) or self.system is None:
            return []
        if getattr(self.system, "is_general", False):  # contact forces, by row
            c = self.constraints
            assert c is not None
            return [f"  {lab}: max |λ| = {np.abs(c.multipliers[:, i]).max():.4g}"
                    for i, lab in enumerate(c.labels)]
        from ...loops.reactions import closing_reactions

        p = np.array([self.parameters[k] for k, _ in self.system.parameters])
        lines = []
        for name, w in closing_reactions(self.system, self.y, self.multipliers, self.t,
                                         p).items():
            F, T = np.abs(w["F"]).max(axis=0), np.abs(w["T"]).max(axis=0)
            lines.append(f"  closing joint {name}: max |F| = ({F[0]:.4g}, {F[1]:.4g}, "
                         f"{F[2]:.4g}), max |T| = ({T[0]:.4g}, {T[1]:.4g}, {T[2]:.4g}) in its "
                         "body A's axes")
        return lines


__all__ = ["FORMAT", "PLOT_POINTS", "VERSION", "Results", "TimeHistories", "append_incremental",
           "mark_interrupted", "open_incremental"]
