"""What ``jourdain check`` and ``jourdain run`` show of a loop model.

``check``: the closing joints, the rows of Φ, the degrees of freedom by Grübler's count and by
the rank of the constraint Jacobian at the initial configuration, and the partition.
``run``: assembly, a simulation on the manifold, the constraint residuals |Φ| and |Φ̇| along
the motion, the closing joints' reactions, the energy, and the linearization about the
equilibrium nearest the initial configuration with its eigenvalues: an HTML page with plots
and a CSV of the motion.
"""

from __future__ import annotations

import html
import json
from collections.abc import Mapping
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import JourdainError
from ..simulation.problem import build_integrator_soon
from ..simulation.simulate import DEFAULT_ATOL, DEFAULT_RTOL
from .cli import linearization_document, linearize_near
from ..model import System
from .closed_loop import LoopEvaluator, constraints
from .figures import FIGURES, Painter
from .simulate import SOLVERS, simulate_loop


def loop_summary(model: Any) -> dict[str, Any]:
    """Closing joints, constraint rows, degrees of freedom (Grübler, rank) and partition."""
    loop: System = model.system
    sim = model.simulation
    ev = LoopEvaluator(loop, sim.y0)
    asm = ev.assemble(sim.y0, sim.yd0)
    rank = ev.rank(asm.z)
    planar = _planar_grubler(loop)
    return {
        "closing_joints": [{"name": c.name, "type": c.type, "body_a": c.body_a,
                            "body_b": c.body_b} for c in loop.closing],
        "constraint_rows": constraints(loop).labels,
        "tree_coordinates": loop.coordinate_names,
        "degrees_of_freedom_grubler_spatial": loop.grubler(),
        "degrees_of_freedom_grubler_planar": planar,
        "degrees_of_freedom_rank": loop.f - rank,
        "rank_Phi_z": rank,
        "independent": list(ev.independent_names),
        "dependent": list(ev.dependent_names),
        "cond_Phi_d": ev.part.cond,
        "assembly_residual": {"Phi": asm.Phi, "Phi_dot": asm.Phi_dot,
                              "newton_iterations": asm.iterations},
        "z0": asm.z.tolist(),
    }


def _planar_grubler(loop: System) -> int | None:
    """Grübler's planar count 3·n − Σ(3 − f_j) when every joint is a revolute about z or a
    prismatic joint in the x-y plane (None otherwise)."""
    from ..model.joints import Rot, Trans

    dofs = []
    for b in loop.tree.bodies:
        j = b.joint
        moving = [s for s in j.steps if isinstance(s, Rot) and s.angle.free_symbols
                  or isinstance(s, Trans) and any(v.free_symbols for v in s.vector)]
        for s in moving:
            if isinstance(s, Rot) and tuple(s.axis) != (0, 0, 1):
                return None
            if isinstance(s, Trans) and s.vector[2] != 0:
                return None
        dofs.append(len(j.coordinates))
    total = 3 * len(loop.tree.bodies) - sum(3 - f for f in dofs)
    for c in loop.closing:
        if c.type not in ("revolute", "prismatic") or (c.axis and tuple(c.axis) != (0, 0, 1)
                                                       and c.type == "revolute"):
            return None
        total -= 2
    return total


def check_lines(s: Mapping[str, Any]) -> list[str]:
    """The lines of ``jourdain check`` for a loop model's :func:`loop_summary` ``s``."""
    lines = [f"  loops: {len(s['closing_joints'])} closing joint(s), "
             f"{len(s['constraint_rows'])} constraint equations Φ = 0 "
             f"({', '.join(s['constraint_rows'])})"]
    for c in s["closing_joints"]:
        lines.append(f"    {c['name']:<14} {c['type']:<12} {c['body_a']} ↔ {c['body_b']}")
    planar = s["degrees_of_freedom_grubler_planar"]
    lines.append(
        f"  degrees of freedom of the mechanism: {s['degrees_of_freedom_rank']} by the rank "
        f"{s['rank_Phi_z']} of Φ_z at the assembled initial configuration; Grübler: "
        f"{s['degrees_of_freedom_grubler_spatial']} (spatial)"
        + (f", {planar} (planar)" if planar is not None else ""))
    lines.append(f"  independent: {', '.join(s['independent'])}; dependent: "
                 f"{', '.join(s['dependent'])} (cond Φ_d = {s['cond_Phi_d']:.3g}); assembly "
                 f"residual |Φ| = {s['assembly_residual']['Phi']:.2e}, |Φ̇| = "
                 f"{s['assembly_residual']['Phi_dot']:.2e}")
    return lines


def run_report(model: Any, out: Path, parameters: Mapping[str, float] | None = None,
               t_end: float | None = None,
               pool: ProcessPoolExecutor | None = None) -> list[str]:
    """Simulate and linearize a loop model, write ``index.html``, plots and ``motion.csv``
    into ``out``; returns summary lines. ``pool``: a one-process worker for the figures,
    forked earlier (it is shut down here)."""
    # Matplotlib imported and the figures drawn in a process forked now (or before the model
    # was read), while this one simulates and linearizes (where there are two cores)
    painter = Painter(pool)
    build_integrator_soon()  # compiled while the loop's equations are derived
    try:
        return _report(model, out, parameters, t_end, painter)
    finally:
        painter.close()


