"""Reading the command line's values: ``name=value`` lists, numbers, parameter overrides,
states, simulation options and input laws, each checked before any work (a mistake is a
:class:`UsageError` naming the option), and the model file itself."""

from __future__ import annotations

import argparse
import difflib
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from ..errors import EvaluationError, ModelError
from ..io import ExpressionError, load_model, parse_expression, parse_number
from ..io.urdf import load_urdf
from ..model.bodies import check_values
from ..model.expressions import magnitude_problem
from ..simulation.simulate import check_atol, check_rtol, check_samples, check_t_end


class UsageError(Exception):
    """A command-line argument is malformed or names something the model does not have."""


def split_assignments(text: str, option: str) -> list[tuple[str, str]]:
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


def number(text: str, where: str) -> float:
    """A number of the command line (``pi/4`` too), a :class:`UsageError` naming ``where``."""
    try:
        return parse_number(text)
    except ExpressionError as exc:
        raise UsageError(f'{where}: "{text}" is not a number: {exc}') from None


def overrides(system: Any, sets: Sequence[str]) -> dict[str, float]:
    """The parameter values of ``--set`` (repeatable, comma-separated), checked as the model
    file's own values are."""
    params = system.parameter_values
    out: dict[str, float] = {}
    for s in sets:
        for name, value in split_assignments(s, "--set"):
            if name not in params:
                raise UsageError(f'--set: "{name}" is not a parameter of the model; parameters '
                                 f"are {', '.join(params) or '(none)'}")
            out[name] = number(value, f"--set {name}")
            why = magnitude_problem(out[name])
            if why:
                raise ModelError(f'with --set {name}={value}: parameter "{name}": {why}')
    if out:
        # the model's numbers at these values pass the checks made at the file's defaults

        try:
            check_values(system.bodies, {**params, **out})
        except ModelError as exc:
            given = ", ".join(f"{k}={v:g}" for k, v in out.items())
            raise ModelError(f"with --set {given}: {exc}") from None
    return out


def state_at(model: Any, at: str | None) -> tuple[np.ndarray, np.ndarray, float, dict[str, float]]:
    """y, ẏ, t and inputs from ``--at``; unset values come from the model's [simulation]."""
    system = model.system
    y = np.array(model.simulation.y0 or [0.0] * system.f, dtype=float)
    yd = np.array(model.simulation.yd0 or [0.0] * system.f, dtype=float)
    t = 0.0
    inputs = {n: 0.0 for n in system.input_names}
    coords = system.coordinate_names
    for name, value in split_assignments(at or "", "--at"):
        v = number(value, f"--at {name}")
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


def load(path: str) -> Any:
    """The model file (TOML, or URDF for a robot) at ``path``."""
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
        return load_urdf(path)
    return load_model(path)


def suggest(name: str, names: Sequence[str]) -> str:
    close = difflib.get_close_matches(name, list(names), n=1)
    return f' (did you mean "{close[0]}"?)' if close else ""



def period(system: Any, text: str | None) -> Any:
    """``--periodic T``: the period of the nominal motion, a number or an expression in the
    parameters (``"2*pi/w"``); None when not given."""
    if text is None:
        return None

    try:
        e = parse_expression(text, names=set(system.parameter_values))
    except ExpressionError as exc:
        raise UsageError(f'--periodic: "{text}": {exc} (the period may use the parameters)'
                         ) from None
    if not e.free_symbols and not float(e) > 0:
        raise UsageError(f'--periodic: the period must be positive, got "{text}"')
    return e



def sim_options(model: Any, args: argparse.Namespace) -> dict[str, Any]:
    """The simulation options given on the command line (those of ``args`` that the command
    has), checked against the bounds of :mod:`jourdain.simulation.simulate` before any work: a value out
    of range is a usage error naming the option."""

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
            opts[key] = check(number(text, option), option)
        except EvaluationError as exc:
            raise UsageError(str(exc)) from None
    if getattr(args, "method", None):
        opts["method"] = args.method
    for key, rates in (("y0", False), ("yd0", True)):
        if getattr(args, key, None):
            opts[key] = coordinate_values(system, args.__dict__[key], f"--{key}", rates)
    if getattr(args, "input", None):
        opts["inputs"] = input_laws(system, args.input)
    return opts


def coordinate_values(system: Any, texts: Sequence[str], option: str,
                       rates: bool) -> dict[str, float]:
    """``--y0 "phi1=0.3, phi2=0"`` (``--yd0`` also takes ``phi1_d=...``): numbers by
    coordinate name (numbers and constant expressions such as ``pi/4``)."""
    coords = system.coordinate_names
    out: dict[str, float] = {}
    for text in texts:
        for name, value in split_assignments(text, option):
            key = name[:-2] if rates and name.endswith("_d") and name[:-2] in coords else name
            if key not in coords:
                raise UsageError(f'{option}: "{name}" is not a coordinate{suggest(name, coords)};'
                                 f" coordinates are {', '.join(coords)}")
            out[key] = number(value, f"{option} {name}")
    return out


def input_laws(system: Any, texts: Sequence[str]) -> dict[str, Any]:
    """``--input "F=2.0, tau=0.5*sin(3*t)"``: a law per input, a number or an expression in t
    and the parameters (jourdain's expression language, never evaluated as Python)."""

    names = system.input_names
    allowed = set(system.parameter_values) | {"t"}
    out: dict[str, Any] = {}
    for text in texts:
        for name, value in split_assignments(text, "--input"):
            if name not in names:
                raise UsageError(f'--input: "{name}" is not an input of the model'
                                 f"{suggest(name, names)}; inputs are "
                                 f"{', '.join(names) or '(none)'}")
            try:
                law = parse_expression(value, names=allowed)
            except ExpressionError as exc:
                raise UsageError(f'--input {name}: "{value}": {exc} (input laws may use t and '
                                 "the parameters)") from None
            out[name] = float(law) if not law.free_symbols else law
    return out

