"""Section 5 of the report: the simulation (``simulation.csv``, written as it goes), its
plots, the energy balance, reaction forces and joint wrenches along the motion
(``wrench-<joint>.csv``), snapshots, the animation and the 3-D view."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import JourdainError
from ...units import axis_label, reactions_label, shared_label
from ...workflow import has_capability
from .. import capabilities
from ..viewer import report_section
from .figures import Figures, snapshot_strip, time_plot
from .html import esc, note, numstr
from .motion import animation, motion_of
from .state import ReportInfo, Run


def simulation_section(run: Run) -> str:
    """Section 5: the motion from the model's initial state (a failure or Ctrl-C keeps what
    was computed: ``run.info.status`` says which)."""
    model, out, info = run.model, run.out, run.info
    system = model.system
    coords = system.coordinate_names
    s = ["<h2>5. Simulation</h2>"]
    if not has_capability("simulate"):
        s.append(note("simulation is not available yet in this version of jourdain"))
        info.notes.append("simulation: not available yet")
    else:
        csv = out / "simulation.csv"
        try:
            t0 = time.perf_counter()
            # written as the run goes (a closed system's at its end or on an interruption); a
            # failed run keeps the motion up to the failure
            try:
                res = capabilities.simulate(model, run.params, t_end=run.t_end,
                                            progress=run.progress, output=csv)
            except JourdainError as exc:
                partial = getattr(exc, "results", None)  # the motion up to the failure
                if partial is None or len(partial.t) < 2:
                    raise
                res = partial
                if system.closing:
                    res.save(csv)
                info.status, info.message = "failed", f"the simulation failed: {exc}"
            wall = time.perf_counter() - t0
            run.results = res
            info.files.append(csv)
            if system.closing and res.status not in ("finished", "interrupted"):
                # stopped on the manifold (a singular position): the motion up to there
                info.status, info.message = "failed", f"the simulation stopped: {res.message}"
            if res.interrupted:
                info.status, info.message = "interrupted", f"the simulation was {res.message}"
            if res.status in ("interrupted", "failed"):
                s.append(note(f"{info.message}. The plots and simulation.csv hold the motion "
                               f"up to t = {res.t[-1]:g} s."))
                info.notes.append(f"simulation: {res.status} at t = {res.t[-1]:g} s")
            sim = model.simulation
            s.append(f"<p>t = 0 … {numstr(res.t[-1])} s, method {esc(sim.method)}, rtol "
                     f"{sim.rtol:g}, atol {sim.atol:g}; {len(res.t)} output samples; "
                     f"{wall:.2f} s wall time (with compilation). Data: simulation.csv.</p>")
            # axis labels with units (jourdain.units): "phi1 / rad", "x_d / (m/s)"
            s.append(run.figures.add(time_plot, res.t, {res.label(c): res.y[:, i] for i, c in enumerate(coords)},
                                shared_label([(c, res.unit(c)) for c in coords], "y"),
                                "coordinates"))
            s.append(run.figures.add(time_plot, res.t, {res.label(f"{c}_d"): res.yd[:, i]
                                        for i, c in enumerate(coords)},
                                shared_label([(f"{c}_d", res.unit(f"{c}_d")) for c in coords],
                                             "ẏ"), "rates"))
            try:
                Tk, V, W = res.kinetic_energy, res.potential_energy, res.work_nonconservative
                Wd = res.work_drive
                s.append(run.figures.add(time_plot, res.t, {"T (kinetic)": Tk, "V (potential)": V,
                                            "T + V − W_nc − W_drive": Tk + V - W - Wd},
                                    axis_label("energy", res.unit("T")), "energy balance"))
                driven = prescribed_joints(system)
                why = (f" (with the work W_drive of the prescribed motion of "
                       f"{', '.join(driven)})" if driven else "")
                if system.closing:  # the run's W: ∫ẏᵀq dt over the interpolated samples
                    why += (" (a closed system's work of the applied forces is integrated "
                            "over the output samples' quintic interpolation, three Gauss "
                            "points per step)")
                s.append(f"<p class='meta'>energy balance error (relative): "
                         f"{res.energy_balance_error:.2e}{esc(why)}</p>")
                info.summary_lines.append(
                    f"  simulated t = 0 … {res.t[-1]:g} s, energy balance error "
                    f"{res.energy_balance_error:.1e}"
                    + (" (prescribed motion's work included)" if driven else ""))
            except (JourdainError, KeyError, AttributeError, ValueError) as exc:
                s.append(note(f"energies not available: {exc}"))
                info.summary_lines.append(f"  simulated t = 0 … {res.t[-1]:g} s")
            try:
                g = res.g
                labels = res.g_names
                keep = list(range(min(12, g.shape[1])))
                s.append(run.figures.add(time_plot, res.t, {res.label(labels[i]): g[:, i] for i in keep},
                                    reactions_label(labels, res.units),
                                    "reaction forces along the motion"
                                    + ("" if len(keep) == g.shape[1] else
                                       f" (first {len(keep)} of {g.shape[1]})")))
            except (JourdainError, KeyError, AttributeError, ValueError) as exc:
                s.append(note(f"reaction forces along the motion not available: {exc}"))
            try:
                s.append(wrench_section(res, out, info, run.figures))
            except (JourdainError, KeyError, AttributeError, ValueError) as exc:
                s.append(note(f"joint wrenches along the motion not available: {exc}"))
            try:
                mo = motion_of(model, res, run.params)
                s.append("<h3>Snapshots of the motion</h3>" + run.figures.add(snapshot_strip, mo, model.view))
                s.append("<h3>Animation</h3>" + animation(mo, model.view)
                         + "<p class='meta'>Lines join the body frames along the tree; dots "
                           "are the centres of mass (size by mass); the triangle is the "
                           "inertial origin."
                         + (" Red lines join each closing joint's body frames to its points "
                            "(the loops drawn closed)." if mo.closing else "") + "</p>")
            except (JourdainError, KeyError, AttributeError, ValueError) as exc:
                s.append(note(f"positions along the motion not available: {exc}"))
            # the 3-D view (jourdain.io.viewer): its own page with three.js, in a sandboxed
            # iframe, so that this page itself runs no script
            s.append(report_section(res, model))
        except JourdainError as exc:
            s.append(note(f"the simulation failed: {exc}"))
            info.notes.append(f"simulation: {exc}")
            info.status, info.message = "failed", f"the simulation failed: {exc}"
            if csv.is_file():  # the initial state, where the run failed at once
                info.files.append(csv)
    return "".join(s)


def prescribed_joints(system: Any) -> list[str]:
    """Joints whose steps depend on t explicitly (rheonomic drives)."""
    out = []
    for b in system.bodies:
        for st in b.joint.steps:
            exprs = [st.angle] if hasattr(st, "angle") else list(st.vector)
            if any("t" in {str(x) for x in e.free_symbols} for e in exprs):
                out.append(b.joint.name)
                break
    return out


def wrench_section(res: Any, out: Path, info: ReportInfo,
                   figures: Figures | None = None) -> str:
    """The magnitudes of each joint's force and torque along the motion (a plot; the vectors
    in the joint and the inertial frame in ``wrench-<joint>.csv``, one table per joint); the plot drawn by ``figures``, else here."""
    own = figures is None  # a page of its own: the plot put in place here
    figures = Figures() if figures is None else figures
    wrenches = res.joint_wrenches
    series: dict[str, np.ndarray] = {}
    files = []
    for name, w in wrenches.items():
        series[f"|F| {name}"] = np.linalg.norm(w.force, axis=1)
        series[f"|T| {name}"] = np.linalg.norm(w.torque, axis=1)
        cols, data = res.joint_wrench_table(name)
        fn = out / f"wrench-{name}.csv"
        np.savetxt(fn, data, delimiter=",", header=",".join(cols), comments="")
        info.files.append(fn)
        files.append(fn.name)
    keep = dict(list(series.items())[:12])
    html = (figures.add(time_plot, res.t, keep, reactions_label(res.g_names, res.units),
                       "joint wrenches along the motion (on the child body at the joint point)"
                       + ("" if len(keep) == len(series) else
                          f" (first {len(keep)} of {len(series)})"))
            + "<p class='meta'>Force and torque vectors per joint, in the joint frame and in "
              f"the inertial frame: {esc(', '.join(files))}.</p>")
    return figures.fill(html) if own else html
