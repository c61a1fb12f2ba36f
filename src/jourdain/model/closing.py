"""Closing joints: the joints that close kinematic loops of a tree (the data; their rows
Φ(y, t) = 0 are formed by the constraint stage, :mod:`jourdain.stages.constraints`).

A closed mechanism is a :class:`jourdain.System` whose ``closing`` joints each join a point of
body A to a point of body B (``"world"`` for either) of its spanning tree (the bodies and their
joints). Reactions: the virtual work of the constraint forces is ``δΦᵀ·λ``; for the rows
``p_A − p_B``, λ is the force that B exerts on A at the joint point (inertial components; −λ
acts on B), for a row ``a·(S_B u)`` the moment about ``a × S_B u`` on A.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import symengine as se

from ..errors import ModelError
from ..model.expressions import Expr, Vec3, as_expr, as_vector, axis_vector, free_names

#: the kinds of closing joint and the rows each contributes before dropping zero rows
KINDS = ("revolute", "spherical", "universal", "prismatic", "point_on_line", "point_on_plane",
         "constraint")
#: the joint's own degrees of freedom (for Grübler's count)
JOINT_DOF = {"revolute": 1, "spherical": 3, "universal": 2, "prismatic": 1,
             "point_on_line": 4, "point_on_plane": 5}
ZERO3: Vec3 = (se.Integer(0), se.Integer(0), se.Integer(0))


@dataclass(frozen=True)
class ClosingJoint:
    """A joint that closes a loop between ``body_a`` and ``body_b`` (either may be "world").

    Parameters
    ----------
    name : str
        Names the reactions (``<name>.Fx`` ...) and the messages.
    type : str
        One of :data:`KINDS`.
    body_a, body_b : str
        Body names of the tree, or ``"world"``.
    point_a, point_b : 3-vectors
        The joint point in each body's frame, from the body frame's origin (the joint point of
        its tree joint). Expressions of parameters.
    axis : axis
        The joint axis in A's frame (revolute, universal: A's cross axis, prismatic,
        point_on_line: the line, point_on_plane: the plane's normal). ``"x"``, ``"-z"`` or a
        3-vector (made a unit vector).
    axis_b : axis, optional
        The axis in B's frame (revolute: the same physical axis, default equal to ``axis``;
        universal: B's cross axis, default perpendicular: y when ``axis`` is x, else x).
    expressions : sequence, optional
        ``type="constraint"`` only: the scalar constraint expressions in the tree's
        coordinates, t and parameters.
    """

    name: str
    type: str
    body_a: str
    body_b: str
    point_a: Vec3
    point_b: Vec3
    axis: Vec3 | None
    axis_b: Vec3 | None
    expressions: tuple[Expr, ...]

    def __init__(self, name: str, type: str, body_a: str = "world", body_b: str = "world", *,
                 point_a: object = None, point_b: object = None, axis: object = None,
                 axis_b: object = None, expressions: Sequence[object] = ()) -> None:
        set_ = object.__setattr__
        if not isinstance(name, str) or not name.isidentifier():
            raise ModelError(f"closing joint: name {name!r} must be an identifier")
        where = f'closing joint "{name}"'
        if type not in KINDS:
            raise ModelError(f"{where}: unknown type {type!r}; expected one of {', '.join(KINDS)}")
        set_(self, "name", name)
        set_(self, "type", type)
        set_(self, "body_a", str(body_a))
        set_(self, "body_b", str(body_b))
        if type == "constraint":
            if not expressions:
                raise ModelError(f"{where}: a constraint needs at least one expression")
            if any(v is not None for v in (point_a, point_b, axis, axis_b)):
                raise ModelError(f"{where}: a constraint takes expressions only (no points or "
                                 "axes)")
            set_(self, "expressions", tuple(as_expr(e, f"{where} expression {i + 1}")
                                            for i, e in enumerate(expressions)))
            set_(self, "point_a", ZERO3)
            set_(self, "point_b", ZERO3)
            set_(self, "axis", None)
            set_(self, "axis_b", None)
            return
        if expressions:
            raise ModelError(f"{where}: expressions belong to type \"constraint\" only")
        if body_a == body_b:
            raise ModelError(f'{where}: body_a and body_b are both "{body_a}"')
        set_(self, "expressions", ())
        set_(self, "point_a", ZERO3 if point_a is None else
             as_vector(point_a, f"{where} point_a"))
        set_(self, "point_b", ZERO3 if point_b is None else
             as_vector(point_b, f"{where} point_b"))
        needs_axis = type not in ("spherical",)
        if needs_axis:
            ax = axis_vector("z" if axis is None else axis, f"{where} axis")
        else:
            if axis is not None or axis_b is not None:
                raise ModelError(f"{where}: a spherical joint has no axis")
            ax = None
        set_(self, "axis", ax)
        if type == "revolute":
            set_(self, "axis_b", ax if axis_b is None else axis_vector(axis_b, f"{where} axis_b"))
        elif type == "universal":
            default = "y" if ax == (1, 0, 0) else "x"
            set_(self, "axis_b", axis_vector(default if axis_b is None else axis_b,
                                             f"{where} axis_b"))
        else:
            if axis_b is not None:
                raise ModelError(f"{where}: axis_b belongs to revolute and universal joints")
            set_(self, "axis_b", None)

    @property
    def joint_dof(self) -> int | None:
        """Degrees of freedom the joint allows (None for a general constraint)."""
        return JOINT_DOF.get(self.type)

    def symbols(self) -> set[str]:
        """Names of the symbols in its geometry or expressions."""
        exprs = [*self.expressions, *self.point_a, *self.point_b, *(self.axis or ()),
                 *(self.axis_b or ())]
        return free_names(exprs)


def grubler(n_bodies: int, tree_joint_dofs: Sequence[int], closing: Sequence[ClosingJoint]
            ) -> int:
    """Grübler–Kutzbach count ``6·n − Σ(6 − f_j)`` over the tree and closing joints (a
    general constraint, which has no joint count, takes away one per expression)."""
    total = 6 * n_bodies - sum(6 - f for f in tree_joint_dofs)
    for cj in closing:
        if cj.joint_dof is None:
            total -= len(cj.expressions)
        else:
            total -= 6 - cj.joint_dof
    return total


__all__ = ["JOINT_DOF", "KINDS", "ZERO3", "ClosingJoint", "grubler"]
