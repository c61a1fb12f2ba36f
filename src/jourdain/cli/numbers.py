"""``jourdain eval``, ``jourdain reactions`` and ``jourdain linearize``: the numbers of the
method at one state, the reaction forces there, and the linearization about a nominal
motion."""

from __future__ import annotations

import argparse
import json
from typing import Any

import numpy as np

from ..io import capabilities as integration
from ..io.export import ROUNDOFF_RTOL, chop, format_array
from ..stages.linearization import force_scale
from ..units import value_units
from ..workflow import (
    eval_document,
    evaluate_all,
    json_array,
    reactions_at,
    require,
)
from . import general
from .arguments import UsageError, load, overrides, period, state_at, suggest

EXIT_OK = 0


def cmd_eval(args: argparse.Namespace) -> int:
    model = load(args.model)
    system = model.system
    if system.is_general:  # velocity constraints: the numbers in the speeds z
        return general.cmd_eval(model, args)
    params = overrides(system, args.set)
    y, yd, t, inputs = state_at(model, args.at)
    values, extra, missing = evaluate_all(model, y, yd, t, params, inputs)
    pv = system.parameter_values
    pv.update(params)
    if args.json:
        out = eval_document(model, y, yd, t, pv, inputs, values, extra, missing)
        print(json.dumps(out, indent=1))
        return EXIT_OK
    if system.closing:  # the numbers are at the state assembled onto Φ = 0, Φ̇ = 0
        y, yd = values["y"], values["yd"]
    print(f"{system.name} at {state_text(system, y, yd, t, inputs)}")
    if system.closing:
        res = extra["closure_residual"]
        print(f"  closed by {', '.join(c.name for c in system.closing)}: M, k, q, J_bar in the "
              f"independent coordinates {', '.join(extra['independent'])} (ẏ = L·ẏ_i + l); "
              f"the state assembled onto the constraints, |Φ| = {res['Phi']:.3g}, "
              f"|Φ̇| = {res['Phi_dot']:.3g}; constraint rows (λ, Phi): "
              + ", ".join(extra["constraint_labels"]))
    if params:
        print("  parameters set: " + ", ".join(f"{k}={v:g}" for k, v in params.items()))
    print(f"  (round-off, below {ROUNDOFF_RTOL:g} of the largest entry of a matrix or vector, "
          "is shown as 0; --json gives the numbers as computed)")
    scales = display_scales(values)
    for k, v in values.items():
        print(f"\n{k} =\n{format_array(v, scales.get(k))}")
    if extra.get("g_names"):
        print("\ng components: " + ", ".join(extra["g_names"]))
    if extra.get("joint_wrenches"):
        print(wrench_text(system, extra["joint_wrenches"]))
    if extra.get("closing_wrenches"):
        force, torque = reaction_units(system)
        print(f"\nclosing joints' wrenches (force [{force}], torque [{torque}]; of body_b on "
              "body_a at its joint point, in body_a's frame):")
        for name, w in extra["closing_wrenches"].items():
            print(f"  {name:<24} F = " + np.array2string(np.asarray(w["F"]), precision=6)
                  + "  T = " + np.array2string(np.asarray(w["T"]), precision=6))
    if missing:
        print("\nnot available yet: " + ", ".join(missing))
    return EXIT_OK


def wrench_text(system: Any, wrenches: dict[str, Any]) -> str:
    """The joint wrenches as a table: force and torque (about the joint point) on the child
    body, in the joint frame and in the inertial frame."""

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
    model = load(args.model)
    system = model.system
    if system.is_general:  # the contact forces, by element
        return general.cmd_reactions(model, args)
    params = overrides(system, args.set)
    y, yd, t, inputs = state_at(model, args.at)
    values = reactions_at(system, y, yd, t, params, inputs)

    labels = list(values.get("g_names") or integration.reaction_labels(system))
    g = np.asarray(values["g"], float).reshape(-1)
    if args.json:
        print(json.dumps({"t": t, "y": y.tolist(), "yd": yd.tolist(), "g_names": labels,
                          "g": json_array(g), "units": value_units(system, labels),
                          "g_undetermined": list(values.get("g_undetermined", []))}, indent=1))
        return EXIT_OK

    print(f"{system.name}: reaction forces g from N̂·g = k̂ − q̂ at "
          f"{state_text(system, y, yd, t, inputs)}")
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


def state_text(system: Any, y: np.ndarray, yd: np.ndarray, t: float,
                inputs: dict[str, float]) -> str:
    """The state of a numeric evaluation, for the header of the text output."""
    parts = [f"t={t:g}"]
    parts += [f"{c}={v:g}" for c, v in zip(system.coordinate_names, y, strict=True)]
    parts += [f"{c}_d={v:g}" for c, v in zip(system.coordinate_names, yd, strict=True)]
    parts += [f"{n}={v:g}" for n, v in inputs.items()]
    return ", ".join(parts)


def display_scales(values: dict[str, np.ndarray]) -> dict[str, Any]:
    """What the round-off of each quantity is judged against: the symmetric and skew parts
    against P and Q, the generalized forces k, q, h against the forces at work
    (:func:`jourdain.stages.linearization.force_scale`, which stays large where q itself cancels to
    round-off, as for a pendulum standing upright); the others against themselves."""

    out: dict[str, Any] = {"D": values.get("P"), "G": values.get("P"), "K": values.get("Q"),
                           "N": values.get("Q")}
    if all(k in values for k in ("J_bar", "q_c", "q_e", "k", "q")):
        forces = force_scale(values["J_bar"], values["q_c"], values["q_e"], values["k"],
                             values["q"])
        out.update({k: forces for k in ("k", "q", "h")})
    return out




def cmd_linearize(args: argparse.Namespace) -> int:
    model = load(args.model)
    system = model.system
    if system.is_general:  # about the file's steady motion, by the complex step
        return general.cmd_linearize(model, args)
    require(system, "linearize", "the linearization")

    if args.about is not None and args.about not in [n.name for n in model.nominal]:
        names = [n.name for n in model.nominal]
        raise UsageError(f'--about: no nominal motion "{args.about}" in {model.path}'
                         f"{suggest(args.about, names)}; the model has: "
                         f"{', '.join(names) or '(none: add a [nominal.<name>] table)'}")
    params = overrides(system, args.set)
    result = integration.linear_analysis(model, args.about, params,
                                         period=period(system, args.periodic))
    if args.json:
        print(json.dumps(integration.jsonable(result), indent=1))
        return EXIT_OK
    print(integration.linear_text(result))
    return EXIT_OK

