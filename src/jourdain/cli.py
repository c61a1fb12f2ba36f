"""The ``jourdain`` command: model files in, equations, numbers and reports out.

A thin layer over the public API. Exit status: 0 on success, 1 on a model error (the message,
no traceback; a failed simulation writes the motion up to the failure first), 2 on a usage error
(a malformed option, a name the model does not have, an output that cannot be written), 130
when interrupted (Ctrl-C: what was computed is written and says so). Every subcommand has
``--help`` with an example. Control characters in any text printed (names and messages from a
model file) are shown escaped, never sent to the terminal.
"""

from __future__ import annotations

import argparse
import difflib
import json
import os
import re
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .differentiate import evaluate_float
from .errors import JourdainError
from .model.expressions import values_at
from .stages.reactions import check_reactions

EXIT_OK, EXIT_MODEL, EXIT_USAGE, EXIT_INTERRUPTED = 0, 1, 2, 130
#: seconds between two progress lines of a long simulation
PROGRESS_SECONDS = 2.0

#: The format tag of ``jourdain eval --json`` (bump the number on incompatible changes).
EVAL_FORMAT = "jourdain-eval/1"


class UsageError(Exception):
    """A command-line argument is malformed or names something the model does not have."""


class NotAvailable(Exception):
    """A capability (reactions, linearization, simulation) is not part of this build yet."""


# ------------------------------------------------------------------------------------------
# capabilities that other parts of jourdain provide
# ------------------------------------------------------------------------------------------

def _capability(system: Any, method: str, what: str) -> Callable[..., Any]:
    fn = getattr(system, method, None)
    if fn is None:
        raise NotAvailable(f"{what} is not available yet in this version of jourdain "
                           f"(System.{method} is missing)")
    return fn


def has_capability(method: str) -> bool:
    """Whether :class:`~jourdain.System` offers ``method`` (reactions, linearize, simulate)."""
    from .model.system import System

    return hasattr(System, method)


# ------------------------------------------------------------------------------------------
# argument helpers
# ------------------------------------------------------------------------------------------

def _split_assignments(text: str, option: str) -> list[tuple[str, str]]:
    """``"phi1=0.3, phi1_d=1.0"`` → [("phi1", "0.3"), ("phi1_d", "1.0")] (commas inside
    parentheses belong to the value)."""
    parts, depth, cur = [], 0, ""
    for ch in text:
        if ch == "(":
            depth += 1
        elif ch == ")":
            depth -= 1
        if ch == "," and depth == 0:
            parts.append(cur)
            cur = ""
        else:
            cur += ch
    parts.append(cur)
    out = []
    for p in parts:
        if not p.strip():
            continue
        name, eq, value = p.partition("=")
        if not eq or not name.strip() or not value.strip():
            raise UsageError(f'{option}: expected name=value, got "{p.strip()}"')
        out.append((name.strip(), value.strip()))
    return out


def _number(text: str, where: str) -> float:
    from .io import ExpressionError, parse_number

    try:
        return parse_number(text)
    except ExpressionError as exc:
        raise UsageError(f'{where}: "{text}" is not a number: {exc}') from None


def _overrides(system: Any, sets: Sequence[str]) -> dict[str, float]:
    params = system.parameter_values
    out: dict[str, float] = {}
    for s in sets:
        for name, value in _split_assignments(s, "--set"):
            if name not in params:
                raise UsageError(f'--set: "{name}" is not a parameter of the model; parameters '
                                 f"are {', '.join(params) or '(none)'}")
            out[name] = _number(value, f"--set {name}")
    if out:
        # the model's numbers at these values pass the checks made at the file's defaults
        from .errors import ModelError
        from .model.bodies import check_values

        try:
            check_values(system.bodies, {**params, **out})
        except ModelError as exc:
            given = ", ".join(f"{k}={v:g}" for k, v in out.items())
            raise ModelError(f"with --set {given}: {exc}") from None
    return out


def _state(model: Any, at: str | None) -> tuple[np.ndarray, np.ndarray, float, dict[str, float]]:
    """y, ẏ, t and inputs from ``--at``; unset values come from the model's [simulation]."""
    system = model.system
    y = np.array(model.simulation.y0 or [0.0] * system.f, dtype=float)
    yd = np.array(model.simulation.yd0 or [0.0] * system.f, dtype=float)
    t = 0.0
    inputs = {n: 0.0 for n in system.input_names}
    coords = system.coordinate_names
    for name, value in _split_assignments(at or "", "--at"):
        v = _number(value, f"--at {name}")
        if name == "t":
            t = v
        elif name in coords:
            y[coords.index(name)] = v
        elif name.endswith("_d") and name[:-2] in coords:
            yd[coords.index(name[:-2])] = v
        elif name in inputs:
            inputs[name] = v
        else:
            raise UsageError(f'--at: "{name}" is not a coordinate, a rate (<coordinate>_d), an '
                             f"input or t; coordinates are {', '.join(coords)}")
    return y, yd, t, inputs


def _load(path: str) -> Any:
    from .io import load_model

    try:  # a model file that is not there is a usage error; what it says, a model error
        with open(path, "rb"):
            pass
    except FileNotFoundError:
        raise UsageError(f"{path}: no such model file") from None
    except IsADirectoryError:
        raise UsageError(f"{path}: is a folder; expected a model file (.toml)") from None
    except OSError as exc:
        raise UsageError(f"{path}: cannot read the model file: {exc.strerror}") from None
    if path.lower().endswith(".urdf"):  # a robot description (docs/urdf.md)
        from .io.urdf import load_urdf

        return load_urdf(path)
    return load_model(path)


def _tree_only(model: Any, command: str) -> None:
    """Refuse a command that would treat a loop model as its open tree."""
    if getattr(model, "loops", None) is not None:
        from .errors import ModelError

        names = ", ".join(c.name for c in model.loops.closing)
        raise ModelError(f"{model.path}: the model closes kinematic loops (closing joints "
                         f"{names}); jourdain {command} works on trees and would ignore them: "
                         "use jourdain check and jourdain run, or jourdain.loops in Python "
                         "(evaluate, simulate_loop, linearize_loop)")


def _suggest(name: str, names: Sequence[str]) -> str:
    close = difflib.get_close_matches(name, list(names), n=1)
    return f' (did you mean "{close[0]}"?)' if close else ""


