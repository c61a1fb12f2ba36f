"""Kinematic quantities for force laws: positions, velocities and accelerations of body points,
relative positions and velocities of two points, angular velocities and distances.

A quantity is declared once with a name and used in force expressions through its symbols:
``name_x``, ``name_y``, ``name_z`` for a vector (components in the quantity's ``frame``), the
name itself for a scalar (:func:`distance`, :func:`distance_rate`)::

    vx, vy, vz = jd.velocity("v_c", "wheel", point=(0, -r, 0), frame="world")
    drag = jd.Force("drag", "wheel", (-c * vx, 0, 0))

The symbols carry their definition (:class:`QuantitySymbol`), so a :class:`jourdain.System`
finds the quantities its forces use without being told. Newton–Euler (q̄^e) replaces each symbol
by its expression in ``y``, ``ẏ``, ``t`` and the parameters, built from the kinematics of the
bodies (:mod:`jourdain.measures`); the equations of motion, the generated code and the
linearization (∂/∂y, ∂/∂ẏ) therefore treat them exactly, as any other expression.

An acceleration ``a = J_T·ÿ + ā`` would put ÿ into q and make the equations of motion implicit;
it is accepted only for points whose motion does not depend on ÿ (a prescribed motion, the
inertial frame), and refused with a message naming the quantity otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass

import symengine as se

from ..errors import ModelError
from .expressions import Expr, as_vector
from .joints import Vec3

#: kinds of quantities: name -> (vector?, two points?, depends on the rates ẏ?)
KINDS: dict[str, tuple[bool, bool, bool]] = {
    "position": (True, False, False),
    "velocity": (True, False, True),
    "acceleration": (True, False, True),
    "angular_velocity": (True, False, True),
    "relative_position": (True, True, False),
    "relative_velocity": (True, True, True),
    "distance": (False, True, False),
    "distance_rate": (False, True, True),
}

COMPONENTS = ("x", "y", "z")


@dataclass(frozen=True)
class Quantity:
    """The definition of a kinematic quantity (see the module docstring).

    ``kind`` is one of :data:`KINDS`. One-point kinds use ``body`` and ``point``; two-point kinds
    ``body``/``point`` (a) and ``body_b``/``point_b``. ``point_frame`` is the frame the point is
    given in (default: ``body``'s own): a point fixed in another frame (a contact point below a
    wheel's centre) names the material point of ``body`` that is there at the instant. ``frame``
    is the frame whose axes the components of a vector refer to (``"world"`` or a body name).
    """

    name: str
    kind: str
    body: str
    point: Vec3
    frame: str
    point_frame: str
    body_b: str | None = None
    point_b: Vec3 | None = None

    @property
    def is_vector(self) -> bool:
        return KINDS[self.kind][0]

    @property
    def uses_rates(self) -> bool:
        """True when the quantity depends on ẏ (not allowed where only y may enter)."""
        return KINDS[self.kind][2]

    @property
    def symbol_names(self) -> tuple[str, ...]:
        if self.is_vector:
            return tuple(f"{self.name}_{c}" for c in COMPONENTS)
        return (self.name,)

    @property
    def bodies(self) -> tuple[str, ...]:
        """Every body or frame the definition refers to."""
        out = [self.body, self.frame, self.point_frame]
        if self.body_b is not None:
            out.append(self.body_b)
        return tuple(out)

    @property
    def expressions(self) -> tuple[Expr, ...]:
        """The point coordinates (parameters only)."""
        return (*self.point, *(self.point_b or ()))

    def describe(self) -> str:
        """The definition in words, e.g. ``velocity "slip" of wheel [0, -r, 0] (point in hub's
        axes), components in world``."""
        comps = f", components in {self.frame}" if self.is_vector else ""
        if KINDS[self.kind][1]:
            return (f'{self.kind} "{self.name}" from {self.body} {_pt(self.point)} to '
                    f"{self.body_b} {_pt(self.point_b or ())}{comps}")
        if self.kind == "angular_velocity":
            return f'angular_velocity "{self.name}" of {self.body}{comps}'
        where = (f" (point in {self.point_frame}'s axes)" if self.point_frame != self.body
                 else "")
        return f'{self.kind} "{self.name}" of {self.body} {_pt(self.point)}{where}{comps}'


def _pt(p: tuple) -> str:
    return "[" + ", ".join(str(x) for x in p) + "]"


class QuantitySymbol(se.Symbol):
    """A symbol that stands for one component of a :class:`Quantity` (``component`` 0, 1, 2, or
    None for a scalar). It compares equal to a plain symbol of the same name: a
    :class:`jourdain.System` refuses a quantity named like a coordinate, parameter or input."""

    def __init__(self, name: str, quantity: Quantity, component: int | None) -> None:
        super().__init__(name)
        self.quantity = quantity
        self.component = component


def _name(name: object) -> str:
    if not isinstance(name, str) or not name.isidentifier() or name.startswith("_"):
        raise ModelError(f"quantity name {name!r} must be an identifier (not starting with _)")
    return name


def _body(body: object, what: str) -> str:
    if not isinstance(body, str) or not body:
        raise ModelError(f"{what}: expected a body name or \"world\", got {body!r}")
    return body


def declare(q: Quantity) -> tuple[QuantitySymbol, ...]:
    """The symbols of ``q``: three for a vector, one for a scalar."""
    if q.is_vector:
        return tuple(QuantitySymbol(n, q, i) for i, n in enumerate(q.symbol_names))
    return (QuantitySymbol(q.name, q, None),)


def quantity(kind: str, name: str, body: str, point: object = (0, 0, 0), *,
             frame: str = "world", point_frame: str | None = None, body_b: str | None = None,
             point_b: object = None) -> Quantity:
    """A :class:`Quantity` from its parts, checked (names, vectors)."""
    if kind not in KINDS:
        raise ModelError(f'unknown kind of quantity "{kind}"; expected one of {", ".join(KINDS)}')
    name = _name(name)
    w = f'{kind} "{name}"'
    body = _body(body, w)
    pt = as_vector(point, f"{w} point")
    two = KINDS[kind][1]
    if two:
        body_b = _body(body_b, w)
        pb = as_vector((0, 0, 0) if point_b is None else point_b, f"{w} point_b")
        if body_b == body and not kind.startswith("relative"):
            raise ModelError(f"{w}: both points are on body \"{body}\"")
    else:
        pb = None
    return Quantity(name, kind, body, pt, _body(frame, w),
                    _body(point_frame if point_frame is not None else body, w), body_b, pb)


def position(name: str, body: str, point: object = (0, 0, 0), frame: str = "world",
             point_frame: str | None = None) -> tuple[QuantitySymbol, ...]:
    """Position of a point of ``body`` (from the inertial origin), components in ``frame``:
    the symbols ``name_x, name_y, name_z``."""
    return declare(quantity("position", name, body, point, frame=frame, point_frame=point_frame))


def velocity(name: str, body: str, point: object = (0, 0, 0), frame: str = "world",
             point_frame: str | None = None) -> tuple[QuantitySymbol, ...]:
    """Absolute (inertial) velocity of the material point of ``body`` at ``point`` (given in
    ``point_frame``, default the body's frame), components in ``frame``."""
    return declare(quantity("velocity", name, body, point, frame=frame, point_frame=point_frame))


def point_acceleration(name: str, body: str, point: object = (0, 0, 0), frame: str = "world",
                    point_frame: str | None = None) -> tuple[QuantitySymbol, ...]:
    """Absolute acceleration of a point of ``body``, components in ``frame``; only for points
    whose motion does not depend on ÿ (else the equations of motion would be implicit)."""
    return declare(quantity("acceleration", name, body, point, frame=frame,
                            point_frame=point_frame))


def angular_velocity(name: str, body: str, frame: str | None = None
                     ) -> tuple[QuantitySymbol, ...]:
    """Absolute angular velocity of ``body``, components in ``frame`` (default: the body's)."""
    return declare(quantity("angular_velocity", name, body, frame=body if frame is None
                            else frame))


def relative_position(name: str, body_a: str, point_a: object, body_b: str, point_b: object,
                      frame: str = "world") -> tuple[QuantitySymbol, ...]:
    """``r_B − r_A`` of point b on ``body_b`` and point a on ``body_a``, components in
    ``frame``."""
    return declare(quantity("relative_position", name, body_a, point_a, frame=frame,
                            body_b=body_b, point_b=point_b))


def relative_velocity(name: str, body_a: str, point_a: object, body_b: str, point_b: object,
                      frame: str = "world") -> tuple[QuantitySymbol, ...]:
    """``v_B − v_A``, the difference of the absolute velocities of the two material points
    (the slip velocity of a contact), components in ``frame``."""
    return declare(quantity("relative_velocity", name, body_a, point_a, frame=frame,
                            body_b=body_b, point_b=point_b))


def distance(name: str, body_a: str, point_a: object, body_b: str,
             point_b: object) -> QuantitySymbol:
    """The distance ``|r_B − r_A|`` of two points (a scalar symbol ``name``)."""
    return declare(quantity("distance", name, body_a, point_a, body_b=body_b,
                            point_b=point_b))[0]


def distance_rate(name: str, body_a: str, point_a: object, body_b: str,
                  point_b: object) -> QuantitySymbol:
    """The rate of the distance of two points, ``e·(v_B − v_A)`` with ``e`` the unit vector
    from a to b (a scalar symbol ``name``; undefined where the points meet)."""
    return declare(quantity("distance_rate", name, body_a, point_a, body_b=body_b,
                            point_b=point_b))[0]


def quantities_in(exprs: list[Expr]) -> dict[str, Quantity]:
    """The quantities whose symbols occur in ``exprs``, by name (sorted), with a ModelError
    when two different definitions share a name."""
    found: dict[str, Quantity] = {}
    for e in exprs:
        for s in e.free_symbols:
            q = getattr(s, "quantity", None)
            if q is None:
                continue
            old = found.get(q.name)
            if old is not None and old != q:
                raise ModelError(f'two different quantities are named "{q.name}": '
                                 f"{old.describe()} and {q.describe()}")
            found[q.name] = q
    return dict(sorted(found.items()))
