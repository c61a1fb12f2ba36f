"""The derivatives of a tree of screw joints (:mod:`.derivatives`): the recursions of
``derivative_screw.h`` on the columns of the joints' elementary steps, O(Σ depth) dot products
of spatial vectors per state, where the forward mode of ``derivative_engine.h`` differentiates
every intermediate quantity.

A model qualifies (:func:`screw_columns`) when

* every coordinate drives exactly one elementary step of its joint, a rotation by the
  coordinate itself about a constant axis or a translation by it along one (revolute,
  prismatic, cylindrical, universal, spherical, planar and free joints, URDF robots); steps of
  constants are fixed offsets; the joints' positions and orientations are constant (no t);
* the force elements are gravity and generalized forces on coordinates whose values depend on
  the inputs and parameters alone (actuator torques); bodies' mass data are parameters.

Others (absolute angles of a chain, general joints, springs, bushings, forces that depend on
the state) take the forward mode, which covers every model.
"""

from __future__ import annotations

from importlib import resources
from typing import TYPE_CHECKING

import symengine as se

from ..model.forces import GeneralizedForce, Gravity
from ..model.joints import Rot, Trans
from .ccode import HEADER, argument_names, function_source
from .recursive import c_table, layout

if TYPE_CHECKING:
    from ..model.system import System

SCREW = resources.files(__package__ or "jourdain.numeric").joinpath(
    "derivative_screw.h").read_text(encoding="utf-8")
ENTRY = resources.files(__package__ or "jourdain.numeric").joinpath(
    "derivative_entry.h").read_text(encoding="utf-8")


def _free_of(e: se.Basic, symbols: set[str]) -> bool:
    return not ({str(s) for s in e.free_symbols} & symbols)


def screw_columns(system: System) -> list[tuple[int, int]] | None:
    """(body, coordinate) of every elementary step driven by a coordinate, in the order of the
    bodies and of their joints' steps; None where the model does not qualify (see the module
    docstring)."""
    coords = {str(c): i for i, c in enumerate(system.coordinates)}
    moving = set(coords) | {str(system.t)}
    state = moving | {str(s) for s in system.yd} | {"deflection", "deflection_d"}
    cols: list[tuple[int, int]] = []
    for b, body in enumerate(system.bodies):
        joint = body.joint
        fixed = [*joint.position, *(x for row in joint.orientation for x in row)]
        if not all(_free_of(x, moving) for x in fixed):
            return None
        for step in joint.steps:
            if isinstance(step, Rot):
                value, axis = step.angle, step.axis
            elif isinstance(step, Trans) and step.distance is not None and step.axis is not None:
                value, axis = step.distance, step.axis
            else:
                if not all(_free_of(x, moving) for x in step.vector):
                    return None
                continue
            if not all(_free_of(x, moving) for x in axis):
                return None
            if _free_of(value, moving):
                continue
            if not (isinstance(value, se.Symbol) and str(value) in coords):
                return None
            cols.append((b, coords[str(value)]))
        if not all(_free_of(x, moving) for x in (body.mass, *body.com,
                                                  *(x for r in body.inertia for x in r))):
            return None
    if sorted(c for _, c in cols) != list(range(system.f)):
        return None
    for fe in system.forces:
        if isinstance(fe, Gravity):
            continue
        if not (isinstance(fe, GeneralizedForce) and fe.on_coordinate
                and _free_of(fe.value, state)):
            return None
    return cols


def screw_source(system: System, cols: list[tuple[int, int]]) -> str:
    """The C of the derivative unit for a tree of screw joints (tables, the generated
    gravity and generalized forces with their derivatives by the inputs, the recursions)."""
    lay = layout(system)
    f, nu, p = system.f, len(system.inputs), len(lay.parent)
    # the position of each coordinate's 6 local numbers (J_R, J_T) in the layout's columns
    lcol: dict[int, int] = {}
    at = 0
    for cs in lay.columns:
        for c in cs:
            lcol[c] = at
            at += 1
    pred: list[int] = []
    vcol: list[int] = []
    by_body: dict[int, list[int]] = {}
    for j, (b, _) in enumerate(cols):
        by_body.setdefault(b, []).append(j)
    for b in range(p):
        lam = lay.parent[b]
        above = vcol[lam] if lam >= 0 else -1
        for j in by_body.get(b, []):
            pred.append(above)
            above = j
        vcol.append(above)
    # gravity, the generalized forces on each coordinate and their derivatives by the inputs
    g = [se.Add(*(fe.vector[a] for fe in system.forces if isinstance(fe, Gravity)))
         for a in range(3)]
    q = [se.Integer(0)] * f
    index = {str(c): i for i, c in enumerate(system.coordinates)}
    for fe in system.forces:
        if isinstance(fe, GeneralizedForce):
            k = index[str(fe.coordinate)]
            q[k] = q[k] + fe.value
    q_u = [se.diff(q[k], u) for k in range(f) for u in system.inputs]
    names = argument_names(system.y, system.yd, system.t, system.parameter_symbols,
                           system.inputs)
    consts = function_source("jda_consts", [*g, *q, *q_u], names)
    # the joints' motion, columns and mass data (no rates, accelerations or applied forces:
    # the recursions form those)
    zero = se.Integer(0)
    local = [zero if (e < 40 * p and (12 <= e % 40 < 24 or e % 40 >= 34)) else x
             for e, x in enumerate(lay.exprs)]
    consts += function_source("jda_local", local, names)

    head = (f"#define JDA_P {p}\n#define JDA_F {f}\n#define JDA_NU {nu}\n"
            f"#define JDA_NC {len(cols)}\n#define JDA_NL {len(lay.exprs)}\n"
            f"#define JDA_NK {3 + f + f * nu}\n"
            + c_table("jda_parent", list(lay.parent))
            + c_table("jda_body", [b for b, _ in cols])
            + c_table("jda_coord", [c for _, c in cols])
            + c_table("jda_pred", pred) + c_table("jda_vcol", vcol)
            + c_table("jda_lcol", [lcol[c] for _, c in cols]))
    return HEADER + consts + head + SCREW + ENTRY