# ------------------------------------------------------------------------------------------
# subcommands
# ------------------------------------------------------------------------------------------

def summary(model: Any) -> dict[str, Any]:
    """Bodies, joints, degrees of freedom and constrained directions of a loaded model.

    The constrained directions of each joint come from the reactions stage (the columns of Q̄)
    when it is available, else from the joint's own freedoms (6 minus them).
    """
    system = model.system
    directions: dict[str, list[str]] = {}
    if has_capability("reactions"):
        try:
            for jr in system.reactions().joints:
                directions[jr.joint.name] = [n.split(".", 1)[-1] for n in jr.names]
        except JourdainError:
            directions = {}
    joints = []
    constraints = 0
    for b in system.bodies:
        j = b.joint
        if j.name in directions:
            names = directions[j.name]
        else:
            freedoms = sum(1 for s in j.steps
                           if {str(x) for x in _step_exprs(s)} & set(system.coordinate_names))
            names = [f"{6 - freedoms} directions"]
        count = len(directions[j.name]) if j.name in directions else 6 - freedoms
        constraints += count
        joints.append({"name": j.name, "type": j.kind, "body": b.name, "parent": b.parent,
                       "coordinates": [str(c) for c in j.coordinates], "constrained": count,
                       "constrained_directions": names if j.name in directions else []})
    return {
        "name": system.name, "file": model.path, "degrees_of_freedom": system.f,
        "coordinates": system.coordinate_names, "bodies": system.body_names,
        "joints": joints, "constraints": constraints,
        "parameters": system.parameter_values, "inputs": system.input_names,
        "forces": [{"name": f.name, "type": type(f).__name__} for f in system.forces],
        "quantities": [{"name": q.name, "type": q.kind, "symbols": list(q.symbol_names),
                        "definition": q.describe()} for q in system.quantities],
        "nominal_motions": [n.name for n in model.nominal],
        "cyclic_coordinates": list(_cyclic(system)),
    }


def _cyclic(system: Any) -> tuple[str, ...]:
    """The cyclic coordinates (in no equation, only their rates), where the equations of
    motion can be formed."""
    from .analysis.cyclic import cyclic_coordinates

    try:
        return cyclic_coordinates(system)
    except JourdainError:
        return ()


def _step_exprs(step: Any) -> set[Any]:
    exprs = [step.angle] if hasattr(step, "angle") else list(step.vector)
    out: set[Any] = set()
    for e in exprs:
        out |= e.free_symbols
    return out


def _check_initial_state(model: Any) -> None:
    """The equations of motion at the model's initial state (its [simulation] y0, yd0 and
    inputs at t = 0, else zeros) must be finite numbers: a NaN there (a spring of zero length,
    a square root of a negative number) is a model error naming its source. M must be positive
    definite there: a coordinate that moves no mass or inertia (every body it moves is massless)
    or a singular configuration leaves ÿ undetermined, and nothing can be simulated."""
    system, sim = model.system, model.simulation
    y0 = list(sim.y0) or [0.0] * system.f
    yd0 = list(sim.yd0) or [0.0] * system.f
    given = dict(sim.inputs)
    values = {**system.parameter_values, "t": 0.0}
    try:
        u = [evaluate_float([given[n]], values)[0] if n in given else 0.0
             for n in system.input_names]
        out = system.evaluate(y0, yd0, 0.0, inputs=u or None)
    except JourdainError as exc:
        raise model.error(f"at the initial state: {exc}") from None
    problem = _mass_matrix_problem(system, np.asarray(out["M"], float), values)
    if problem:
        state = ", ".join(f"{c}={v:g}" for c, v in zip(system.coordinate_names, y0, strict=True))
        raise model.error(f"at the initial state ({state}): {problem}")


#: M counts as singular where its smallest eigenvalue is below this fraction of its largest
#: (the relative pivot limit of the integrator's Cholesky factorization)
SINGULAR_RTOL = 1e-13


def _mass_matrix_problem(system: Any, M: np.ndarray, values: dict[str, float]) -> str | None:
    """Why M is not positive definite (None when it is): the coordinates that move no mass or
    inertia and the massless bodies they move, else the eigenvalues of a singular
    configuration."""
    M = 0.5 * (M + M.T)
    w = np.linalg.eigvalsh(M) if M.size else np.ones(1)
    top = max(float(w.max()), 0.0)
    if w.min() > SINGULAR_RTOL * top:
        return None
    coords = system.coordinate_names
    idle = [c for i, c in enumerate(coords) if not M[i, i] > SINGULAR_RTOL * top]
    if idle:
        moved: dict[str, set[str]] = {}  # body -> the coordinates that move it
        for b in system.bodies:
            own = {str(c) for c in b.joint.coordinates}
            moved[b.name] = own | moved.get(b.parent, set())
        bodies = [b for b in system.bodies if moved[b.name] & set(idle)]
        massless = [b.name for b in bodies  # NaN (no value) counts as not massless
                    if not any(values_at([b.mass, *(e for row in b.inertia for e in row)],
                                         values))]
        named = ", ".join(f'body "{n}"' for n in massless)
        one = len(massless) == 1
        who = (f"; {'it moves' if len(idle) == 1 else 'they move'} only {named}, which "
               f"{'has' if one else 'have'} no mass and no inertia"
               if massless and len(massless) == len(bodies) else "")
        fix = ("it" if one else "one of them") if who else "a body they move"
        return (f"the mass matrix M is singular: no mass or inertia moves with "
                f"{', '.join(idle)}{who}; give {fix} a mass or an inertia")
    return (f"the mass matrix M is not positive definite (its eigenvalues range from "
            f"{w.min():.3g} to {top:.3g}): the coordinates are not independent at this state "
            "(a singular configuration of the joints); start from another state")


