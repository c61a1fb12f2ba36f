"""Joints: how a body's frame hangs from its parent's frame.

Every joint is a sequence of *elementary transformations* applied one after the other, starting
at the joint frame on the parent (the parent's body frame moved by ``position`` and turned by
``orientation``): a rotation :class:`Rot` about an axis by an angle, or a translation
:class:`Trans` by a vector, each an expression in the coordinates ``y``, the parameters and the
time ``t``. The frame reached at the end is the child body's frame. Standard joints (revolute,
prismatic, ...) are just named sequences; a :func:`General` joint takes any sequence, so prescribed
(rheonomic) motions such as a disc turning at ``Omega*t`` are written the same way.

Axes are given in the frame *before* the transformation (the current frame), as in Neweul-M².
An axis is ``"x"``, ``"y"``, ``"z"`` (or ``"-x"``, ...) or a 3-vector that gives its direction:
a vector is made a unit vector (``(1, 1, 0)`` is the axis ``(√2/2, √2/2, 0)``; see
:func:`jourdain.model.expressions.unit_axis` for vectors with parameters) and the zero vector
is refused, the same rule as in model files. Axes may depend on parameters only.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import symengine as se

from ..errors import ModelError
from .expressions import (
    Expr,
    Mat3,
    Vec3,
    as_expr,
    as_matrix3,
    as_vector,
    axis_vector,
    values_at,
)

IDENTITY: Mat3 = (
    (se.Integer(1), se.Integer(0), se.Integer(0)),
    (se.Integer(0), se.Integer(1), se.Integer(0)),
    (se.Integer(0), se.Integer(0), se.Integer(1)),
)


@dataclass(frozen=True)
class Rot:
    """Elementary rotation about ``axis`` (current frame) by ``angle`` (rad).

    ``axis`` is ``"x"``, ``"y"``, ``"z"`` (optionally signed) or a nonzero 3-vector, stored as
    the unit vector along it.
    """

    axis: Vec3
    angle: Expr

    def __init__(self, axis: object, angle: object) -> None:
        object.__setattr__(self, "axis", axis_vector(axis, "Rot axis"))
        object.__setattr__(self, "angle", as_expr(angle, "Rot angle"))

    @property
    def parameter(self) -> Expr:
        return self.angle


@dataclass(frozen=True)
class Trans:
    """Elementary translation by ``distance`` along ``axis``, or by a 3-vector ``vector``.

    ``Trans("x", s)`` moves by ``s`` along the current x axis (a vector ``axis`` is made a unit
    vector, so ``s`` is the distance); ``Trans(vector=(a, b, c))`` by an arbitrary vector in the
    current frame (each component may depend on y and t).
    """

    axis: Vec3 | None
    distance: Expr | None
    vector: Vec3

    def __init__(
        self, axis: object = None, distance: object = None, *, vector: object = None
    ) -> None:
        if vector is not None:
            if axis is not None or distance is not None:
                raise ModelError("Trans: give either axis and distance, or vector, not both")
            object.__setattr__(self, "axis", None)
            object.__setattr__(self, "distance", None)
            object.__setattr__(self, "vector", as_vector(vector, "Trans vector"))
            return
        if axis is None or distance is None:
            raise ModelError("Trans: give axis and distance, or vector")
        u = axis_vector(axis, "Trans axis")
        s = as_expr(distance, "Trans distance")
        object.__setattr__(self, "axis", u)
        object.__setattr__(self, "distance", s)
        object.__setattr__(self, "vector", tuple(c * s for c in u))

    @property
    def parameter(self) -> Expr | None:
        return self.distance


Step = Rot | Trans


@dataclass(frozen=True)
class Joint:
    """A joint: the transformation from the parent's body frame to the child's body frame.

    Attributes
    ----------
    name : str
        Unique name, used in messages and for the reaction forces (``hinge1.F_x``).
    kind : str
        ``revolute``, ``prismatic``, ``cylindrical``, ``universal``, ``spherical``, ``planar``,
        ``free``, ``fixed`` or ``general``.
    coordinates : tuple of Symbol
        The generalized coordinates this joint drives (each may be driven by one joint only).
    position : 3-tuple
        Joint point in the parent's body frame (from the parent frame's origin).
    orientation : 3x3 tuple
        Joint frame axes expressed in the parent's body frame (constant).
    steps : tuple of Rot/Trans
        The elementary transformations, applied in order from the joint frame.
    constrained : tuple or None
        For general joints: user-given constrained directions (reactions issue).
    """

    name: str
    kind: str
    coordinates: tuple[se.Symbol, ...]
    steps: tuple[Step, ...]
    position: Vec3 = field(default=(se.Integer(0),) * 3)
    orientation: Mat3 = IDENTITY
    constrained: tuple | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.isidentifier():
            raise ModelError(f"joint name {self.name!r} must be an identifier")


def _frame(name: str, position: object, orientation: object) -> tuple[Vec3, Mat3]:
    pos = as_vector((0, 0, 0) if position is None else position, f'joint "{name}" position')
    if orientation is None:
        ori = IDENTITY
    elif isinstance(orientation, list | tuple) and orientation and isinstance(orientation[0], Rot):
        ori = IDENTITY
        for r in orientation:
            ori = _matmul(ori, rotation_matrix(r.axis, r.angle))
    else:
        ori = as_matrix3(orientation, f'joint "{name}" orientation')
        if not any(x.free_symbols for row in ori for x in row):
            why = orientation_problem(ori, {})
            if why:
                raise ModelError(f'joint "{name}": the orientation {why}')
    for v in (*pos, *(x for row in ori for x in row)):
        if "t" in {str(s) for s in v.free_symbols}:
            raise ModelError(
                f'joint "{name}": position and orientation must be constant; '
                "use a General joint with Rot/Trans steps for prescribed motion"
            )
    return pos, ori


#: Tolerance of the check that a joint's orientation A is a rotation: |AᵀA − E| entrywise. A
#: matrix of decimals rounded to 4 digits (0.7071) is refused: write sqrt(2)/2, or rotations.
ROTATION_TOL = 1e-9


def orientation_problem(orientation: Mat3, values: Mapping[str, float]) -> str | None:
    """Why the 3×3 ``orientation`` is not a rotation matrix at the parameter ``values`` (None
    when it is one): it must be finite, orthonormal (AᵀA = E to :data:`ROTATION_TOL`) and have
    determinant +1 (not a reflection). The text completes "the orientation ..."."""
    A = np.array(values_at([x for row in orientation for x in row], values)).reshape(3, 3)
    if not np.all(np.isfinite(A)):
        return "has entries that are not finite real numbers at the parameter values"
    err = float(np.abs(A.T @ A - np.eye(3)).max())
    if err > ROTATION_TOL:
        rows = "; ".join(", ".join(f"{v:.6g}" for v in r) for r in A)
        return (f"[{rows}] is not a rotation matrix: its columns are not orthonormal (AᵀA "
                f"differs from the identity by {err:.3g}); give a rotation (orthonormal, "
                "determinant +1), e.g. as a list of rotations about axes")
    det = float(np.linalg.det(A))
    if det < 0:
        return (f"is a reflection (determinant {det:.3g}), not a rotation: a rotation has "
                "determinant +1")
    return None


def joint_problem(joint: Joint, values: Mapping[str, float]) -> tuple[str, str] | None:
    """What is wrong with ``joint`` at the parameter ``values``, as (key, message) with the key
    ``position``, ``orientation`` or ``axis``; None when nothing is. The position must be
    finite, the orientation a rotation and the axes of the steps finite (an axis u/|u| with
    parameters is undefined where u = 0)."""
    pos = values_at(joint.position, values)
    if not all(np.isfinite(pos)):
        return "position", ("the position is not a finite real vector at the parameter values "
                            f"({', '.join(f'{v:g}' for v in pos)})")
    why = orientation_problem(joint.orientation, values)
    if why:
        return "orientation", f"the orientation {why}"
    for k, step in enumerate(joint.steps):
        if step.axis is not None and any(c.free_symbols for c in step.axis):
            if not all(np.isfinite(values_at(step.axis, values))):
                which = "the axis" if len(joint.steps) == 1 else f"the axis of step {k}"
                return "axis", f"{which} is the zero vector at the parameter values"
    return None


def check_joint_values(joint: Joint, values: Mapping[str, float]) -> None:
    """Raise a :class:`ModelError` naming the joint when :func:`joint_problem` finds one."""
    problem = joint_problem(joint, values)
    if problem:
        raise ModelError(f'joint "{joint.name}": {problem[1]}')


def _coord(name: str, c: object, what: str = "coordinate") -> se.Symbol:
    e = as_expr(c, f'joint "{name}" {what}')
    if not isinstance(e, se.Symbol):
        raise ModelError(
            f'joint "{name}": {what} must be a symbol, got {e}; use a General joint for expressions'
        )
    return e


def _coords(name: str, cs: Sequence[object], n: int) -> tuple[se.Symbol, ...]:
    if isinstance(cs, str | se.Basic) or len(cs) != n:
        raise ModelError(f'joint "{name}": expected {n} coordinates, got {cs!r}')
    return tuple(_coord(name, c) for c in cs)


def Revolute(name: str, coordinate: object, axis: object = "z", *, position: object = None,
             orientation: object = None) -> Joint:
    """Revolute (hinge) joint: rotation by ``coordinate`` about ``axis`` of the joint frame
    (``"x"``, ``"y"``, ``"z"`` or a nonzero 3-vector, normalized)."""
    q = _coord(name, coordinate)
    u = axis_vector(axis, f'joint "{name}" axis')
    pos, ori = _frame(name, position, orientation)
    return Joint(name, "revolute", (q,), (Rot(u, q),), pos, ori)


def Prismatic(name: str, coordinate: object, axis: object = "x", *, position: object = None,
              orientation: object = None) -> Joint:
    """Prismatic (slider) joint: translation by ``coordinate`` along ``axis`` (``"x"``, ``"y"``,
    ``"z"`` or a nonzero 3-vector, normalized, so ``coordinate`` is the distance)."""
    q = _coord(name, coordinate)
    u = axis_vector(axis, f'joint "{name}" axis')
    pos, ori = _frame(name, position, orientation)
    return Joint(name, "prismatic", (q,), (Trans(u, q),), pos, ori)


def Cylindrical(name: str, coordinates: Sequence[object], axis: object = "z", *,
                position: object = None, orientation: object = None) -> Joint:
    """Cylindrical joint: rotation ``coordinates[0]`` about and translation ``coordinates[1]``
    along the same ``axis`` (normalized, as for :func:`Revolute`)."""
    phi, s = _coords(name, coordinates, 2)
    u = axis_vector(axis, f'joint "{name}" axis')
    pos, ori = _frame(name, position, orientation)
    return Joint(name, "cylindrical", (phi, s), (Trans(u, s), Rot(u, phi)), pos, ori)


def Universal(name: str, coordinates: Sequence[object], axes: Sequence[object] = ("x", "y"), *,
              position: object = None, orientation: object = None) -> Joint:
    """Universal (Cardan) joint: rotation about ``axes[0]``, then about the turned ``axes[1]``
    (each normalized, as for :func:`Revolute`)."""
    a, b = _coords(name, coordinates, 2)
    if len(axes) != 2:
        raise ModelError(f'joint "{name}": a universal joint needs two axes')
    u1 = axis_vector(axes[0], f'joint "{name}" axes[0]')
    u2 = axis_vector(axes[1], f'joint "{name}" axes[1]')
    if not any((x - y) != 0 for x, y in zip(u1, u2, strict=True)) or _parallel(u1, u2):
        raise ModelError(f'joint "{name}": the two axes of a universal joint must differ')
    pos, ori = _frame(name, position, orientation)
    return Joint(name, "universal", (a, b), (Rot(u1, a), Rot(u2, b)), pos, ori)


_SEQUENCES = {"xyz", "xzy", "yxz", "yzx", "zxy", "zyx", "zxz", "xyx", "xzx", "yxy", "yzy", "zyz"}


def _rotations(name: str, sequence: str, angles: Sequence[se.Symbol]) -> tuple[Rot, ...]:
    seq = sequence.lower()
    if seq not in _SEQUENCES:
        raise ModelError(
            f'joint "{name}": rotation sequence {sequence!r} is not one of '
            f"{', '.join(sorted(_SEQUENCES))}"
        )
    return tuple(Rot(ax, a) for ax, a in zip(seq, angles, strict=True))


def Spherical(name: str, coordinates: Sequence[object], sequence: str = "xyz", *,
              position: object = None, orientation: object = None) -> Joint:
    """Spherical (ball) joint described by three successive rotations.

    ``sequence`` is ``"xyz"`` (Cardan / Tait–Bryan angles, the default) or a proper Euler
    sequence such as ``"zxz"``.
    """
    angles = _coords(name, coordinates, 3)
    pos, ori = _frame(name, position, orientation)
    return Joint(name, "spherical", angles, _rotations(name, sequence, angles), pos, ori)


def Planar(name: str, coordinates: Sequence[object], normal: object = "z", *,
           position: object = None, orientation: object = None) -> Joint:
    """Planar joint: translations ``coordinates[0:2]`` in the plane normal to ``normal``
    (a coordinate axis), then rotation ``coordinates[2]`` about the normal."""
    x, y, phi = _coords(name, coordinates, 3)
    if not isinstance(normal, str) or normal.lstrip("+-").lower() not in ("x", "y", "z"):
        raise ModelError(f'joint "{name}": planar normal must be one of x, y, z, got {normal!r}')
    n = normal.lstrip("+-").lower()
    a1, a2 = {"x": ("y", "z"), "y": ("z", "x"), "z": ("x", "y")}[n]
    pos, ori = _frame(name, position, orientation)
    steps = (Trans(a1, x), Trans(a2, y), Rot(n, phi))
    return Joint(name, "planar", (x, y, phi), steps, pos, ori)


def Free(name: str, coordinates: Sequence[object], sequence: str = "xyz", *,
         position: object = None, orientation: object = None) -> Joint:
    """Free joint (6 DOF): translations along x, y, z of the joint frame, then three rotations."""
    cs = _coords(name, coordinates, 6)
    pos, ori = _frame(name, position, orientation)
    steps: tuple[Rot | Trans, ...] = (Trans("x", cs[0]), Trans("y", cs[1]), Trans("z", cs[2]),
                                      *_rotations(name, sequence, cs[3:]))
    return Joint(name, "free", cs, steps, pos, ori)


def Fixed(name: str, *, position: object = None, orientation: object = None) -> Joint:
    """Fixed (welded) joint: the child frame is the joint frame."""
    pos, ori = _frame(name, position, orientation)
    return Joint(name, "fixed", (), (), pos, ori)


def General(name: str, steps: Sequence[Step], *, coordinates: Sequence[object] = (),
            position: object = None, orientation: object = None,
            constrained: Sequence | None = None) -> Joint:
    """A joint given as a sequence of elementary transformations.

    Angles and distances are expressions in the coordinates, the parameters and ``t``. A
    prescribed rotation is ``General("drive", [Rot("z", Omega*t)])``; a base excited by
    ``a*sin(w*t)`` is ``General("base", [Trans("y", a*sin(w*t))])``. ``coordinates`` lists those
    coordinates this joint *drives* (optional; used for the check that no coordinate is driven
    twice). ``constrained`` optionally gives the constrained directions for the reactions.
    """
    steps = tuple(steps)
    for k, s in enumerate(steps):
        if not isinstance(s, Rot | Trans):
            raise ModelError(
                f'joint "{name}": step {k} must be Rot(...) or Trans(...), got {s!r}'
            )
    pos, ori = _frame(name, position, orientation)
    cs = tuple(_coord(name, c) for c in coordinates)
    return Joint(name, "general", cs, steps, pos, ori,
                 None if constrained is None else tuple(constrained))


def _parallel(u: Vec3, v: Vec3) -> bool:
    cross = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    return all(se.expand(c) == 0 for c in cross)


def rotation_matrix(u: Vec3, angle: Expr) -> Mat3:
    """Rotation matrix of the turn by ``angle`` about the unit axis ``u``: v_before = A·v_after."""
    c, s = se.cos(angle), se.sin(angle)
    one, zero = se.Integer(1), se.Integer(0)
    if u == (one, zero, zero):
        return ((one, zero, zero), (zero, c, -s), (zero, s, c))
    if u == (zero, one, zero):
        return ((c, zero, s), (zero, one, zero), (-s, zero, c))
    if u == (zero, zero, one):
        return ((c, -s, zero), (s, c, zero), (zero, zero, one))
    # Rodrigues: A = c E + (1 - c) u u^T + s ũ
    x, y, z = u
    C = 1 - c
    return (
        (c + x * x * C, x * y * C - z * s, x * z * C + y * s),
        (y * x * C + z * s, c + y * y * C, y * z * C - x * s),
        (z * x * C - y * s, z * y * C + x * s, c + z * z * C),
    )


def _matmul(A: Mat3, B: Mat3) -> Mat3:
    return tuple(
        tuple(sum((A[i][k] * B[k][j] for k in range(3)), se.Integer(0)) for j in range(3))
        for i in range(3)
    )  # type: ignore[return-value]
