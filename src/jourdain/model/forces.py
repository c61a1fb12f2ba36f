"""Applied (impressed) forces: the sources of q̄^e.

Expressions may depend on the coordinates ``y``, their rates (``phi_d`` for a coordinate ``phi``,
see :func:`rate`), ``t``, the inputs ``u`` and the parameters. Vectors are given in the frame
named by ``frame``: ``"world"`` (inertial) or a body name.
"""

from __future__ import annotations

from dataclasses import dataclass

import symengine as se

from ..errors import ModelError
from .expressions import Expr, as_expr, as_vector
from .joints import Vec3

#: In a :class:`SpringDamper` ``law``: the elongation ``L - L0`` and its rate ``dL/dt``.
elongation = se.Symbol("elongation")
elongation_d = se.Symbol("elongation_d")

RESERVED = {"t", "world", str(elongation), str(elongation_d)}


def rate(coordinate: se.Symbol) -> se.Symbol:
    """The symbol of the rate ẏ of a coordinate: ``phi`` → ``phi_d``."""
    return se.Symbol(f"{coordinate}_d")


def acceleration(coordinate: se.Symbol) -> se.Symbol:
    """The symbol of the acceleration ÿ of a coordinate: ``phi`` → ``phi_dd``."""
    return se.Symbol(f"{coordinate}_dd")


def _name(name: object, what: str) -> str:
    if not isinstance(name, str) or not name.isidentifier():
        raise ModelError(f"{what} name {name!r} must be an identifier")
    return name


@dataclass(frozen=True)
class Gravity:
    """Gravity on every body: force ``m_i * vector`` at each centre of mass (inertial frame)."""

    vector: Vec3
    name: str = "gravity"

    def __init__(self, vector: object, name: str = "gravity") -> None:
        object.__setattr__(self, "name", _name(name, "force"))
        object.__setattr__(self, "vector", as_vector(vector, f'force "{name}" vector'))


@dataclass(frozen=True)
class Force:
    """A point force ``vector`` (in ``frame``) acting on ``body`` at ``point`` (body frame)."""

    name: str
    body: str
    vector: Vec3
    point: Vec3
    frame: str

    def __init__(self, name: str, body: str, vector: object, point: object = (0, 0, 0),
                 frame: str = "world") -> None:
        object.__setattr__(self, "name", _name(name, "force"))
        object.__setattr__(self, "body", body)
        object.__setattr__(self, "vector", as_vector(vector, f'force "{name}" vector'))
        object.__setattr__(self, "point", as_vector(point, f'force "{name}" point'))
        object.__setattr__(self, "frame", frame)


@dataclass(frozen=True)
class Torque:
    """A torque ``vector`` (in ``frame``) acting on ``body``."""

    name: str
    body: str
    vector: Vec3
    frame: str

    def __init__(self, name: str, body: str, vector: object, frame: str = "world") -> None:
        object.__setattr__(self, "name", _name(name, "torque"))
        object.__setattr__(self, "body", body)
        object.__setattr__(self, "vector", as_vector(vector, f'torque "{name}" vector'))
        object.__setattr__(self, "frame", frame)


@dataclass(frozen=True)
class SpringDamper:
    """A spring–damper between ``point_a`` on ``body_a`` and ``point_b`` on ``body_b``.

    The tension (positive: pulls the points together) is
    ``stiffness*(L - rest_length) + damping*dL/dt``, or, when ``law`` is given, the expression
    ``law`` in :data:`elongation` (``L - rest_length``) and :data:`elongation_d`, for nonlinear
    characteristics. Points are in the body frames; ``"world"`` is allowed as a body.
    """

    name: str
    body_a: str
    point_a: Vec3
    body_b: str
    point_b: Vec3
    stiffness: Expr
    damping: Expr
    rest_length: Expr
    law: Expr | None

    def __init__(self, name: str, body_a: str, point_a: object, body_b: str, point_b: object,
                 stiffness: object = 0, damping: object = 0, rest_length: object = 0,
                 law: object = None) -> None:
        w = f'spring-damper "{name}"'
        object.__setattr__(self, "name", _name(name, "spring-damper"))
        object.__setattr__(self, "body_a", body_a)
        object.__setattr__(self, "point_a", as_vector(point_a, f"{w} point_a"))
        object.__setattr__(self, "body_b", body_b)
        object.__setattr__(self, "point_b", as_vector(point_b, f"{w} point_b"))
        object.__setattr__(self, "stiffness", as_expr(stiffness, f"{w} stiffness"))
        object.__setattr__(self, "damping", as_expr(damping, f"{w} damping"))
        object.__setattr__(self, "rest_length", as_expr(rest_length, f"{w} rest_length"))
        object.__setattr__(self, "law", None if law is None else as_expr(law, f"{w} law"))

    def tension(self, L: Expr, L_d: Expr) -> Expr:
        """Tension for length ``L`` and length rate ``L_d``."""
        if self.law is None:
            return self.stiffness * (L - self.rest_length) + self.damping * L_d
        return self.law.subs({elongation: L - self.rest_length, elongation_d: L_d})


@dataclass(frozen=True)
class GeneralizedForce:
    """A generalized force ``value`` on ``coordinate``: it adds ``value`` to the row of q.

    Realized as an equal and opposite torque (or force) pair on the two bodies of the joint step
    that the coordinate drives, so it also enters q̄^e and the reactions correctly.
    """

    name: str
    coordinate: se.Symbol
    value: Expr

    def __init__(self, name: str, coordinate: object, value: object) -> None:
        object.__setattr__(self, "name", _name(name, "force"))
        c = as_expr(coordinate, f'generalized force "{name}" coordinate')
        if not isinstance(c, se.Symbol):
            raise ModelError(f'generalized force "{name}": coordinate must be a symbol, got {c}')
        object.__setattr__(self, "coordinate", c)
        object.__setattr__(self, "value", as_expr(value, f'generalized force "{name}" value'))


def RotationalSpringDamper(name: str, coordinate: object, stiffness: object = 0,
                           damping: object = 0, rest_angle: object = 0) -> GeneralizedForce:
    """Spring–damper on a joint coordinate: ``-stiffness*(y - rest_angle) - damping*ẏ``.

    Works for rotational and translational joint coordinates alike.
    """
    c = as_expr(coordinate, f'spring-damper "{name}" coordinate')
    if not isinstance(c, se.Symbol):
        raise ModelError(f'spring-damper "{name}": coordinate must be a symbol, got {c}')
    k = as_expr(stiffness, f'spring-damper "{name}" stiffness')
    d = as_expr(damping, f'spring-damper "{name}" damping')
    y0 = as_expr(rest_angle, f'spring-damper "{name}" rest_angle')
    return GeneralizedForce(name, c, -k * (c - y0) - d * rate(c))


ForceElement = Gravity | Force | Torque | SpringDamper | GeneralizedForce