def cmd_check(args: argparse.Namespace) -> int:
    model = _load(args.model)
    if has_capability("reactions"):
        # the joints' constrained directions must satisfy the orthogonality J̄ᵀQ̄ = 0, joint by
        # joint and assembled (the numeric reactions' own checks, without the symbolic N̂)
        try:
            check_reactions(model.system)
        except JourdainError as exc:
            raise model.error(str(exc)) from None
    _check_initial_state(model)
    s = summary(model)
    loops = getattr(model, "loops", None)
    if loops is not None:  # closing joints (jourdain.loops): the loops and their mobility
        from .loops.report import check_lines, loop_summary

        s["loops"] = loop_summary(model)
    if args.json:
        print(json.dumps(s, indent=2))
        return EXIT_OK
    print(f"{args.model}: OK — {s['name']}")
    print(f"  degrees of freedom f = {s['degrees_of_freedom']}: {', '.join(s['coordinates'])}")
    print(f"  bodies p = {len(s['bodies'])}, Newton–Euler equations 6p = {6 * len(s['bodies'])}")
    print(f"  joints ({len(s['joints'])}), constrained directions q = {s['constraints']}:")
    for j in s["joints"]:
        coords = ", ".join(j["coordinates"]) or "—"
        dirs = ", ".join(j["constrained_directions"])
        print(f"    {j['name']:<14} {j['type']:<12} {j['parent']} → {j['body']}   "
              f"coordinates: {coords}; constrained: {j['constrained']}"
              + (f" ({dirs})" if dirs else ""))
    if s["forces"]:
        print("  force elements: " + ", ".join(f"{f['name']} ({f['type']})" for f in s["forces"]))
    if s["quantities"]:
        print("  kinematic quantities: " + "; ".join(
            f"{q['definition']} ({', '.join(q['symbols'])})" for q in s["quantities"]))
    if s["inputs"]:
        print("  inputs: " + ", ".join(s["inputs"]))
    print(f"  parameters ({len(s['parameters'])}): "
          + ", ".join(f"{k} = {v:g}" for k, v in s["parameters"].items()))
    if s["nominal_motions"]:
        print("  nominal motions: " + ", ".join(s["nominal_motions"]))
    if s["cyclic_coordinates"] and loops is None:  # the tree's, not the loop system's
        print(f"  cyclic coordinates: {', '.join(s['cyclic_coordinates'])} (in no equation, only "
              "their rates; stability verdicts are taken in Routh's sense without them)")
    if loops is not None:
        for line in check_lines(s["loops"]):
            print(line)
    return EXIT_OK


def _eom_matrices(system: Any) -> dict[str, Any]:
    eom = system.equations_of_motion()
    ne = eom.newton_euler
    return {"M_bar": ne.M_bar, "J_bar": ne.J_bar, "q_c": ne.q_c, "q_e": ne.q_e,
            "M": eom.M, "k": eom.k, "q": eom.q}


_TITLES = {
    "M_bar": "M̄ (global mass matrix, 6p×6p)", "J_bar": "J̄ (global Jacobian, 6p×f)",
    "q_c": "q̄^c (Coriolis, centrifugal and gyroscopic forces, 6p)",
    "q_e": "q̄^e (applied forces and torques, 6p)", "M": "M (mass matrix, f×f)",
    "k": "k (generalized gyroscopic forces, f)", "q": "q (generalized applied forces, f)",
}


def cmd_eom(args: argparse.Namespace) -> int:
    from .io import export

    model = _load(args.model)
    system = model.system
    mats = _eom_matrices(system)
    if args.format == "json":
        data = {"format": "jourdain-eom/1", "model": system.name,
                "coordinates": system.coordinate_names,
                "rates": [f"{c}_d" for c in system.coordinate_names],
                "parameters": system.parameter_values, "inputs": system.input_names}
        data.update(export.matrices_json(mats, system))
        print(json.dumps(data, indent=1))
        return EXIT_OK
    if args.format == "latex":
        names = {"M_bar": r"\bar{M}", "J_bar": r"\bar{J}", "q_c": r"\bar{q}^{c}",
                 "q_e": r"\bar{q}^{e}", "M": "M", "k": "k", "q": "q"}
        print(export.latex_fragment(
            mats, names, system, f"{system.name}: Newton-Euler equations and equations of motion",
            args.max_ops), end="")
        return EXIT_OK
    print(f"{system.name}: M̄·J̄·ÿ + q̄^c = q̄^e + Q̄·g  →  M·ÿ + k = q")
    for k, m in mats.items():
        print(f"\n{_TITLES[k]} =")
        print(export.matrix_text(m, system, args.max_ops))
    return EXIT_OK


def evaluate_all(model: Any, y: np.ndarray, yd: np.ndarray, t: float,
                 parameters: dict[str, float], inputs: dict[str, float]
                 ) -> tuple[dict[str, np.ndarray], dict[str, Any], dict[str, str]]:
    """Every matrix and vector of the method at one state.

    Returns the arrays by the seed's names, extra information (``g_names``,
    ``g_undetermined``) and, for what is missing, the reason.
    """
    from .numeric import evaluate

    system = model.system
    missing: dict[str, str] = {}
    reaction_names = ("Q_bar", "N_hat", "k_hat", "q_hat", "g")
    try:
        out = dict(system.evaluate(y, yd, t=t, parameters=parameters or None,
                                   inputs=inputs or None))
    except JourdainError as exc:
        # the equations of motion alone, when a later stage (the reactions) cannot be formed
        out = dict(evaluate(system, y, yd, t=t, parameters=parameters or None,
                            inputs=inputs or None))
        missing.update({k: f"the reaction forces could not be formed: {exc}"
                        for k in reaction_names})
    values = {k: np.asarray(v, float) for k, v in out.items() if isinstance(v, np.ndarray)}
    extra = {k: v for k, v in out.items() if not isinstance(v, np.ndarray)}
    error = extra.pop("reactions_error", None)
    if error:
        missing.update({k: f"the reaction forces could not be formed: {error}"
                        for k in reaction_names})
    for k in reaction_names:
        if k not in values and k not in missing:
            missing[k] = "the reaction forces are not available yet in this version of jourdain"
    lin_names = ("M_tilde", "P", "Q", "h", "D", "G", "K", "N")
    try:
        values.update(_linearization_at(model, y, yd, t, parameters, inputs))
    except NotAvailable as exc:
        missing.update({k: str(exc) for k in lin_names})
    except JourdainError as exc:
        missing.update({k: f"the linearization could not be formed: {exc}" for k in lin_names})
    return values, extra, missing


