"""Units of the quantities jourdain computes, for axis labels, tables and file headers.

jourdain computes in whatever consistent units the model is written in and never converts;
these functions only name the units. They come from

- the units the model declares (``units=`` of :class:`~jourdain.model.System`; ``unit`` of
  coordinates, parameters and inputs in a model file): a declared unit always wins;
- the joints, for coordinates: a coordinate that enters a rotation angle with a numeric factor
  (revolute, spherical, the angles of general joints) is an angle, ``rad``; one that enters a
  translation with a numeric factor (prismatic, planar, free) is a length, in the model's unit
  of length;
- rates and accelerations: the coordinate's unit per ``s`` and ``s^2``;
- the force elements, for inputs: an input that enters a force (torque) vector with a numeric
  factor is a force (torque); one in a generalized force is a force on a length coordinate
  and a torque on an angle;
- reaction components: ``<joint>.F_*`` are forces, ``<joint>.T_*`` torques; energies and work
  are energies.

The model's units of mass and length are the first of :data:`MASSES` and :data:`LENGTHS`
among the declared units (kg and m when none is declared); force, torque and energy are N,
N m and J for kg and m, and ``kg mm/s^2``, ``kg mm^2/s^2`` etc. otherwise.

Axis labels follow ISO 80000-1 (quantity / unit): ``phi1 / rad``, ``phi1_d / (rad/s)``,
``F_y / N``, ``M_z / (N m)``.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from functools import lru_cache
from typing import TYPE_CHECKING

import symengine as se

from .model.forces import Force, GeneralizedForce, Torque
from .model.joints import Rot

if TYPE_CHECKING:
    from .model.system import System

#: units of length and mass recognized among a model's declared units
LENGTHS = ("m", "mm", "cm", "km", "in", "ft")
MASSES = ("kg", "g", "t", "lb")
#: the unit of time (jourdain's t is in seconds)
TIME = "s"
ANGLE = "rad"


def base_units(units: Mapping[str, str]) -> tuple[str, str]:
    """``(mass, length)``: the first declared unit of each kind (in the order of ``units``),
    kg and m where none is declared."""
    declared = [str(u).strip() for u in units.values()]
    length = next((u for u in declared if u in LENGTHS), "m")
    mass = next((u for u in declared if u in MASSES), "kg")
    return mass, length


def force_unit(units: Mapping[str, str]) -> str:
    mass, length = base_units(units)
    return "N" if (mass, length) == ("kg", "m") else f"{mass} {length}/s^2"


def torque_unit(units: Mapping[str, str]) -> str:
    mass, length = base_units(units)
    return "N m" if (mass, length) == ("kg", "m") else f"{mass} {length}^2/s^2"


def energy_unit(units: Mapping[str, str]) -> str:
    mass, length = base_units(units)
    return "J" if (mass, length) == ("kg", "m") else f"{mass} {length}^2/s^2"


def per_time(unit: str, order: int) -> str:
    """The unit of the ``order``-th time derivative: ``rad`` → ``rad/s``, ``rad/s^2``; a
    compound unit is put in parentheses (``(N m)/s``); empty for an unknown unit."""
    if order == 0 or not unit:
        return unit
    base = f"({unit})" if _compound(unit) else unit
    return f"{base}/s" if order == 1 else f"{base}/s^{order}"


def _compound(unit: str) -> bool:
    return any(c in unit for c in " /·*")


def axis_label(name: str, unit: str) -> str:
    """``name / unit`` (ISO 80000-1), the unit in parentheses where it is a product or a
    quotient (``phi1_d / (rad/s)``); the name alone for an unknown or dimensionless unit."""
    if not unit or unit == "1":
        return name
    return f"{name} / ({unit})" if _compound(unit) else f"{name} / {unit}"


def _linear_in(exprs: Iterable[se.Basic], symbols: Iterable[se.Symbol]) -> dict[str, bool]:
    """For each symbol that occurs in ``exprs``: whether every occurrence is ``number·symbol``
    plus terms free of it (the derivative a number), so the symbol has the unit of the
    expression."""
    out: dict[str, bool] = {}
    syms = list(symbols)
    for e in exprs:
        e = se.sympify(e)
        free = e.free_symbols
        for s in syms:
            if s in free:
                d = se.diff(e, s)
                out[str(s)] = out.get(str(s), True) and not d.free_symbols
    return out


def coordinate_units(system: System) -> dict[str, str]:
    """The unit of each coordinate: declared, else from the joint steps it enters (``rad`` for
    an angle, the unit of length for a translation), else ``""`` (unknown: it enters with a
    parameter factor, or both as an angle and as a length)."""
    declared = dict(system.units)
    _, length = base_units(declared)
    kinds: dict[str, set[str]] = {}
    for body in system.bodies:
        for step in body.joint.steps:
            if isinstance(step, Rot):
                exprs, kind = [step.angle], ANGLE
            else:
                exprs, kind = list(step.vector), length
            for name, ok in _linear_in(exprs, system.y).items():
                kinds.setdefault(name, set()).add(kind if ok else "")
    return _decided(system.coordinate_names, declared, kinds)


def _decided(names: list[str], declared: Mapping[str, str],
             kinds: Mapping[str, set[str]]) -> dict[str, str]:
    """The unit of each name: declared, else the one kind found for it, else "" (none found,
    or several that disagree)."""
    out = {}
    for name in names:
        if name in declared:
            out[name] = declared[name]
        else:
            k = kinds.get(name, set())
            out[name] = next(iter(k)) if len(k) == 1 else ""
    return out


def input_units(system: System) -> dict[str, str]:
    """The unit of each input: declared, else from the force elements it enters with a numeric
    factor (a force vector: force; a torque vector: torque; a generalized force on a coordinate
    of unit L: force if L is the length, torque if rad), else ``""``."""
    declared = dict(system.units)
    coords = coordinate_units(system)
    kinds: dict[str, set[str]] = {}
    for fe in system.forces:
        if isinstance(fe, Force):
            exprs, kind = list(fe.vector), force_unit(declared)
        elif isinstance(fe, Torque):
            exprs, kind = list(fe.vector), torque_unit(declared)
        elif isinstance(fe, GeneralizedForce):
            kind = generalized_force_unit(coords.get(str(fe.coordinate), ""), declared)
            exprs = [fe.value]
        else:
            continue
        for name, ok in _linear_in(exprs, system.inputs).items():
            kinds.setdefault(name, set()).add(kind if ok else "")
    return _decided(system.input_names, declared, kinds)


def model_units(system: System) -> dict[str, str]:
    """The declared units with the derived units of coordinates and inputs added (``""``
    left out): what results store in their ``units``."""
    return dict(_model_units(system))


@lru_cache(maxsize=32)
def _model_units(system: System) -> tuple[tuple[str, str], ...]:
    # a System is immutable (and hashed by its content): every Results of a model asks
    out = dict(system.units)
    for name, u in {**coordinate_units(system), **input_units(system)}.items():
        if u and name not in out:
            out[name] = u
    return tuple(out.items())


def reaction_unit(name: str, units: Mapping[str, str]) -> str:
    """The unit of a reaction component ``<joint>.F_x`` (force) or ``<joint>.T_x`` (torque)."""
    comp = name.rsplit(".", 1)[-1]
    if comp.startswith("T"):
        return torque_unit(units)
    if comp.startswith("F"):
        return force_unit(units)
    return ""


def unit_of(name: str, units: Mapping[str, str], coordinates: Iterable[str] = ()) -> str:
    """The unit of a column of results: ``t``, a coordinate or its ``_d``/``_dd``, an input, the
    energies and work ``T, V, W, W_nc, W_drive``, a reaction component, or any declared name;
    ``""`` where unknown."""
    coords = set(coordinates)
    if name == "t":
        return TIME
    if name in coords:
        return units.get(name, "")
    for suffix, order in (("_dd", 2), ("_d", 1)):
        base = name[: -len(suffix)]
        if name.endswith(suffix) and (base in coords or (base in units and not coords)):
            return per_time(units.get(base, ""), order)
    if name in ("T", "V", "W", "W_nc", "W_drive", "E"):
        return energy_unit(units)
    if name in units:
        return units[name]
    return reaction_unit(name, units) if "." in name else ""


def generalized_force_unit(coordinate_unit: str, units: Mapping[str, str]) -> str:
    """The unit of a generalized force (a row of k, q, h) on a coordinate of the given unit:
    energy over the coordinate's unit (a force on a length, a torque on an angle); ``""``
    where the coordinate's unit is unknown."""
    _, length = base_units(units)
    if coordinate_unit == length:
        return force_unit(units)
    if coordinate_unit == ANGLE:
        return torque_unit(units)
    return ""


