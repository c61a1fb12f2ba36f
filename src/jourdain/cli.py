"""The ``jourdain`` command: model files in, equations, numbers and reports out.

A thin layer over the public API. Exit status: 0 on success, 1 on a model error (the message,
no traceback), 2 on a usage error. Every subcommand has ``--help`` with an example.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .errors import JourdainError

EXIT_OK, EXIT_MODEL, EXIT_USAGE = 0, 1, 2

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

    return load_model(path)


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
        "nominal_motions": [n.name for n in model.nominal],
    }


def _step_exprs(step: Any) -> set[Any]:
    exprs = [step.angle] if hasattr(step, "angle") else list(step.vector)
    out: set[Any] = set()
    for e in exprs:
        out |= e.free_symbols
    return out


def _check_initial_state(model: Any) -> None:
    """The equations of motion at the model's initial state (its [simulation] y0, yd0 and
    inputs at t = 0, else zeros) must be finite numbers: a NaN there (a spring of zero length,
    a square root of a negative number) is a model error naming its source."""
    from .differentiate import evaluate_float

    system, sim = model.system, model.simulation
    y0 = list(sim.y0) or [0.0] * system.f
    yd0 = list(sim.yd0) or [0.0] * system.f
    given = dict(sim.inputs)
    values = {**system.parameter_values, "t": 0.0}
    try:
        u = [evaluate_float([given[n]], values)[0] if n in given else 0.0
             for n in system.input_names]
        system.evaluate(y0, yd0, 0.0, inputs=u or None)
    except JourdainError as exc:
        raise model.error(f"at the initial state: {exc}") from None


def cmd_check(args: argparse.Namespace) -> int:
    model = _load(args.model)
    if has_capability("reactions"):
        # the joints' constrained directions must satisfy the orthogonality J̄ᵀQ̄ = 0
        try:
            model.system.reactions()
        except JourdainError as exc:
            raise model.error(str(exc)) from None
    _check_initial_state(model)
    s = summary(model)
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
    if s["inputs"]:
        print("  inputs: " + ", ".join(s["inputs"]))
    print(f"  parameters ({len(s['parameters'])}): "
          + ", ".join(f"{k} = {v:g}" for k, v in s["parameters"].items()))
    if s["nominal_motions"]:
        print("  nominal motions: " + ", ".join(s["nominal_motions"]))
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
    model = _load(args.model)
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
    if missing:
        print("\nnot available yet: " + ", ".join(missing))
    return EXIT_OK


def cmd_reactions(args: argparse.Namespace) -> int:
    model = _load(args.model)
    system = model.system
    params = _overrides(system, args.set)
    y, yd, t, inputs = _state(model, args.at)
    values = _reactions_at(system, y, yd, t, params, inputs)
    from .io import capabilities as integration

    labels = list(values.get("g_names") or integration.reaction_labels(system))
    g = np.asarray(values["g"], float).reshape(-1)
    if args.json:
        print(json.dumps({"t": t, "y": y.tolist(), "yd": yd.tolist(), "g_names": labels,
                          "g": _json_array(g),
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
    (:func:`jourdain.linearization.force_scale`, which stays large where q itself cancels to
    round-off, as for a pendulum standing upright); the others against themselves."""
    from .linearization import force_scale

    out: dict[str, Any] = {"D": values.get("P"), "G": values.get("P"), "K": values.get("Q"),
                           "N": values.get("Q")}
    if all(k in values for k in ("J_bar", "q_c", "q_e", "k", "q")):
        forces = force_scale(values["J_bar"], values["q_c"], values["q_e"], values["k"],
                             values["q"])
        out.update({k: forces for k in ("k", "q", "h")})
    return out


def cmd_linearize(args: argparse.Namespace) -> int:
    model = _load(args.model)
    system = model.system
    _capability(system, "linearize", "the linearization")
    from .io import capabilities as integration

    params = _overrides(system, args.set)
    result = integration.linear_analysis(model, args.about, params)
    if args.json:
        print(json.dumps(integration.jsonable(result), indent=1))
        return EXIT_OK
    print(integration.linear_text(result))
    return EXIT_OK


def cmd_simulate(args: argparse.Namespace) -> int:
    model = _load(args.model)
    system = model.system
    _capability(system, "simulate", "simulation")
    from .io import capabilities as integration

    params = _overrides(system, args.set)
    res = integration.simulate(model, params, t_end=args.t_end, samples=args.samples)
    names = system.coordinate_names
    if args.out:
        out = Path(args.out)
        out.parent.mkdir(parents=True, exist_ok=True)
        integration.write_csv(res, system, out)
        print(f"wrote {out} ({len(res.t)} samples, t = {res.t[0]:g} … {res.t[-1]:g})")
    else:
        print(f"{system.name}: simulated t = {res.t[0]:g} … {res.t[-1]:g} ({len(res.t)} samples)")
    print("final state: " + ", ".join(f"{n}={v:.6g}" for n, v in
                                        zip(names, res.y[-1], strict=True)))
    print("final rates: " + ", ".join(f"{n}_d={v:.6g}" for n, v in
                                        zip(names, res.yd[-1], strict=True)))
    return EXIT_OK


def cmd_run(args: argparse.Namespace) -> int:
    from .io.report import write_report

    model = _load(args.model)
    params = _overrides(model.system, args.set)
    info = write_report(model, Path(args.out), parameters=params, t_end=args.t_end,
                        max_ops=args.max_ops)
    for line in info.summary_lines:
        print(line)
    print(f"report: {info.html}")
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
    p.add_argument("--max-ops", type=int, default=600, metavar="N",
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
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help=set_help)
    p.add_argument("--json", action="store_true", help="print JSON")

    p = _sub(subs, "simulate", "integrate the nonlinear equations of motion",
             "jourdain simulate examples/double_pendulum.toml --t-end 10 --out sim.csv",
             cmd_simulate)
    p.add_argument("--t-end", type=float, metavar="T", help="end time (default: [simulation])")
    p.add_argument("--samples", type=int, metavar="N", help="output samples")
    p.add_argument("--out", metavar="FILE", help="write the results (.csv, or .h5 for HDF5)")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help=set_help)

    p = _sub(subs, "run", "everything for a model, written as a self-contained HTML report "
             "plus data files", "jourdain run examples/double_pendulum.toml --out report/",
             cmd_run)
    p.add_argument("--out", required=True, metavar="DIR", help="output folder")
    p.add_argument("--t-end", type=float, metavar="T", help="simulation end time")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help=set_help)
    p.add_argument("--max-ops", type=int, default=600, metavar="N",
                   help="summarize matrices needing more than N operations")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``jourdain`` console script; returns the exit status."""
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
        print(f"jourdain {args.command}: error: {exc}", file=sys.stderr)
        return EXIT_MODEL
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:  # output piped into head & co.
        sys.stdout = open(os.devnull, "w")  # noqa: SIM115 - silence the flush at exit
        return EXIT_OK


if __name__ == "__main__":
    sys.exit(main())