def _report(model: Any, out: Path, parameters: Mapping[str, float] | None,
            t_end: float | None, painter: Painter) -> list[str]:
    loop: System = model.system
    sim = model.simulation
    t1 = float(t_end if t_end is not None else sim.t_end)
    out.mkdir(parents=True, exist_ok=True)

    # the file's method and tolerances where it sets them; else tighter defaults than a tree
    # model's (the energy of a conservative loop is reported to 1e-9)
    rtol = sim.rtol if sim.rtol != DEFAULT_RTOL else 1e-10
    atol = sim.atol if sim.atol != DEFAULT_ATOL else 1e-12
    method = sim.method if sim.method in SOLVERS else "DOP853"
    res = simulate_loop(loop, (0.0, t1), sim.y0, sim.yd0, samples=sim.samples,
                        parameters=parameters, rtol=rtol, atol=atol, method=method,
                        inputs=dict(sim.inputs) if sim.inputs else None)
    names = loop.coordinate_names
    # the motion's figures drawn in the worker while this process linearizes
    motion_figs = painter.draw(out, {
        "t": res.t, "z": res.z, "names": list(names), "Phi": res.Phi, "Phi_dot": res.Phi_dot,
        "lam": res.lam, "labels": list(res.labels), "E": res.total_energy})
    lines = res.summary().splitlines()
    # linearization about the equilibrium nearest the initial configuration
    lin = None
    try:
        lin, about = linearize_near(loop, res.z[0] if len(res.t) else sim.y0, parameters)
        lin_doc = linearization_document(loop, lin, about)
        eig = ", ".join(f"{v.real:.6g}{v.imag:+.6g}j" for v in lin.eigenvalues)
        lines.append(f"  linearized about the {about}: z = {np.round(lin.z_s, 6).tolist()}; "
                     f"eigenvalues in {', '.join(lin.names)}: {eig}")
    except (JourdainError, np.linalg.LinAlgError) as exc:
        lines.append(f"  no linearization: {exc}")
    # CSV of the motion, residuals and reactions
    cols = ["t", *names, *[f"{n}_d" for n in names], *[f"Phi[{r}]" for r in res.labels],
            *[f"Phi_d[{r}]" for r in res.labels], *[f"lambda[{r}]" for r in res.labels],
            "T", "V"]
    wrenches = res.closing_reactions()
    for name in wrenches:
        cols += [f"{name}.{q}{c}" for q in "FT" for c in "xyz"]
    data = np.column_stack([res.t, res.z, res.zd, res.Phi, res.Phi_dot, res.lam, res.T,
                            res.V, *[np.column_stack([w["F"], w["T"]])
                                     for w in wrenches.values()]])
    np.savetxt(out / "motion.csv", data, delimiter=",", header=",".join(cols), comments="")
    files = ["index.html", "run.json", "loops.json", "motion.csv"]
    # per closing joint, the tree report's wrench-<joint>.csv columns (A's axes, inertial)
    for name, w in wrenches.items():
        head = ["t", *[f"{name}.{q}_{c}{suffix}" for suffix in ("", "_inertial")
                       for q in "FT" for c in "xyz"]]
        np.savetxt(out / f"wrench-{name}.csv",
                   np.column_stack([res.t, w["F"], w["T"], w["F_inertial"], w["T_inertial"]]),
                   delimiter=",", header=",".join(head), comments="")
        files.append(f"wrench-{name}.csv")
    drawn = painter.draw(out, {"t": res.t, "wrenches": {n: {"F": w["F"], "T": w["T"]}
                                                       for n, w in wrenches.items()}})
    figs = sorted([*motion_figs.result(), *drawn.result()], key=FIGURES.index)
    info = {"name": loop.name, "status": res.status, "message": res.message,
            "max_Phi": res.max_Phi, "max_Phi_dot": res.max_Phi_dot,
            "energy_drift": res.energy_drift,
            "partitions": [[t, list(n)] for t, n in res.partitions],
            "eigenvalues": None if lin is None else [[v.real, v.imag]
                                                     for v in lin.eigenvalues]}
    (out / "loops.json").write_text(json.dumps(info, indent=2))
    if lin is not None:
        (out / "linearization-equilibrium.json").write_text(json.dumps(
            lin_doc, indent=1))
        files.append("linearization-equilibrium.json")
    files += figs
    (out / "run.json").write_text(json.dumps({
        "format": "jourdain-run/1", "model": loop.name, "file": str(getattr(model, "path", "")),
        "status": "complete" if res.status == "finished" else res.status,
        "message": "" if res.status == "finished" else res.message, "files": files,
        "notes": []}, indent=1))
    body = "\n".join(f"<p>{html.escape(x)}</p>" for x in lines)
    imgs = "\n".join(f'<img src="{f}" alt="{f}">' for f in figs)
    (out / "index.html").write_text(
        f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{html.escape(loop.name)}"
        f"</title></head><body><h1>{html.escape(loop.name)}</h1>{body}{imgs}"
        "<p>motion.csv: tree coordinates, rates, constraint residuals, closing-joint "
        "multipliers, energies and each closing joint's force and torque (B on A at A's "
        "joint point, in A's axes) at every sample.</p></body></html>")
    return lines


__all__ = ["check_lines", "loop_summary", "run_report"]
