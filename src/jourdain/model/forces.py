"""Applied (impressed) forces: the sources of q̄^e.

Expressions may depend on the coordinates ``y``, their rates (``phi_d`` for a coordinate ``phi``,
see :func:`rate`), ``t``, the inputs ``u``, the parameters and kinematic quantities (positions,
velocities, distances of body points: :mod:`jourdain.model.quantities`). Vectors are given in the
frame named by ``frame``: ``"world"`` (inertial) or a body name. :class:`Bushing` is a 6-D
spring–damper between two body frames; :class:`GeneralizedForce` and
:func:`RotationalSpringDamper` act on a coordinate or on an expression of the coordinates.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import symengine as se

from ..errors import ModelError
from .expressions import Expr, as_expr, as_matrix3, as_vector
from .joints import IDENTITY, Mat3, Rot, Vec3, _matmul, orientation_problem, rotation_matrix

#: In a :class:`SpringDamper` ``law``: the elongation ``L - L0`` and its rate ``dL/dt``.
elongation = se.Symbol("elongation")
elongation_d = se.Symbol("elongation_d")
#: In a :class:`GeneralizedForce` ``value`` and a :class:`Bushing` law: the generalized
#: coordinate the force acts on (an expression of y and t; a bushing's deflection component)
#: and its rate.
deflection = se.Symbol("deflection")
deflection_d = se.Symbol("deflection_d")

RESERVED = {"t", "world", str(elongation), str(elongation_d), str(deflection), str(deflection_d)}


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
    """A point force ``vector`` (components in ``frame``) acting on ``body`` at ``point``.

    ``point`` is given in the axes and from the origin of ``point_frame`` (default: ``body``
    itself), a body or ``"world"``: a point fixed in another frame, such as the contact point
    below a wheel's hub, is where the force acts, on the material point of ``body`` that is
    there at the instant (as the kinematic quantities' ``point_frame``). The moment of the
    force about the body's centre of mass then follows the point as it travels over the body.
    """

    name: str
    body: str
    vector: Vec3
    point: Vec3
    frame: str
    point_frame: str

    def __init__(self, name: str, body: str, vector: object, point: object = (0, 0, 0),
                 frame: str = "world", point_frame: str | None = None) -> None:
        object.__setattr__(self, "name", _name(name, "force"))
        object.__setattr__(self, "body", body)
        object.__setattr__(self, "vector", as_vector(vector, f'force "{name}" vector'))
        object.__setattr__(self, "point", as_vector(point, f'force "{name}" point'))
        object.__setattr__(self, "frame", frame)
        object.__setattr__(self, "point_frame", body if point_frame is None else point_frame)


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
    """A generalized force ``value`` on ``coordinate``: a coordinate y_j, or an expression
    ``e(y, t)`` of the coordinates (a relative angle ``phi2 - phi1``, a combination of
    coordinates, a :mod:`position quantity <jourdain.model.quantities>` such as a distance).

    By virtual work, ``value·δe = Σ_j value·(∂e/∂y_j)·δy_j``: it adds ``value·∂e/∂y_j`` to row j
    of q (``value`` itself for a coordinate). ``value`` may use :data:`deflection` (= e) and
    :data:`deflection_d` (= ė), besides coordinates, rates, parameters, inputs, ``t`` and
    kinematic quantities.

    Each share ``value·∂e/∂y_j`` is realized as an equal and opposite torque (or force) pair on
    the two bodies of the joint step that y_j drives, so it also enters q̄^e and the reactions
    (for an expression, the reactions are those of these pairs; a torque between two bodies
    that are not neighbours is better modelled as a :class:`Bushing`).
    """

    name: str
    coordinate: Expr
    value: Expr

    def __init__(self, name: str, coordinate: object, value: object) -> None:
        object.__setattr__(self, "name", _name(name, "force"))
        c = as_expr(coordinate, f'generalized force "{name}" coordinate')
        if c.is_Number:
            raise ModelError(f'generalized force "{name}": the coordinate must be a coordinate or '
                             f"an expression of the coordinates, got the constant {c}")
        object.__setattr__(self, "coordinate", c)
        object.__setattr__(self, "value", as_expr(value, f'generalized force "{name}" value'))

    @property
    def on_coordinate(self) -> bool:
        """True when the force acts on a plain coordinate symbol (not an expression)."""
        return isinstance(self.coordinate, se.Symbol) and not hasattr(self.coordinate,
                                                                      "quantity")


def RotationalSpringDamper(name: str, coordinate: object, stiffness: object = 0,
                           damping: object = 0, rest_angle: object = 0) -> GeneralizedForce:
    """Spring–damper on a joint coordinate or on an expression e of the coordinates:
    ``-stiffness*(e - rest_angle) - damping*ė`` (a :class:`GeneralizedForce` on e).

    Works for rotational and translational coordinates alike; for an expression, the
    generalized forces are ``∂e/∂y_j`` times that value (virtual work).
    """
    c = as_expr(coordinate, f'spring-damper "{name}" coordinate')
    k = as_expr(stiffness, f'spring-damper "{name}" stiffness')
    d = as_expr(damping, f'spring-damper "{name}" damping')
    y0 = as_expr(rest_angle, f'spring-damper "{name}" rest_angle')
    if isinstance(c, se.Symbol) and not hasattr(c, "quantity"):
        return GeneralizedForce(name, c, -k * (c - y0) - d * rate(c))
    return GeneralizedForce(name, c, -k * (deflection - y0) - d * deflection_d)


#: Components of a bushing's deflection and wrench: translations along and rotations about the
#: axes of its frame.
BUSHING_COMPONENTS = ("x", "y", "z", "rx", "ry", "rz")


def _six(value: object, where: str) -> tuple[Expr, ...]:
    if isinstance(value, str | bytes):
        raise ModelError(f"{where}: expected a 6-vector, got the string {value!r}")
    return as_vector(value, where, 6)


def _six_by_six(value: object, where: str) -> tuple[tuple[Expr, ...], ...]:
    """A 6×6 matrix from a 6-vector (its diagonal), nested rows or a NumPy/SymPy matrix."""
    if isinstance(value, str | bytes):
        raise ModelError(f"{where}: expected a 6-vector (diagonal) or a 6×6 matrix of numbers or "
                         f"expressions, got the string {value!r}")
    if isinstance(value, (int, float)) or isinstance(value, se.Basic) and value.is_Number:
        if value == 0:
            z = as_expr(0, where)
            return tuple(tuple(z for _ in range(6)) for _ in range(6))
        raise ModelError(f"{where}: expected a 6-vector (diagonal) or a 6×6 matrix, got {value!r}")
    shape = getattr(value, "shape", None)
    if shape is not None and not isinstance(value, se.Basic):
        array: Any = value  # NumPy, SymPy or SymEngine matrices
        try:
            rows = [[array[i, j] for j in range(shape[1])] for i in range(shape[0])] \
                if len(shape) == 2 else [array[i] for i in range(shape[0])]
        except Exception as exc:  # noqa: BLE001 - reported with the element's name
            raise ModelError(f"{where}: expected a 6-vector or a 6×6 matrix ({exc})") from None
        value = rows
    try:
        items = list(value)  # type: ignore[call-overload]
    except TypeError:
        raise ModelError(f"{where}: expected a 6-vector (diagonal) or a 6×6 matrix, got "
                         f"{value!r}") from None
    if len(items) != 6:
        raise ModelError(f"{where}: expected 6 entries (the diagonal) or 6 rows, got {len(items)}")
    if all(not isinstance(r, (str, bytes)) and hasattr(r, "__len__") for r in items):
        out = []
        for i, r in enumerate(items):
            if len(r) != 6:
                raise ModelError(f"{where}: row {i} has {len(r)} entries, expected 6")
            out.append(tuple(as_expr(v, f"{where}[{i},{j}]") for j, v in enumerate(r)))
        return tuple(out)
    diag = _six(items, where)
    z = as_expr(0, where)
    return tuple(tuple(diag[i] if i == j else z for j in range(6)) for i in range(6))


def _axes(value: object, where: str) -> Mat3:
    """A bushing's axes in a body frame: a 3×3 rotation matrix or a list of :class:`Rot`."""
    if value is None:
        return IDENTITY
    if isinstance(value, list | tuple) and value and all(isinstance(r, Rot) for r in value):
        R = IDENTITY
        for r in value:
            R = _matmul(R, rotation_matrix(r.axis, r.angle))
        return R
    R = as_matrix3(value, where)
    if not any(x.free_symbols for row in R for x in row):
        why = orientation_problem(R, {})
        if why:
            raise ModelError(f"{where}: the matrix {why}")
    return R


@dataclass(frozen=True)
class Bushing:
    """A 6-D spring–damper between a point of ``body_a`` and a point of ``body_b`` (either may
    be ``"world"``): rubber mounts, bearings, shaft couplings.

    Each end has its own axes: the body's axes turned by ``axes_a`` (``axes_b``), a constant
    rotation (3×3 matrix, or a list of :class:`jourdain.Rot`; default: the body's axes), so that
    inclined mounts and bodies whose frames differ at rest are described directly. Deflection
    ``x = (d, s)`` (6), in the axes of ``frame`` (``body_a`` or ``body_b``: that end's axes):

    * ``d = S_Fᵀ·(r_b − r_a)``: the position of point b relative to point a, in frame F;
    * ``s = ½·vee(R − Rᵀ) = sin θ·n`` with ``R = S_Aᵀ·S_B`` the rotation of end b's axes
      relative to end a's (angle θ about the unit axis n): the axial vector of the relative
      rotation's skew part, whose components are the same in the axes of either end.

    Wrench on body b, in frame F, conjugate to x:
    ``w = preload − stiffness·x − damping·ẋ``, with ẋ the time derivative of x (``ḋ``: the rate
    of d seen from frame F; ``ṡ = ½(tr R·E − R)·ω_rel``, ω_rel the angular velocity of b
    relative to a); a ``laws`` entry replaces one component's row by
    ``w_i = preload_i − law_i`` with the law an expression in :data:`deflection` (x_i) and
    :data:`deflection_d` (ẋ_i) besides the names allowed in forces. The wrenches on the two
    bodies follow from the virtual work ``wᵀ·δx``: equal and opposite (the force at each
    point, and torques whose sum with the moment of the force balances), so the reactions and
    the energy see a proper internal force element.

    Why s: it is smooth at zero rotation (the rotation vector θ·n is 0/0 there, exactly where
    a bushing is linearized), needs no rotation sequence (Cardan angles depend on one and have
    a singular attitude), has the same components in both bodies' axes and changes sign when a
    and b are exchanged, and agrees with θ·n to first order (relative difference θ²/6:
    0.2 % at 6°), so the linearization about the unloaded state is that of any small-angle
    convention. It is meant for small relative rotations (below 90° it is one to one).

    Parameters
    ----------
    stiffness, damping : 6-vector (diagonal) or 6×6 matrix
        Order ``x, y, z, rx, ry, rz`` (:data:`BUSHING_COMPONENTS`); forces per length and
        torques per radian.
    preload : 6-vector
        The force and torque on body b at zero deflection and rate (frame F).
    laws : mapping component -> expression, optional
        Nonlinear characteristics (their component's rows of stiffness and damping must be 0).
    """

    name: str
    body_a: str
    body_b: str
    point_a: Vec3
    point_b: Vec3
    frame: str
    axes_a: Mat3
    axes_b: Mat3
    stiffness: tuple[tuple[Expr, ...], ...]
    damping: tuple[tuple[Expr, ...], ...]
    preload: tuple[Expr, ...]
    laws: tuple[Expr | None, ...]

    def __init__(self, name: str, body_a: str, body_b: str, point_a: object = (0, 0, 0),
                 point_b: object = (0, 0, 0), stiffness: object = 0, damping: object = 0,
                 preload: object = (0, 0, 0, 0, 0, 0), frame: str | None = None,
                 laws: dict | None = None, axes_a: object = None,
                 axes_b: object = None) -> None:
        w = f'bushing "{name}"'
        set_ = object.__setattr__
        set_(self, "name", _name(name, "bushing"))
        set_(self, "body_a", body_a)
        set_(self, "body_b", body_b)
        set_(self, "point_a", as_vector(point_a, f"{w} point_a"))
        set_(self, "point_b", as_vector(point_b, f"{w} point_b"))
        fr = body_a if frame is None else frame
        if fr not in (body_a, body_b):
            raise ModelError(f'{w}: frame "{fr}" must be one of its bodies, "{body_a}" or '
                             f'"{body_b}"')
        set_(self, "frame", fr)
        set_(self, "axes_a", _axes(axes_a, f"{w} axes_a"))
        set_(self, "axes_b", _axes(axes_b, f"{w} axes_b"))
        K = _six_by_six(stiffness, f"{w} stiffness")
        C = _six_by_six(damping, f"{w} damping")
        set_(self, "stiffness", K)
        set_(self, "damping", C)
        set_(self, "preload", _six(preload, f"{w} preload"))
        out: list[Expr | None] = [None] * 6
        for key, law in (laws or {}).items():
            if key not in BUSHING_COMPONENTS:
                raise ModelError(f'{w}: unknown component "{key}" in laws; expected one of '
                                 f"{', '.join(BUSHING_COMPONENTS)}")
            i = BUSHING_COMPONENTS.index(key)
            if any(v != 0 for v in K[i]) or any(v != 0 for v in C[i]):
                raise ModelError(f'{w}: component "{key}" has a law and also nonzero entries in '
                                 "its row of stiffness or damping; give one or the other")
            out[i] = as_expr(law, f"{w} laws.{key}")
        set_(self, "laws", tuple(out))

    @property
    def expressions(self) -> list[Expr]:
        """Every expression of the element (for checks of the names used)."""
        return [*self.point_a, *self.point_b, *(v for r in self.axes_a for v in r),
                *(v for r in self.axes_b for v in r), *(v for r in self.stiffness for v in r),
                *(v for r in self.damping for v in r), *self.preload,
                *(law for law in self.laws if law is not None)]

    @property
    def linear(self) -> bool:
        """True without laws: the wrench is linear in x and ẋ."""
        return all(law is None for law in self.laws)


ForceElement = Gravity | Force | Torque | SpringDamper | GeneralizedForce | Bushing