def _reactions_at(system: Any, y: Any, yd: Any, t: float, parameters: dict[str, float],
                  inputs: dict[str, float]) -> dict[str, Any]:
    _capability(system, "reactions", "the reaction forces (jourdain reactions)")
    from .io import capabilities as integration

    return integration.reactions_at(system, y, yd, t, parameters, inputs)


def _linearization_at(model: Any, y: Any, yd: Any, t: float, parameters: dict[str, float],
                      inputs: dict[str, float]) -> dict[str, np.ndarray]:
    _capability(model.system, "linearize", "the linearization (jourdain linearize)")
    from .io import capabilities as integration

    return integration.linearization_at(model, y, yd, t, parameters, inputs)


def _json_array(v: np.ndarray) -> Any:
    """Nested lists with NaN (an undetermined reaction) as null."""
    a = np.asarray(v, float)
    if a.ndim == 0:
        return float(a) if np.isfinite(a) else None
    return [_json_array(x) for x in a]


def cmd_eval(args: argparse.Namespace) -> int:
    from .units import value_units

    model = _load(args.model)
    _tree_only(model, "eval")
    system = model.system
    params = _overrides(system, args.set)
    y, yd, t, inputs = _state(model, args.at)
    values, extra, missing = evaluate_all(model, y, yd, t, params, inputs)
    pv = system.parameter_values
    pv.update(params)
    if args.json:
        out = {
            "format": EVAL_FORMAT, "model": system.name, "file": model.path,
            "coordinates": system.coordinate_names, "t": t, "y": y.tolist(), "yd": yd.tolist(),
            "parameters": pv, "inputs": inputs,
            "values": {k: _json_array(v) for k, v in values.items()},
            "g_names": list(extra.get("g_names", [])),
            "g_undetermined": list(extra.get("g_undetermined", [])),
            "not_available": missing,
            "joint_wrenches": {k: w.as_dict() for k, w in extra.get("joint_wrenches", {}).items()},
            "units": value_units(system, extra.get("g_names", [])),
        }
        print(json.dumps(out, indent=1))
        return EXIT_OK
    from .io.export import ROUNDOFF_RTOL, format_array

    print(f"{system.name} at {_state_text(system, y, yd, t, inputs)}")
    if params:
        print("  parameters set: " + ", ".join(f"{k}={v:g}" for k, v in params.items()))
    print(f"  (round-off, below {ROUNDOFF_RTOL:g} of the largest entry of a matrix or vector, "
          "is shown as 0; --json gives the numbers as computed)")
    scales = _display_scales(values)
    for k, v in values.items():
        print(f"\n{k} =\n{format_array(v, scales.get(k))}")
    if extra.get("g_names"):
        print("\ng components: " + ", ".join(extra["g_names"]))
    if extra.get("joint_wrenches"):
        print(_wrench_text(system, extra["joint_wrenches"]))
    if missing:
        print("\nnot available yet: " + ", ".join(missing))
    return EXIT_OK


def _wrench_text(system: Any, wrenches: dict[str, Any]) -> str:
    """The joint wrenches as a table: force and torque (about the joint point) on the child
    body, in the joint frame and in the inertial frame."""
    from .io.export import chop

    force, torque = reaction_units(system)
    lines = [f"\njoint wrenches on the child body at the joint point (force [{force}], torque "
             f"[{torque}]; joint frame = child body frame):"]
    for name, w in wrenches.items():
        for label, F, T in (("joint frame", w.force, w.torque),
                            ("inertial", w.force_inertial, w.torque_inertial)):
            top = max(float(np.nanmax(np.abs(F), initial=0.0)),
                      float(np.nanmax(np.abs(T), initial=0.0)))
            F, T = chop(F, top), chop(T, top)
            lines.append(f"  {name + ' (' + w.child + ')':<24} {label:<12} F = "
                         + np.array2string(F, precision=6) + "  T = "
                         + np.array2string(T, precision=6))
    return "\n".join(lines)


def cmd_reactions(args: argparse.Namespace) -> int:
    model = _load(args.model)
    _tree_only(model, "reactions")
    system = model.system
    params = _overrides(system, args.set)
    y, yd, t, inputs = _state(model, args.at)
    values = _reactions_at(system, y, yd, t, params, inputs)
    from .io import capabilities as integration
    from .units import value_units

    labels = list(values.get("g_names") or integration.reaction_labels(system))
    g = np.asarray(values["g"], float).reshape(-1)
    if args.json:
        print(json.dumps({"t": t, "y": y.tolist(), "yd": yd.tolist(), "g_names": labels,
                          "g": _json_array(g), "units": value_units(system, labels),
                          "g_undetermined": list(values.get("g_undetermined", []))}, indent=1))
        return EXIT_OK
    from .io.export import ROUNDOFF_RTOL, chop

    print(f"{system.name}: reaction forces g from N̂·g = k̂ − q̂ at "
          f"{_state_text(system, y, yd, t, inputs)}")
    if params:
        print("  parameters set: " + ", ".join(f"{k}={v:g}" for k, v in params.items()))
    print("  (components in the child body frame at the joint point; round-off, below "
          f"{ROUNDOFF_RTOL:g} of the largest |g|, is shown as 0)")
    force, torque = reaction_units(system)
    shown = chop(g)
    for lab, v in zip(labels, shown, strict=False):
        unit = torque if lab.rsplit(".", 1)[-1].startswith("T") else force
        print(f"  {lab:<24} {v: .6g} {unit}" if np.isfinite(v)
              else f"  {lab:<24} undetermined")
    return EXIT_OK


#: units of length and mass recognized in a model's units, for the units of forces and torques
_LENGTHS = ("m", "mm", "cm", "km", "in", "ft")
_MASSES = ("kg", "g", "t", "lb")


def reaction_units(system: Any) -> tuple[str, str]:
    """Units of the reaction forces and torques: N and N·m, or mass·length/s² and
    mass·length²/s² where the model declares other units of length or mass (jourdain does not
    convert units, so the numbers are in the model's own)."""
    declared = [u.strip() for u in dict(system.units).values()]
    length = next((u for u in declared if u in _LENGTHS), "m")
    mass = next((u for u in declared if u in _MASSES), "kg")
    if (mass, length) == ("kg", "m"):
        return "N", "N·m"
    return f"{mass}·{length}/s²", f"{mass}·{length}²/s²"


