"""Checks of a system's description: parents before children, declared names, what each joint,
mass, force element and kinematic quantity may depend on, axes and mass data at the default
parameter values. :class:`jourdain.model.System` runs them when it is built; each failure is a
ModelError naming the element and what is wrong."""

from __future__ import annotations

import math
from typing import Protocol

import symengine as se

from ..errors import ModelError
from .bodies import WORLD, Body, check_values
from .expressions import free_names, values_at
from .forces import (
    RESERVED,
    Bushing,
    Force,
    ForceElement,
    GeneralizedForce,
    Gravity,
    SpringDamper,
    Torque,
    deflection,
    deflection_d,
    elongation,
    elongation_d,
)
from .joints import Rot, orientation_problem
from .quantities import Quantity


class Description(Protocol):
    """What the checks read of a system (the fields of :class:`jourdain.model.System`)."""

    @property
    def coordinates(self) -> tuple[se.Symbol, ...]: ...
    @property
    def inputs(self) -> tuple[se.Symbol, ...]: ...
    @property
    def parameters(self) -> tuple[tuple[str, float], ...]: ...
    @property
    def bodies(self) -> tuple[Body, ...]: ...
    @property
    def forces(self) -> tuple[ForceElement, ...]: ...
    @property
    def quantities(self) -> tuple[Quantity, ...]: ...


def parents_first(bodies: list[Body]) -> tuple[Body, ...]:
    """The bodies in the order given, checked to list every parent before its children.

    The rows of M̄, J̄, q̄^c, q̄^e and the joints of g follow this order. Any order with parents
    first is valid for the method, so the user's is kept; one with a child before its parent is
    refused instead of being rearranged behind the user's back.
    """
    position: dict[str, int] = {}
    for k, b in enumerate(bodies):
        if b.name in position:
            raise ModelError(f'duplicate body name "{b.name}"')
        position[b.name] = k
    for b in bodies:
        if b.parent != WORLD and b.parent not in position:
            raise ModelError(
                f'body "{b.name}": unknown parent "{b.parent}" (not a body and not "world")'
            )
    # with every parent listed first the parents cannot form a cycle; where one is listed
    # later, a cycle is reported as such rather than as a matter of order
    parent = {b.name: b.parent for b in bodies}
    for k, b in enumerate(bodies):
        if b.parent == WORLD or position[b.parent] < k:
            continue
        chain = [b.name]
        while parent[chain[-1]] != WORLD and parent[chain[-1]] not in chain:
            chain.append(parent[chain[-1]])
        if parent[chain[-1]] != WORLD:
            cycle = " → ".join([*chain[chain.index(parent[chain[-1]]):], parent[chain[-1]]])
            raise ModelError(
                f'body "{b.name}" is not connected to the inertial frame (a cycle of parents: '
                f'{cycle}); every chain of parents must end at "{WORLD}"'
            )
        raise ModelError(
            f'body "{b.name}" (position {k + 1}) comes before its parent "{b.parent}" '
            f"(position {position[b.parent] + 1}): list parents before their children"
        )
    return tuple(bodies)


