"""Rigid bodies and helpers for the inertia of common shapes.

A body's frame is the frame its joint ends in; the centre of mass ``com`` and the inertia tensor
``inertia`` (about the centre of mass) are given in that body frame, so they are constant.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

import numpy as np
import symengine as se

from ..errors import ModelError
from .expressions import Expr, as_expr, as_matrix3, as_vector, values_at
from .joints import Joint, Mat3, Vec3, check_joint_values

WORLD = "world"

_ZERO = se.Integer(0)


@dataclass(frozen=True)
class Body:
    """A rigid body hanging from ``parent`` (a body name or ``"world"``) through ``joint``.

    Parameters
    ----------
    name : str
    parent : str
        Name of the parent body, or ``"world"`` for the inertial frame.
    joint : Joint
    mass : expression
        May be zero only for massless frames (then ``inertia`` must be zero as well).
    com : 3-vector
        Centre of mass in the body frame.
    inertia : 3x3 matrix or 3-vector, or :func:`planar_inertia`
        Inertia tensor about the centre of mass in the body frame; a 3-vector gives its
        diagonal (principal moments). Zero for point masses. ``planar_inertia(I, "z")`` gives
        the moment about the normal of the plane alone, for a body whose angular velocity
        stays about that axis (checked by the Newton–Euler stage): ``planar`` is then that
        axis.
    ``section``: the body is a slice of a beam (an elastic body's mass point,
    :mod:`jourdain.elastic.quadrature`), whose inertia is the section's ρ·(I_p, I_y, I_z) per
    length, that of a one-dimensional continuum: positive semi-definite, but without the
    rigid body's triangle inequality (a beam without rotary inertia keeps its torsional one).
    """

    name: str
    parent: str
    joint: Joint
    mass: Expr
    com: Vec3
    inertia: Mat3
    planar: str | None = None
    section: bool = False

    def __init__(self, name: str, parent: str, joint: Joint, mass: object = None,
                 com: object = (0, 0, 0), inertia: object = None, *,
                 section: bool = False) -> None:
        if not isinstance(name, str) or not name.isidentifier():
            raise ModelError(f"body name {name!r} must be an identifier")
        if name == WORLD:
            raise ModelError(f'body name "{WORLD}" is reserved for the inertial frame')
        if not isinstance(parent, str):
            raise ModelError(f'body "{name}": parent must be a body name or "world"')
        if not isinstance(joint, Joint):
            raise ModelError(f'body "{name}": joint must be a Joint, got {type(joint).__name__}')
        if mass is None:
            raise ModelError(f'body "{name}": mass is missing')
        m = as_expr(mass, f'body "{name}" mass')
        c = as_vector(com, f'body "{name}" com')
        if inertia is None:
            raise ModelError(
                f'body "{name}": inertia is missing (use zeros for a point mass, or the helpers '
                "point_mass, rod, disc, cylinder, box)"
            )
        planar = None
        if isinstance(inertia, PlanarInertia):
            planar = inertia.axis
            I = _axis_diag(inertia.axis, inertia.moment, 0, "planar inertia")
        elif isinstance(inertia, list | tuple) and len(inertia) == 3 and not isinstance(
            inertia[0], list | tuple
        ):
            d = as_vector(inertia, f'body "{name}" inertia')
            I = ((d[0], _ZERO, _ZERO), (_ZERO, d[1], _ZERO), (_ZERO, _ZERO, d[2]))
        else:
            I = as_matrix3(inertia, f'body "{name}" inertia')
        for i in range(3):
            for j in range(i + 1, 3):
                if se.expand(I[i][j] - I[j][i]) != 0:
                    raise ModelError(
                        f'body "{name}": inertia tensor is not symmetric '
                        f"(I[{i},{j}] = {I[i][j]} but I[{j},{i}] = {I[j][i]})"
                    )
        object.__setattr__(self, "name", name)
        object.__setattr__(self, "parent", parent)
        object.__setattr__(self, "joint", joint)
        object.__setattr__(self, "mass", m)
        object.__setattr__(self, "com", c)
        object.__setattr__(self, "inertia", I)
        object.__setattr__(self, "planar", planar)
        object.__setattr__(self, "section", bool(section))
        if not any(x.free_symbols for x in (m, *c, *(x for row in I for x in row))):
            # numbers only: checked now (with parameters: by the System, at their values)
            check_mass_data(self, {})

    @property
    def has_inertia(self) -> bool:
        """False for point masses and massless frames (inertia tensor identically zero)."""
        return any(x != 0 for row in self.inertia for x in row)


#: Tolerance of the physical checks of an inertia tensor: eigenvalues ≥ −1e-12·max(1, |I|)
#: and each principal moment at most the sum of the other two plus 1e-9 times the largest.
TRIANGLE_TOL = 1e-9


def mass_data_problem(body: Body, values: Mapping[str, float]) -> tuple[str, str] | None:
    """What is wrong with the mass data of ``body`` at the parameter ``values`` — as (key,
    message), the key ``mass``, ``com`` or ``inertia`` — or None when nothing is.

    The mass must be a finite number ≥ 0, the centre of mass a finite vector, and the inertia
    tensor one a rigid body can have: finite, symmetric, positive semi-definite, and its
    principal moments must satisfy the triangle inequality (each at most the sum of the other
    two: I₁ + I₂ − I₃ = 2∫x₃² dm ≥ 0). A massless body has no rotational inertia.
    """
    nums = values_at([body.mass, *body.com, *(x for row in body.inertia for x in row)], values)
    m, com, I = nums[0], nums[1:4], np.array(nums[4:]).reshape(3, 3)
    if not math.isfinite(m):
        return "mass", "the mass is not a finite real number at the parameter values"
    if m < 0:
        return "mass", f"mass must be a non-negative number, got {m:g}"
    if not all(math.isfinite(x) for x in com):
        return "com", ("the centre of mass is not a finite real vector at the parameter values "
                       f"({', '.join(f'{x:g}' for x in com)})")
    if not np.all(np.isfinite(I)):
        return "inertia", "inertia tensor has entries that are not finite real numbers"
    scale = max(1.0, float(np.abs(I).max()))
    if np.abs(I - I.T).max() > 1e-12 * scale:
        return "inertia", "inertia tensor is not symmetric"
    ev = np.linalg.eigvalsh(0.5 * (I + I.T))
    if ev.min() < -1e-12 * scale:
        return "inertia", ("inertia tensor is not positive semi-definite (eigenvalues "
                           f"{np.array2string(ev, precision=4)})")
    if (ev[2] > ev[0] + ev[1] + TRIANGLE_TOL * ev[2] and body.planar is None
            and not body.section):
        return "inertia", ("inertia tensor is not that of a rigid body: its largest principal "
                           f"moment {ev[2]:.6g} exceeds the sum of the other two "
                           f"({ev[0]:.6g} + {ev[1]:.6g}); each principal moment must be at most "
                           "the sum of the other two (the triangle inequality). A body that "
                           "moves in a plane may be given by its moment about the plane's "
                           "normal alone: inertia=jd.planar_inertia(I_zz, \"z\") in Python, "
                           "inertia = { planar = { moment = \"I_zz\", axis = \"z\" } } in a "
                           "model file (accepted where its angular velocity stays about that "
                           "axis)")
    if m == 0 and np.abs(I).max() > 0:
        return "inertia", "a massless body cannot have rotational inertia"
    return None


def check_mass_data(body: Body, values: Mapping[str, float]) -> None:
    """Raise a :class:`ModelError` naming the body when :func:`mass_data_problem` finds one."""
    problem = mass_data_problem(body, values)
    if problem:
        raise ModelError(f'body "{body.name}": {problem[1]}')


def check_values(bodies: Iterable[Body], values: Mapping[str, float]) -> None:
    """The checks of the model's numbers at other parameter ``values`` (e.g. overrides given on
    the command line): every body's mass data (:func:`check_mass_data`) and joint frame and axes
    (:func:`jourdain.model.joints.check_joint_values`), as at the default values."""
    for b in bodies:
        check_mass_data(b, values)
        try:
            check_joint_values(b.joint, values)
        except ModelError as exc:
            raise ModelError(f'{exc} (body "{b.name}")') from None


def _diag(a: object, b: object, c: object) -> Mat3:
    A, B, C = (as_expr(v, "inertia") for v in (a, b, c))
    return ((A, _ZERO, _ZERO), (_ZERO, B, _ZERO), (_ZERO, _ZERO, C))


@dataclass(frozen=True)
class PlanarInertia:
    """The inertia of a body that moves in a plane: its ``moment`` about the plane's normal
    ``axis`` (a body axis, x, y or z) alone, as the models of planar tools give it
    ((0, 0, I_zz)). See :func:`planar_inertia`."""

    moment: Expr
    axis: str


def planar_inertia(moment: object, axis: str = "z") -> PlanarInertia:
    """The inertia of a body that moves in a plane, given by its moment about the plane's
    normal ``axis`` alone: the tensor diag(0, 0, I) for ``"z"``, which no 3-D body has (the
    triangle inequality), accepted for a body whose angular velocity stays about that axis
    (the Newton–Euler stage checks it and refuses the model otherwise). Its motion is that of
    any body with this moment about the axis and the axis principal; the reaction moments
    across the plane at its joint (``Reactions.planar_moments``) are those of a body without
    products of inertia about the axis, which the model does not know, and are flagged."""
    if axis not in ("x", "y", "z"):
        raise ModelError(f"planar inertia: axis must be x, y or z, got {axis!r}")
    return PlanarInertia(as_expr(moment, "planar inertia moment"), axis)


def point_mass() -> Mat3:
    """Inertia tensor of a point mass: zero."""
    return _diag(0, 0, 0)


def rod(mass: object, length: object, axis: str = "x") -> Mat3:
    """Thin rod of given length along ``axis``, about its centre: m l²/12 across, 0 along."""
    m, l = as_expr(mass, "rod mass"), as_expr(length, "rod length")
    J = m * l**2 / 12
    return _axis_diag(axis, 0, J, "rod")


def disc(mass: object, radius: object, axis: str = "z") -> Mat3:
    """Thin disc with symmetry ``axis``: m r²/2 about the axis, m r²/4 across."""
    m, r = as_expr(mass, "disc mass"), as_expr(radius, "disc radius")
    return _axis_diag(axis, m * r**2 / 2, m * r**2 / 4, "disc")


def cylinder(mass: object, radius: object, length: object, axis: str = "z") -> Mat3:
    """Solid cylinder with symmetry ``axis``: m r²/2 along, m (3 r² + l²)/12 across."""
    m = as_expr(mass, "cylinder mass")
    r, l = as_expr(radius, "cylinder radius"), as_expr(length, "cylinder length")
    return _axis_diag(axis, m * r**2 / 2, m * (3 * r**2 + l**2) / 12, "cylinder")


def box(mass: object, a: object, b: object, c: object) -> Mat3:
    """Solid cuboid with edge lengths a, b, c along x, y, z."""
    m = as_expr(mass, "box mass")
    ea, eb, ec = (as_expr(v, "box edge") for v in (a, b, c))
    return _diag(m * (eb**2 + ec**2) / 12, m * (ea**2 + ec**2) / 12, m * (ea**2 + eb**2) / 12)


def _axis_diag(axis: str, along: object, across: object, what: str) -> Mat3:
    if axis not in ("x", "y", "z"):
        raise ModelError(f"{what}: axis must be x, y or z, got {axis!r}")
    d = [across, across, across]
    d["xyz".index(axis)] = along
    return _diag(*d)


class BodyGroup:
    """A body made of several of the method's bodies, such as an elastic body
    (:class:`jourdain.elastic.ElasticBody`: its reference frame, the nodes that carry its mass,
    the frames at which joints and forces attach). Listed among a :class:`~jourdain.System`'s
    bodies, it is expanded there into its coordinates (appended to ``y`` unless listed),
    bodies (in its place) and force elements (appended), by :meth:`expand`; the system keeps
    the group itself in ``System.groups`` for the stages that draw or report it."""

    name: str

    def expand(self) -> tuple[tuple[se.Symbol, ...], tuple[Body, ...], tuple[object, ...]]:
        """(coordinates, bodies, force elements) of the group."""
        raise NotImplementedError

    def internal_joints(self) -> tuple[str, ...]:
        """The joints inside the group (moved by its shared coordinates: no joint reactions
        of their own); its other joints, such as the one it hangs from, are ordinary."""
        return ()


def expand_groups(coordinates: tuple[se.Symbol, ...], bodies: Iterable[object],
                  forces: Iterable[object]
                  ) -> tuple[tuple[se.Symbol, ...], list[object], list[object],
                             tuple[BodyGroup, ...]]:
    """The coordinates, bodies and force elements of a system with its :class:`BodyGroup`\\ s
    expanded (coordinates of a group appended unless already listed, in the group's order)."""
    y = list(coordinates)
    out: list[object] = []
    extra: list[object] = []
    groups: list[BodyGroup] = []
    for b in bodies:
        if not isinstance(b, BodyGroup):
            out.append(b)
            continue
        cs, bs, fs = b.expand()
        y.extend(c for c in cs if c not in y)
        out.extend(bs)
        extra.extend(fs)
        groups.append(b)
    return tuple(y), out, [*forces, *extra], tuple(groups)
