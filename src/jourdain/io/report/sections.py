"""Sections 1 and 3 of the report: the model as read, and the numbers of the method at its
initial state (``values.json``)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import symengine as se

from ...errors import JourdainError
from ...units import force_unit, model_units, torque_unit
from ...workflow import eval_document, evaluate_all
from ...workflow.evaluation import LINEARIZATION_NAMES
from .. import export
from ..capabilities import T
from .html import SYM, esc, html_table, mathml, matrix_table, note, numstr
from .loops import numbers_rows
from .state import Run, model_copy


def model_section(run: Run) -> str:
    """Section 1: the model's coordinates, parameters, inputs, bodies, joints and force
    elements (and the copy of the model file)."""
    model, out, info, summ = run.model, run.out, run.info, run.summ
    system = model.system
    p = len(system.bodies)
    units = model_units(system)  # declared, and derived for coordinates and inputs
    desc = dict(model.descriptions)
    pv = run.values
    src = Path(model.path)
    copy = out / model_copy(model)
    if src.is_file() and not copy.resolve() == src.resolve():
        shutil.copyfile(src, copy)
        info.files.append(copy)
    names = export.display_names(system)

    def sym(n: str) -> str:
        return mathml(names[n].mathml(), block=False) if n in names else esc(n)

    s = [f"<h2>1. Model</h2><p>{esc(model.description)}</p>" if model.description else
         "<h2>1. Model</h2>"]
    s.append(f"<p>f = {system.f} degrees of freedom, p = {p} bodies, "
             f"{summ['constraints']} constrained directions (reaction forces), "
             f"{len(system.forces)} force elements.</p>")
    if system.closing:  # a closed system: the tree's coordinates bound by the loops
        s.append(f"<p>Closed by the closing joint(s) {esc(', '.join(c.name for c in system.closing))}"
                 f" (section 6): the {system.f} coordinates of the open tree are bound by "
                 "the loops' constraint equations Φ = 0; independent coordinates: "
                 f"{esc(', '.join(system.independent or ('chosen at the initial configuration',)))}"
                 ". The joints below are the tree's; "
                 "the reaction forces of the closing joints are in sections 3, 5 and 6.</p>")
    s.append("<h3>Coordinates</h3>" + html_table(
        [(sym(c), esc(c), esc(units.get(c, "")), esc(desc.get(c, ""))) for c in
         system.coordinate_names], ["", "name", "unit", "description"], "info"))
    if pv:
        s.append("<h3>Parameters</h3>" + html_table(
            [(sym(k), esc(k), numstr(v), esc(units.get(k, "")), esc(desc.get(k, ""))) for k, v in
             pv.items()], ["", "name", "value", "unit", "description"], "info"))
    if system.inputs:
        s.append("<h3>Inputs</h3>" + html_table(
            [(sym(u), esc(u), esc(units.get(u, "")), esc(desc.get(u, ""))) for u in
             system.input_names], ["", "name", "unit", "description"], "info"))
    s.append("<h3>Bodies and joints</h3>" + html_table(
        [(esc(j["body"]), esc(j["parent"]), esc(j["name"]), esc(j["type"]),
          esc(", ".join(j["coordinates"]) or "—"), j["constrained"]) for j in summ["joints"]],
        ["body", "parent", "joint", "type", "coordinates", "constrained"], "info"))
    if system.forces:
        s.append("<h3>Force elements</h3>" + html_table(
            [(esc(f["name"]), esc(f["type"])) for f in summ["forces"]], ["name", "type"], "info"))
    if summ.get("quantities"):
        s.append("<p>Kinematic quantities in the force laws (replaced by their expressions in "
                 "y, ẏ, t in q̄<sup>e</sup>):</p>" + html_table(
                     [(esc(q["name"]), esc(q["definition"]), esc(", ".join(q["symbols"])))
                      for q in summ["quantities"]], ["name", "definition", "symbols"], "info"))
    return "".join(s)


def numbers_section(run: Run) -> str:
    """Section 3: M, k, q and the reaction forces g at the initial state (and
    ``values.json``, the document of ``jourdain eval --json`` there)."""
    model, out, info, pv = run.model, run.out, run.info, run.values
    system = model.system
    units = model_units(system)
    y0 = np.array(model.simulation.y0, float)
    yd0 = np.array(model.simulation.yd0, float)
    u0 = {n: 0.0 for n in system.input_names}
    try:
        for name, e in model.simulation.inputs:
            subs = {se.Symbol(k): v for k, v in pv.items()}
            subs[T] = 0.0
            u0[name] = float(e.subs(subs))
    except (RuntimeError, TypeError, ValueError):
        pass
    s = ["<h2>3. Numbers at the initial state</h2>",
         "<p>" + ", ".join(f"{esc(c)} = {numstr(v)}" for c, v in
                           zip(system.coordinate_names, y0, strict=True))
         + "; " + ", ".join(f"{esc(c)}_d = {numstr(v)}" for c, v in
                            zip(system.coordinate_names, yd0, strict=True))
         + (("; " + ", ".join(f"{esc(k)} = {numstr(v)}" for k, v in u0.items())) if u0 else "")
         + ", t = 0.</p>"]
    coords = system.coordinate_names
    values: dict[str, np.ndarray] = {}
    extra: dict[str, Any] = {}
    try:
        values, extra, missing = evaluate_all(model, y0, yd0, 0.0, run.params, u0)
        if system.closing:  # the closed system's numbers, in its independent coordinates
            # the tree's linearization is no closed system's (section 4 has the closed one)
            missing = {k: v for k, v in missing.items() if k not in LINEARIZATION_NAMES}
            s += numbers_rows(run, values, extra)
        else:
            for k in ("M", "k", "q"):
                s.append(f"<h3>{mathml(SYM[k], False)}</h3>"
                         + matrix_table(values[k], coords, coords if k == "M" else None))
        if "g" in values:
            g = np.asarray(values["g"], float).reshape(-1)
            labels = list(extra.get("g_names", [str(i) for i in range(g.size)]))
            s.append("<h3>Reaction forces g (N̂·g = k̂ − q̂)</h3>"
                     "<p class='meta'>Components in the child body frame at the joint point; "
                     f"forces in {esc(force_unit(units))}, torques in {esc(torque_unit(units))} "
                     "(in the model's units).</p>")
            s.append(matrix_table(g[None, :], None, labels))
            if extra.get("g_undetermined"):
                s.append(note("undetermined components (statically indeterminate): "
                               + ", ".join(extra["g_undetermined"])))
        for k, why in missing.items():
            info.notes.append(f"{k}: {why}")
        if missing:
            s.append(note("not available: " + ", ".join(missing) + " — "
                           + next(iter(missing.values()))))
        vj = eval_document(model, y0, yd0, 0.0, pv, u0, values, extra, missing)
        if system.closing:  # the closed system's: M, k, q in these coordinates
            vj["independent"] = list(extra.get("independent", system.independent or ()))
            vj["dependent"] = list(extra.get("dependent", []))
            vj["constraint_labels"] = list(extra.get("constraint_labels", []))
            vj["closure_residual"] = extra.get("closure_residual")
        (out / "values.json").write_text(json.dumps(vj, indent=1), encoding="utf-8")
        info.files.append(out / "values.json")
    except JourdainError as exc:
        s.append(note(f"could not evaluate at the initial state: {exc}"))
        info.notes.append(f"evaluation: {exc}")
    return "".join(s)