def _state_text(system: Any, y: np.ndarray, yd: np.ndarray, t: float,
                inputs: dict[str, float]) -> str:
    """The state of a numeric evaluation, for the header of the text output."""
    parts = [f"t={t:g}"]
    parts += [f"{c}={v:g}" for c, v in zip(system.coordinate_names, y, strict=True)]
    parts += [f"{c}_d={v:g}" for c, v in zip(system.coordinate_names, yd, strict=True)]
    parts += [f"{n}={v:g}" for n, v in inputs.items()]
    return ", ".join(parts)


def _display_scales(values: dict[str, np.ndarray]) -> dict[str, Any]:
    """What the round-off of each quantity is judged against: the symmetric and skew parts
    against P and Q, the generalized forces k, q, h against the forces at work
    (:func:`jourdain.stages.linearization.force_scale`, which stays large where q itself cancels to
    round-off, as for a pendulum standing upright); the others against themselves."""
    from .stages.linearization import force_scale

    out: dict[str, Any] = {"D": values.get("P"), "G": values.get("P"), "K": values.get("Q"),
                           "N": values.get("Q")}
    if all(k in values for k in ("J_bar", "q_c", "q_e", "k", "q")):
        forces = force_scale(values["J_bar"], values["q_c"], values["q_e"], values["k"],
                             values["q"])
        out.update({k: forces for k in ("k", "q", "h")})
    return out


def _period(system: Any, text: str | None) -> Any:
    """``--periodic T``: the period of the nominal motion, a number or an expression in the
    parameters (``"2*pi/w"``); None when not given."""
    if text is None:
        return None
    from .io import ExpressionError, parse_expression

    try:
        e = parse_expression(text, names=set(system.parameter_values))
    except ExpressionError as exc:
        raise UsageError(f'--periodic: "{text}": {exc} (the period may use the parameters)'
                         ) from None
    if not e.free_symbols and not float(e) > 0:
        raise UsageError(f'--periodic: the period must be positive, got "{text}"')
    return e


def cmd_linearize(args: argparse.Namespace) -> int:
    model = _load(args.model)
    _tree_only(model, "linearize")
    system = model.system
    _capability(system, "linearize", "the linearization")
    from .io import capabilities as integration

    if args.about is not None and args.about not in [n.name for n in model.nominal]:
        names = [n.name for n in model.nominal]
        raise UsageError(f'--about: no nominal motion "{args.about}" in {model.path}'
                         f"{_suggest(args.about, names)}; the model has: "
                         f"{', '.join(names) or '(none: add a [nominal.<name>] table)'}")
    params = _overrides(system, args.set)
    result = integration.linear_analysis(model, args.about, params,
                                         period=_period(system, args.periodic))
    if args.json:
        print(json.dumps(integration.jsonable(result), indent=1))
        return EXIT_OK
    print(integration.linear_text(result))
    return EXIT_OK


# --- simulation options, outputs and progress ---------------------------------------------

def _sim_options(model: Any, args: argparse.Namespace) -> dict[str, Any]:
    """The simulation options given on the command line (those of ``args`` that the command
    has), checked against the bounds of :mod:`jourdain.simulation.simulate` before any work: a value out
    of range is a usage error naming the option."""
    from .errors import EvaluationError
    from .simulation.simulate import check_atol, check_rtol, check_samples, check_t_end

    system = model.system
    opts: dict[str, Any] = {}
    checks: dict[str, Callable[[float, str], Any]] = {
        "t_end": check_t_end, "rtol": check_rtol,
        "atol": lambda v, name: check_atol(v, 1, name)[0],
        "samples": lambda v, name: check_samples(v, system.f, len(system.inputs), name)}
    for key, check in checks.items():
        text = getattr(args, key, None)
        if text is None:
            continue
        option = "--" + key.replace("_", "-")
        try:
            opts[key] = check(_number(text, option), option)
        except EvaluationError as exc:
            raise UsageError(str(exc)) from None
    if getattr(args, "method", None):
        opts["method"] = args.method
    for key, rates in (("y0", False), ("yd0", True)):
        if getattr(args, key, None):
            opts[key] = _coordinate_values(system, args.__dict__[key], f"--{key}", rates)
    if getattr(args, "input", None):
        opts["inputs"] = _input_laws(system, args.input)
    return opts


def _coordinate_values(system: Any, texts: Sequence[str], option: str,
                       rates: bool) -> dict[str, float]:
    """``--y0 "phi1=0.3, phi2=0"`` (``--yd0`` also takes ``phi1_d=...``): numbers by
    coordinate name (numbers and constant expressions such as ``pi/4``)."""
    coords = system.coordinate_names
    out: dict[str, float] = {}
    for text in texts:
        for name, value in _split_assignments(text, option):
            key = name[:-2] if rates and name.endswith("_d") and name[:-2] in coords else name
            if key not in coords:
                raise UsageError(f'{option}: "{name}" is not a coordinate{_suggest(name, coords)};'
                                 f" coordinates are {', '.join(coords)}")
            out[key] = _number(value, f"{option} {name}")
    return out


def _input_laws(system: Any, texts: Sequence[str]) -> dict[str, Any]:
    """``--input "F=2.0, tau=0.5*sin(3*t)"``: a law per input, a number or an expression in t
    and the parameters (jourdain's expression language, never evaluated as Python)."""
    from .io import ExpressionError, parse_expression

    names = system.input_names
    allowed = set(system.parameter_values) | {"t"}
    out: dict[str, Any] = {}
    for text in texts:
        for name, value in _split_assignments(text, "--input"):
            if name not in names:
                raise UsageError(f'--input: "{name}" is not an input of the model'
                                 f"{_suggest(name, names)}; inputs are "
                                 f"{', '.join(names) or '(none)'}")
            try:
                law = parse_expression(value, names=allowed)
            except ExpressionError as exc:
                raise UsageError(f'--input {name}: "{value}": {exc} (input laws may use t and '
                                 "the parameters)") from None
            out[name] = float(law) if not law.free_symbols else law
    return out


