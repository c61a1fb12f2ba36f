"""Velocity (nonholonomic) constraints: the data of rolling contacts, knife edges and general
velocity rows ``A(y, t)·ẏ + a(y, t) = 0`` (METHOD.md §7, *general* multibody systems). Their
rows are formed by the constraint stage (:mod:`jourdain.stages.contact_rows`), in the same place
as the closing joints' rows.

The ground is the plane through the world's origin normal to ``normal`` (a world axis, the
side the bodies are on: ``"z"`` when z points up, ``"-z"`` in a frame whose z points down, as
in the benchmark bicycle's).

==================  ===========================================================================
element             rows
==================  ===========================================================================
``RollingDisc``     a disc (a wheel with a knife-edge rim, or a torus of ``tube_radius`` ρ) of
                    ``radius`` about ``center`` in the plane normal to ``axis`` (body frame)
                    rolling on the ground without slip: its contact point is the rim's point
                    nearest the ground, ``P = C − R·(n − (n·a)·a)/|n − (n·a)·a| − ρ·n``; rows
                    ``<name>.N``: ``n·P = 0`` (holonomic: the wheel touches the ground),
                    ``<name>.T1``, ``<name>.T2``: the velocity of the disc's material point at
                    P along two ground directions vanishes (velocity rows)
``KnifeEdge``       a blade or skate at ``point`` of a body, edge ``direction`` (body frame):
                    the point's velocity across the edge in the ground plane vanishes (one
                    velocity row ``<name>.T``)
``VelocityConstraint``  the given expressions, linear in the rates ``<coordinate>_d`` (rows
                    ``<name>.1``, ...)
==================  ===========================================================================
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import symengine as se

from ..errors import ModelError
from .expressions import Expr, Vec3, as_expr, as_vector, axis_vector, free_names
from .forces import rate

ZERO3: Vec3 = (se.Integer(0), se.Integer(0), se.Integer(0))


def _name(name: object, what: str) -> str:
    if not isinstance(name, str) or not name.isidentifier():
        raise ModelError(f"{what}: name {name!r} must be an identifier")
    return name


def _ground(normal: object, where: str) -> Vec3:
    n = axis_vector(normal, f"{where} normal")
    if sum(1 for c in n if c != 0) != 1:
        raise ModelError(f"{where}: the ground normal must be a world axis (\"z\", \"-z\", ...), "
                         f"got {normal!r}")
    return n


@dataclass(frozen=True)
class RollingDisc:
    """A disc of ``radius`` on ``body`` rolling without slip on the ground.

    Parameters
    ----------
    name : str
        Names its rows and contact forces (``<name>.N`` normal, ``<name>.T1``, ``<name>.T2``
        tangential, along the ground's two axes).
    body : str
        The wheel body.
    radius : expression
        Rim radius (a parameter expression).
    axis : axis
        The disc's axle in the body frame (``"y"``, or a 3-vector).
    center : 3-vector, optional
        The disc's centre in the body frame (default the body frame's origin).
    normal : world axis, optional
        The ground's normal pointing to the bodies' side (default ``"z"``).
    tube_radius : expression, optional
        A torus: the rim's cross-section is a circle of this radius about the circle of
        ``radius`` (a tyre's crown; 0, the default, is the knife-edge disc; ``radius = 0``
        makes a sphere of ``tube_radius``).
    """

    name: str
    body: str
    radius: Expr
    axis: Vec3
    center: Vec3
    normal: Vec3
    tube_radius: Expr = se.Integer(0)

    def __init__(self, name: str, body: str, radius: object, axis: object = "y", *,
                 center: object = None, normal: object = "z",
                 tube_radius: object = 0) -> None:
        set_ = object.__setattr__
        where = f'rolling disc "{_name(name, "rolling disc")}"'
        set_(self, "name", name)
        set_(self, "body", str(body))
        set_(self, "radius", as_expr(radius, f"{where} radius"))
        set_(self, "axis", axis_vector(axis, f"{where} axis"))
        set_(self, "center", ZERO3 if center is None else as_vector(center, f"{where} center"))
        set_(self, "normal", _ground(normal, where))
        set_(self, "tube_radius", as_expr(tube_radius, f"{where} tube_radius"))

    @property
    def bodies(self) -> tuple[str, ...]:
        return (self.body,)

    def symbols(self) -> set[str]:
        return free_names([self.radius, self.tube_radius, *self.axis, *self.center])


@dataclass(frozen=True)
class KnifeEdge:
    """A knife edge or skate at ``point`` of ``body``: no velocity across its edge
    ``direction`` (body frame) in the ground plane (one velocity row ``<name>.T``, its
    multiplier the lateral force on the body at the point)."""

    name: str
    body: str
    point: Vec3
    direction: Vec3
    normal: Vec3

    def __init__(self, name: str, body: str, point: object = None, direction: object = "x", *,
                 normal: object = "z") -> None:
        set_ = object.__setattr__
        where = f'knife edge "{_name(name, "knife edge")}"'
        set_(self, "name", name)
        set_(self, "body", str(body))
        set_(self, "point", ZERO3 if point is None else as_vector(point, f"{where} point"))
        set_(self, "direction", axis_vector(direction, f"{where} direction"))
        set_(self, "normal", _ground(normal, where))

    @property
    def bodies(self) -> tuple[str, ...]:
        return (self.body,)

    def symbols(self) -> set[str]:
        return free_names([*self.point, *self.direction])


@dataclass(frozen=True)
class VelocityConstraint:
    """General velocity rows ``A(y, t)·ẏ + a(y, t) = 0``: each expression linear in the rates
    (the symbols ``<coordinate>_d``), of the coordinates, t and parameters. Its rows' forces are
    generalized forces ``Aᵀ·λ`` (no point of application)."""

    name: str
    expressions: tuple[Expr, ...]

    def __init__(self, name: str, expressions: Sequence[object]) -> None:
        where = f'velocity constraint "{_name(name, "velocity constraint")}"'
        if isinstance(expressions, (str, se.Basic)) or not expressions:
            raise ModelError(f"{where}: expected a list of expressions")
        object.__setattr__(self, "name", name)
        object.__setattr__(self, "expressions", tuple(
            as_expr(e, f"{where} expression {i + 1}") for i, e in enumerate(expressions)))

    @property
    def bodies(self) -> tuple[str, ...]:
        return ()

    def symbols(self) -> set[str]:
        return free_names(list(self.expressions))


Contact = RollingDisc | KnifeEdge | VelocityConstraint
CONTACT_TYPES = (RollingDisc, KnifeEdge, VelocityConstraint)


def check_linear(name: str, expressions: Sequence[Expr], coordinates: Sequence[se.Symbol]
                 ) -> None:
    """ModelError naming the row when an expression of a velocity constraint is not linear in
    the rates (or has none: then it is no velocity row)."""
    rates = [rate(c) for c in coordinates]
    for i, e in enumerate(expressions, 1):
        first = [se.diff(e, r) for r in rates]
        if all(d == 0 for d in first):
            raise ModelError(f'velocity constraint "{name}" expression {i} ({e}) contains no '
                             "rate; a condition on positions is a closing constraint "
                             '(ClosingJoint(type="constraint"))')
        for d in first:
            if any(se.diff(d, r) != 0 for r in rates):
                raise ModelError(f'velocity constraint "{name}" expression {i} ({e}) is not '
                                 "linear in the rates")


__all__ = ["CONTACT_TYPES", "Contact", "KnifeEdge", "RollingDisc", "VelocityConstraint",
           "check_linear"]