def validate(sys: Description) -> None:
    y_names = [str(c) for c in sys.coordinates]
    u_names = [str(c) for c in sys.inputs]
    p_names = [k for k, _ in sys.parameters]
    rate_names = [f"{n}_d" for n in y_names] + [f"{n}_dd" for n in y_names]
    if not y_names:
        raise ModelError("a system needs at least one generalized coordinate")
    if not sys.bodies:
        raise ModelError("a system needs at least one body")
    seen: dict[str, str] = {}
    for kind, names in (("coordinate", y_names), ("input", u_names), ("parameter", p_names),
                        ("coordinate rate", rate_names)):
        for n in names:
            if n in RESERVED:
                raise ModelError(f'{kind} name "{n}" is reserved')
            if n in seen:
                raise ModelError(f'name "{n}" is declared twice (as {seen[n]} and as {kind})')
            seen[n] = kind

    joint_names: dict[str, str] = {}
    driven_by: dict[str, str] = {}
    used_coords: set[str] = set()
    allowed_kin = set(y_names) | set(p_names) | {"t"}
    defaults = dict(sys.parameters)
    for b in sys.bodies:
        j = b.joint
        if j.name in joint_names:
            raise ModelError(
                f'duplicate joint name "{j.name}" (bodies "{joint_names[j.name]}" and "{b.name}")'
            )
        joint_names[j.name] = b.name
        for c in j.coordinates:
            cn = str(c)
            if cn not in y_names:
                raise ModelError(f'joint "{j.name}" (body "{b.name}"): "{cn}" is not a declared coordinate')
            if cn in driven_by:
                raise ModelError(
                    f'coordinate "{cn}" is driven by two joints: "{driven_by[cn]}" and "{j.name}"'
                )
            driven_by[cn] = j.name
        kin_exprs = [*j.position, *(x for row in j.orientation for x in row)]
        for s in j.steps:
            kin_exprs.extend([s.angle] if isinstance(s, Rot) else list(s.vector))
        kin_names = free_names(kin_exprs)
        bad = kin_names - allowed_kin
        if bad:
            raise ModelError(
                f'joint "{j.name}" (body "{b.name}"): undeclared symbol(s) {sorted(bad)}; joints may '
                "depend on coordinates, parameters and t only"
            )
        used_coords |= kin_names & set(y_names)
        _check_axes(sys, b)
        # mass data
        mass_names = free_names([b.mass, *b.com, *(x for row in b.inertia for x in row)])
        bad = mass_names - set(p_names)
        if bad:
            raise ModelError(f'body "{b.name}": mass data use undeclared symbol(s) {sorted(bad)}')
        # mass data a rigid body can have, and joint frames and axes, at the default values
        check_values([b], defaults)
    unused = [n for n in y_names if n not in used_coords]
    if unused:
        raise ModelError(f"coordinate(s) {unused} are not used by any joint")

    body_names = {b.name for b in sys.bodies}
    allowed_force = set(y_names) | set(p_names) | set(u_names) | {"t"} | {f"{n}_d" for n in y_names}
    q_names = _check_quantities(sys, seen, body_names, set(p_names))
    allowed_force |= q_names
    force_names: set[str] = set()
    for f in sys.forces:
        w = f'force "{f.name}"'
        if f.name in force_names:
            raise ModelError(f'duplicate force name "{f.name}"')
        force_names.add(f.name)
        exprs: list = []
        extra: set[str] = set()
        if isinstance(f, Gravity):
            exprs = list(f.vector)
        elif isinstance(f, Force | Torque):
            if f.body not in body_names:
                raise ModelError(f'{w}: unknown body "{f.body}"')
            if f.frame != WORLD and f.frame not in body_names:
                raise ModelError(f'{w}: unknown frame "{f.frame}" (a body name or "world")')
            point_frame = getattr(f, "point_frame", WORLD)
            if point_frame != WORLD and point_frame not in body_names:
                raise ModelError(f'{w}: unknown point_frame "{point_frame}" (a body name or '
                                 '"world")')
            exprs = list(f.vector) + list(getattr(f, "point", ()))
        elif isinstance(f, SpringDamper):
            for bn in (f.body_a, f.body_b):
                if bn != WORLD and bn not in body_names:
                    raise ModelError(f'spring-damper "{f.name}": unknown body "{bn}"')
            if f.body_a == f.body_b:
                raise ModelError(f'spring-damper "{f.name}": both ends are on body "{f.body_a}"')
            exprs = [*f.point_a, *f.point_b, f.stiffness, f.damping, f.rest_length]
            if f.law is not None:
                exprs.append(f.law)
                extra = {str(elongation), str(elongation_d)}
        elif isinstance(f, GeneralizedForce):
            if f.on_coordinate:
                if str(f.coordinate) not in y_names:
                    raise ModelError(f'{w}: "{f.coordinate}" is not a declared coordinate')
            else:
                used = free_names([f.coordinate])
                bad = used - (set(y_names) | set(p_names) | {"t"} | q_names)
                if bad:
                    raise ModelError(f"{w}: its coordinate {f.coordinate} uses {sorted(bad)}; "
                                     "it may use coordinates, parameters, t and kinematic "
                                     "quantities of positions")
                if not used & set(y_names) and not used & q_names:
                    raise ModelError(f"{w}: its coordinate {f.coordinate} depends on no "
                                     "coordinate")
            exprs = [f.value]
            extra = {str(deflection), str(deflection_d)}
        elif isinstance(f, Bushing):
            w = f'bushing "{f.name}"'
            for bn in (f.body_a, f.body_b):
                if bn != WORLD and bn not in body_names:
                    raise ModelError(f'{w}: unknown body "{bn}"')
            if f.body_a == f.body_b:
                raise ModelError(f'{w}: both ends are on body "{f.body_a}"')
            points = free_names([*f.point_a, *f.point_b]) - set(p_names)
            if points:
                raise ModelError(f"{w}: points use {sorted(points)}; points may use parameters "
                                 "only")
            for key in ("axes_a", "axes_b"):
                R = getattr(f, key)
                bad = free_names([x for row in R for x in row]) - set(p_names)
                if bad:
                    raise ModelError(f"{w}: {key} uses {sorted(bad)}; axes may use parameters "
                                     "only")
                why = orientation_problem(R, defaults)
                if why:
                    raise ModelError(f"{w}: {key}: the matrix {why}")
            exprs = f.expressions
            extra = {str(deflection), str(deflection_d)}
        bad = free_names(exprs) - allowed_force - extra
        if bad:
            hint = ""
            if isinstance(f, GeneralizedForce | Bushing) and bad & {str(elongation),
                                                                  str(elongation_d)}:
                hint = " (use deflection and deflection_d here)"
            raise ModelError(f"{w}: undeclared symbol(s) {sorted(bad)}{hint}")