def _writable_folder(folder: Path, option: str, text: str) -> None:
    """Create ``folder`` (and its parents) and check that a file can be written in it."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            pass
    except (FileExistsError, NotADirectoryError):
        raise UsageError(f"{option} {text}: a part of the path {folder} is a file, not a "
                         "folder") from None
    except OSError as exc:
        raise UsageError(f"{option} {text}: cannot write in the folder {folder}: "
                         f"{exc.strerror or exc}") from None


def _output_file(text: str, force: bool, suffixes: Sequence[str],
                 option: str = "--out") -> Path:
    """The results file of ``--out``, checked before any work: a known type, a folder that
    can be written, not an existing file unless ``--force``."""
    path = Path(text)
    if path.is_dir():
        raise UsageError(f"{option} {text}: is a folder; expected a file name ending in "
                         f"{', '.join(suffixes)}")
    if path.suffix.lower() not in suffixes:
        kind = repr(path.suffix) if path.suffix else "(no extension)"
        raise UsageError(f"{option} {text}: unknown file type {kind}; use "
                         f"{', '.join(suffixes)}")
    if path.exists() and not force:
        raise UsageError(f"{option} {text}: the file exists; --force overwrites it")
    _writable_folder(path.parent, option, text)
    return path


def _output_folder(text: str, force: bool, model: Any) -> Path:
    """The report folder of ``run --out``, checked before any work: a folder (created if
    missing) that can be written, not the model file's own, holding none of the files the
    report writes unless ``--force``."""
    from .io.report import model_copy, report_files

    out = Path(text)
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {text}: is a file; expected a folder for the report")
    src = Path(model.path)
    if out.is_dir() and src.is_file() and out.resolve() == src.resolve().parent:
        raise UsageError(f"--out {text}: is the folder of the model file {model.path}; the "
                         f"report writes {model_copy(model)}, report.html and its "
                         "data files into a "
                         "folder of their own (e.g. --out report/)")
    if out.is_dir() and not force:
        clash = [n for n in report_files(model) if (out / n).exists()]
        if clash:
            shown = ", ".join(clash[:6]) + (", …" if len(clash) > 6 else "")
            raise UsageError(f"--out {text}: would overwrite {shown}; --force overwrites them")
    _writable_folder(out, "--out", text)
    return out


class _Progress:
    """Prints t and the fraction done to stderr every :data:`PROGRESS_SECONDS` of a long
    simulation (on a terminal one line rewritten in place, else a line each time)."""

    def __init__(self, stream: Any, tty: bool, label: str) -> None:
        self.stream, self.tty, self.label = stream, tty, printable(label)
        self.last = time.monotonic()
        self.width = 0

    def __call__(self, t: float, t1: float) -> None:
        now = time.monotonic()
        if now - self.last < PROGRESS_SECONDS:
            return
        self.last = now
        line = f"{self.label}: t = {t:.6g} of {t1:.6g} ({100 * t / t1:.0f} %)"
        if self.tty:
            self.stream.write("\r" + line.ljust(self.width))
            self.width = len(line)
        else:
            self.stream.write(line + "\n")
        self.stream.flush()

    def done(self) -> None:
        if self.tty and self.width:
            self.stream.write("\n")
            self.stream.flush()
            self.width = 0


def _progress(asked: bool, label: str) -> _Progress | None:
    """A progress printer when asked (``--progress``) or when stderr is a terminal."""
    stream = sys.stderr
    tty = bool(getattr(stream, "isatty", lambda: False)())
    if not (asked or tty):
        return None
    return _Progress(getattr(stream, "raw", stream), tty, label)


def _samples(n: int) -> str:
    return f"{n} sample" + ("" if n == 1 else "s")


def cmd_simulate(args: argparse.Namespace) -> int:
    from .simulation.simulate import OUTPUT_SUFFIXES

    model = _load(args.model)
    _tree_only(model, "simulate")
    system = model.system
    _capability(system, "simulate", "simulation")
    from .io import capabilities as integration

    # every option and the output file are checked before the work
    params = _overrides(system, args.set)
    opts = _sim_options(model, args)
    out = _output_file(args.out, args.force, OUTPUT_SUFFIXES) if args.out else None
    progress = _progress(args.progress, f"simulating {system.name}")
    failure: JourdainError | None = None
    try:
        # with --out the results are written as the run goes, and complete at its end
        res = integration.simulate(model, params, **opts, progress=progress or False,
                                   output=out)
    except JourdainError as exc:
        if getattr(exc, "results", None) is None:
            raise
        if len(exc.results.t) == 0:  # failed before the first sample
            raise JourdainError(f"{exc}; nothing was computed"
                                + (f" ({out} holds the header only)" if out else "")) from None
        res, failure = exc.results, exc
    finally:
        if progress:
            progress.done()
    names = system.coordinate_names
    span = f"t = {res.t[0]:g} … {res.t[-1]:g}"
    if out:
        print(f"wrote {out} ({_samples(len(res.t))}, {span}"
              + ("" if res.status == "finished" else f"; {res.status}") + ")")
    else:
        print(f"{system.name}: simulated {span} ({_samples(len(res.t))})")
    where = ("final {}: " if res.status == "finished" else f"{{}} at t = {res.t[-1]:g}: ").format
    print(where("state") + ", ".join(f"{n}={v:.6g}" for n, v in
                                     zip(names, res.y[-1], strict=True)))
    print(where("rates") + ", ".join(f"{n}_d={v:.6g}" for n, v in
                                     zip(names, res.yd[-1], strict=True)))
    kept = (f"the motion up to t = {res.t[-1]:g} ({_samples(len(res.t))}) is in {out}" if out
            else "give --out FILE to keep the motion up to there")
    if failure is not None:
        raise JourdainError(f"{failure}; {kept}")
    if res.interrupted:
        print(f"jourdain simulate: interrupted (Ctrl-C) at t = {res.t[-1]:g}; {kept}",
              file=sys.stderr)
        return EXIT_INTERRUPTED
    return EXIT_OK


def cmd_run(args: argparse.Namespace) -> int:
    from .io.report import write_report

    model = _load(args.model)
    params = _overrides(model.system, args.set)
    opts = _sim_options(model, args)
    out = _output_folder(args.out, args.force, model)
    if getattr(model, "loops", None) is not None:  # a loop model: jourdain.loops' report
        from .loops.report import run_report

        for line in run_report(model, out, params, opts.get("t_end")):
            print(line)
        print(f"report: {out / 'index.html'}")
        return EXIT_OK
    progress = _progress(args.progress, f"simulating {model.system.name}")
    try:
        info = write_report(model, out, parameters=params, t_end=opts.get("t_end"),
                            max_ops=args.max_ops, progress=progress or False)
    finally:
        if progress:
            progress.done()
    for line in info.summary_lines:
        print(line)
    print(f"report: {info.html}")
    if info.status == "interrupted":
        print(f"jourdain run: {info.message}; the report holds what was computed",
              file=sys.stderr)
        return EXIT_INTERRUPTED
    if info.status == "failed":
        print(f"jourdain run: error: {info.message}", file=sys.stderr)
        return EXIT_MODEL
    return EXIT_OK


def cmd_fmu(args: argparse.Namespace) -> int:
    """``jourdain fmu MODEL --out model.fmu``: an FMI 2.0 FMU (docs/fmu.md)."""
    from .io.fmu import export_fmu

    out = Path(args.out)
    if out.suffix.lower() != ".fmu":
        raise UsageError(f"--out: expected a file name ending in .fmu, got {args.out!r}")
    if out.is_dir():
        raise UsageError(f"--out: {args.out} is a folder; expected a .fmu file")
    if out.exists() and not args.force:
        raise UsageError(f"--out: {args.out} exists; --force replaces it")
    model = _load(args.model)
    params = _overrides(model.system, args.set)
    names = [n.strip() for r in args.reaction for n in r.split(",") if n.strip()]
    info = export_fmu(model, out, reactions="all" if names == ["all"] else names,
                      parameters=params, model_identifier=args.identifier,
                      binary=not args.sources_only)
    f = model.system.f
    print(f"{info.path}: FMI 2.0 model exchange and co-simulation, modelIdentifier "
          f"{info.model_identifier}; {2 * f} states, {len(model.system.parameters)} parameters, "
          f"{len(model.system.inputs)} inputs, {len(info.reactions)} reaction outputs; "
          + (f"binary {info.binary}" if info.binary else "sources only"))
    return EXIT_OK


# ------------------------------------------------------------------------------------------
# parser
# ------------------------------------------------------------------------------------------

class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # type: ignore[override]
        self.print_usage(sys.stderr)
        self.exit(EXIT_USAGE, f"{self.prog}: usage error: {message}\n")


def _sub(subs: Any, name: str, help: str, example: str, func: Callable[..., int]) -> Any:
    p = subs.add_parser(name, help=help, description=help,
                        epilog=f"example:\n  {example}",
                        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("model", metavar="MODEL", help="model file (TOML, see docs/model-format.md)")
    p.set_defaults(func=func)
    return p


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="jourdain",
        description="Multibody dynamics by the Newton–Euler projection method (Schiehlen): "
                    "equations of motion, reactions, linearization, simulation and reports "
                    "from a TOML model file.",
        epilog="example:\n  jourdain run examples/double_pendulum.toml --out report/",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    from . import __version__

    parser.add_argument("--version", action="version", version=f"jourdain {__version__}")
    subs = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    p = _sub(subs, "check", "validate a model file and summarize it (bodies, joints, degrees of "
             "freedom, constraints)", "jourdain check examples/double_pendulum.toml", cmd_check)
    p.add_argument("--json", action="store_true", help="print the summary as JSON")

    p = _sub(subs, "eom", "print M̄, J̄, q̄^c, q̄^e and M, k, q",
             "jourdain eom examples/double_pendulum.toml --format latex", cmd_eom)
    p.add_argument("--format", choices=("text", "latex", "json"), default="text",
                   help="text (default), latex, or json (expressions with shared temporaries)")
    p.add_argument("--max-ops", type=_operations, default=600, metavar="N",
                   help="summarize matrices needing more than N operations (text, latex)")

    state_help = ('state as "name=value, ..." with coordinates, rates <name>_d, inputs and t '
                  "(unset values: the model's [simulation] y0/yd0, else 0)")
    set_help = "override a parameter: --set m1=2.0 (repeatable, or comma-separated)"

    p = _sub(subs, "eval", "numeric values of every matrix and vector of the method at one "
             "state (a stable JSON contract with --json)",
             'jourdain eval examples/double_pendulum.toml --at "phi1=0.3, phi1_d=1.0, t=0" '
             "--json", cmd_eval)
    p.add_argument("--at", metavar="STATE", help=state_help)
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help=set_help)
    p.add_argument("--json", action="store_true", help=f"print JSON ({EVAL_FORMAT})")

    p = _sub(subs, "reactions", "generalized reaction forces g at one state (N̂·g = k̂ − q̂)",
             'jourdain reactions examples/double_pendulum.toml --at "phi1=0.3"', cmd_reactions)
    p.add_argument("--at", metavar="STATE", help=state_help)
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help=set_help)
    p.add_argument("--json", action="store_true", help="print JSON")

    p = _sub(subs, "linearize", "linearize about a nominal motion: M̃, P, Q, h; D, G, K, N; "
             "eigenvalues and stability",
             "jourdain linearize examples/double_pendulum.toml --about hanging", cmd_linearize)
    p.add_argument("--about", metavar="NAME",
                   help="nominal motion of the model file ([nominal.NAME]; default: the first)")
    p.add_argument("--periodic", metavar="T",
                   help="Floquet analysis of a T-periodic nominal motion: monodromy matrix, "
                        "multipliers, exponents and verdict (T a number or an expression in "
                        'the parameters, "2*pi/w"; default: the period = ... of the nominal motion '
                        "in the model file, if it has one)")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help=set_help)
    p.add_argument("--json", action="store_true", help="print JSON")

    from .io.capabilities import SIM_METHODS
    from .simulation import simulate as sim

    default = "(default: the model's [simulation] {}, else {})".format
    t_end_help = (f"end time, at most {sim.MAX_TIME:g} {default('t_end', sim.DEFAULT_T_END)}")
    progress_help = (f"print t and the fraction done to stderr every {PROGRESS_SECONDS:g} s "
                     "(without it: only when stderr is a terminal)")
    p = _sub(subs, "simulate", "integrate the nonlinear equations of motion",
             "jourdain simulate examples/double_pendulum.toml --t-end 10 --out sim.csv\n  "
             'jourdain simulate examples/quarter_car.toml --method Radau --rtol 1e-9 '
             '--y0 "z_b=0.05" --input "z_r=0.02*sin(8*t)"', cmd_simulate)
    p.add_argument("--t-end", metavar="T", help=t_end_help)
    p.add_argument("--samples", metavar="N",
                   help=f"output samples, evenly spaced from t = 0 ({sim.MIN_SAMPLES} to "
                        f"{sim.MAX_SAMPLES:g}) {default('samples', sim.DEFAULT_SAMPLES)}")
    p.add_argument("--method", choices=SIM_METHODS,
                   help=f"integration method {default('method', sim.DEFAULT_METHOD)}")
    p.add_argument("--rtol", metavar="R",
                   help=f"relative tolerance, {sim.RTOL_MIN:g} <= R < 1 "
                        f"{default('rtol', f'{sim.DEFAULT_RTOL:g}')}")
    p.add_argument("--atol", metavar="A",
                   help=f"absolute tolerance, 0 < A <= {sim.ATOL_MAX:g} "
                        f"{default('atol', f'{sim.DEFAULT_ATOL:g}')}")
    p.add_argument("--y0", action="append", default=[], metavar="STATE",
                   help='initial coordinates: --y0 "phi1=0.3, phi2=0" (the others: the model\'s '
                        "[simulation] y0, else 0)")
    p.add_argument("--yd0", action="append", default=[], metavar="RATES",
                   help='initial rates: --yd0 "phi1=1.0" (or phi1_d=1.0; the others: the '
                        "model's [simulation] yd0, else 0)")
    p.add_argument("--input", action="append", default=[], metavar="NAME=LAW",
                   help='input law: --input "F=2.0" or "F=2*sin(3*t)", an expression in t and '
                        "the parameters (the others: the model's [simulation] inputs, else 0)")
    p.add_argument("--out", metavar="FILE",
                   help="write the results as the run goes (.csv, or .h5 for HDF5)")
    p.add_argument("--force", action="store_true", help="overwrite an existing --out file")
    p.add_argument("--progress", action="store_true", help=progress_help)
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help=set_help)

    p = _sub(subs, "run", "everything for a model, written as a self-contained HTML report "
             "plus data files", "jourdain run examples/double_pendulum.toml --out report/",
             cmd_run)
    p.add_argument("--out", required=True, metavar="DIR",
                   help="output folder (not the model file's own)")
    p.add_argument("--force", action="store_true",
                   help="overwrite the files of an earlier report in --out")
    p.add_argument("--t-end", metavar="T", help="simulation " + t_end_help)
    p.add_argument("--progress", action="store_true", help=progress_help)
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help=set_help)
    p.add_argument("--max-ops", type=_operations, default=600, metavar="N",
                   help="summarize matrices needing more than N operations")

    p = _sub(subs, "fmu", "export an FMI 2.0 FMU (model exchange and co-simulation, C sources "
             "and a binary for this machine; docs/fmu.md)",
             "jourdain fmu examples/double_pendulum.toml --out double_pendulum.fmu "
             "--reaction hinge1.F_x,hinge1.F_y", cmd_fmu)
    p.add_argument("--out", required=True, metavar="FILE", help="the .fmu file to write")
    p.add_argument("--force", action="store_true", help="replace an existing --out file")
    p.add_argument("--reaction", action="append", default=[], metavar="NAME",
                   help='reaction components as outputs: --reaction hinge1.F_x (repeatable, or '
                        'comma-separated; "all" for every one)')
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="a parameter's start value in the FMU: --set m1=2.0 (repeatable)")
    p.add_argument("--identifier", metavar="NAME",
                   help="FMI modelIdentifier, the binary's name (default: from the model's name)")
    p.add_argument("--sources-only", action="store_true",
                   help="no binary: the FMU holds the C sources only")

    from .study.cli import add_study_parser

    add_study_parser(subs, _Parser)
    return parser


def _operations(text: str) -> int:
    """``--max-ops``: a whole number of operations, 0 or more."""
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if n < 0:
        raise argparse.ArgumentTypeError(f"expected 0 or more operations, got {n}")
    return n


_CONTROL = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\u2028\u2029\u202a-\u202e\u2066-\u2069]")


def printable(text: str) -> str:
    """``text`` with control characters other than line breaks and tabs written as escapes
    (``\\x1b``): names and messages from a model file never reach the terminal as escape
    sequences or hidden text."""
    return _CONTROL.sub(lambda m: m.group().encode("unicode_escape").decode("ascii"), text)


class _Printable:
    """A text stream that writes through :func:`printable` (``raw``: the stream itself)."""

    def __init__(self, raw: Any) -> None:
        self.raw = raw

    def write(self, text: str) -> int:
        return self.raw.write(printable(text))

    def __getattr__(self, name: str) -> Any:
        return getattr(self.raw, name)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``jourdain`` console script; returns the exit status."""
    out, err = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = _Printable(out), _Printable(err)
    try:
        return _main(argv)
    finally:
        if isinstance(sys.stdout, _Printable):
            sys.stdout = out
        if isinstance(sys.stderr, _Printable):
            sys.stderr = err


def _main(argv: Sequence[str] | None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help(sys.stderr)
        return EXIT_USAGE
    try:
        return int(args.func(args))
    except UsageError as exc:
        print(f"jourdain {args.command}: usage error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except NotAvailable as exc:
        print(f"jourdain {args.command}: {exc}", file=sys.stderr)
        return EXIT_MODEL
    except JourdainError as exc:
        if isinstance(exc.__cause__, KeyboardInterrupt):  # a SciPy method's run, Ctrl-C
            print(f"jourdain {args.command}: interrupted (Ctrl-C): {exc}", file=sys.stderr)
            return EXIT_INTERRUPTED
        print(f"jourdain {args.command}: error: {exc}", file=sys.stderr)
        return EXIT_MODEL
    except KeyboardInterrupt:
        print(f"jourdain {args.command}: interrupted (Ctrl-C)", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # output piped into head & co.
        sys.stdout = open(os.devnull, "w")  # noqa: SIM115 - silence the flush at exit
        return EXIT_OK
    except OSError as exc:  # an output that failed after the checks (a full disk)
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"jourdain {args.command}: error: cannot write {where}{exc.strerror or exc}",
              file=sys.stderr)
        return EXIT_MODEL


if __name__ == "__main__":
    sys.exit(main())