def shared_label(series: Iterable[tuple[str, str]], what: str, max_names: int = 3) -> str:
    """The label of an axis that holds several series ``(name, unit)``: the names (``what``
    where there are more than ``max_names``) over their unit, one group per unit in order of
    appearance (``q0 / m; q1, q2 / rad``); a name repeated counts once."""
    groups: dict[str, list[str]] = {}
    for name, unit in series:
        names = groups.setdefault(unit, [])
        if name not in names:
            names.append(name)
    parts = [axis_label(", ".join(names) if len(names) <= max_names else what, unit)
             for unit, names in groups.items()]
    return "; ".join(parts) if parts else what


def reactions_label(names: Iterable[str], units: Mapping[str, str]) -> str:
    """The label of an axis of reaction components: ``forces / N; torques / (N m)`` (the kinds
    present, in order)."""
    return shared_label([("torques" if n.rsplit(".", 1)[-1].startswith("T") else "forces",
                          reaction_unit(n, units)) for n in names], "reaction forces g")


def value_units(system: System, g_names: Iterable[str] = ()) -> dict[str, object]:
    """The units of the numbers at one state (``jourdain eval --json``, the report's
    values.json), aligned with their arrays: ``t``; ``y``, ``yd`` per coordinate; ``inputs``
    by name; ``k``, ``q`` (generalized forces: force on a length, torque on an angle) per
    coordinate; ``g`` per reaction component; ``""`` where unknown."""
    units = model_units(system)
    coords = coordinate_units(system)
    gen = [generalized_force_unit(coords[c], units) for c in system.coordinate_names]
    return {"t": TIME, "y": [coords[c] for c in system.coordinate_names],
            "yd": [per_time(coords[c], 1) for c in system.coordinate_names],
            "inputs": input_units(system), "k": gen, "q": list(gen),
            "g": [reaction_unit(n, units) for n in g_names]}