def force_expressions(f: object) -> list:
    """Every expression of a force element (to find the kinematic quantities it uses)."""
    if isinstance(f, Gravity):
        return list(f.vector)
    if isinstance(f, Force):
        return [*f.vector, *f.point]
    if isinstance(f, Torque):
        return list(f.vector)
    if isinstance(f, SpringDamper):
        return [f.stiffness, f.damping, f.rest_length, *([f.law] if f.law is not None else [])]
    if isinstance(f, GeneralizedForce):
        return [f.coordinate, f.value]
    if isinstance(f, Bushing):
        return f.expressions
    return []


def _check_quantities(sys: Description, seen: dict[str, str], body_names: set[str],
                      p_names: set[str]) -> set[str]:
    """Check the kinematic quantities the forces use; return the names of their symbols."""
    names: set[str] = set()
    for q in sys.quantities:
        w = f'quantity "{q.name}" ({q.kind})'
        for bn in q.bodies:
            if bn != WORLD and bn not in body_names:
                raise ModelError(f'{w}: unknown body or frame "{bn}" (a body name or "world")')
        bad = free_names(list(q.expressions)) - p_names
        if bad:
            raise ModelError(f"{w}: points use {sorted(bad)}; points may use parameters only")
        for n in q.symbol_names:
            if n in seen or n in RESERVED:
                what = seen.get(n, "a reserved name")
                raise ModelError(f'{w}: its symbol "{n}" is already declared (as {what})')
            names.add(n)
    # a generalized force's coordinate must not depend on rates through a quantity
    for f in sys.forces:
        if isinstance(f, GeneralizedForce) and not f.on_coordinate:
            for s in f.coordinate.free_symbols:
                used = getattr(s, "quantity", None)
                if used is not None and used.uses_rates:
                    raise ModelError(
                        f'force "{f.name}": its coordinate uses {used.describe()}, which depends '
                        "on the rates; a generalized coordinate may use positions, relative "
                        "positions and distances only")
    return names


def _check_axes(sys: Description, b: Body) -> None:
    """Axes of the joint's steps: constant in the frame before the step (parameters only, as
    the kinematics takes u̇ = 0) and, for axes with parameters, not zero at the default values
    (:func:`jourdain.model.expressions.unit_axis` divides them by their symbolic length)."""
    j = b.joint
    p_names = {k for k, _ in sys.parameters}
    defaults = dict(sys.parameters)
    for k, step in enumerate(j.steps):
        u = step.axis
        if u is None:
            continue
        names = free_names(u)
        if not names:
            continue
        axis = "the axis" if len({s.axis for s in j.steps}) == 1 else f"the axis of step {k}"
        where = f'joint "{j.name}" (body "{b.name}"): {axis}'
        bad = names - p_names
        if bad:
            raise ModelError(f"{where} uses {sorted(bad)}; axes may depend on parameters only")
        if not all(math.isfinite(v) for v in values_at(u, defaults)):  # NaN: no real value
            raise ModelError(f"{where} is the zero vector at the default parameter values")


