"""Closing joints: the holonomic constraints Φ(z, t) = 0 that close kinematic loops.

A loop system is a spanning tree (a :class:`jourdain.System`, all its coordinates ``z``) plus
closing joints, each joining a point of body A to a point of body B (``"world"`` for either).
Its constraint equations are written with the tree's own kinematics (METHOD.md §1): the body
frames' origins ``r_O`` and rotations ``S`` as expressions of ``z`` and ``t``. With
``p_A = r_O,A + S_A·point_a`` and ``p_B = r_O,B + S_B·point_b`` (inertial) and
``a = S_A·axis`` (the joint axis fixed in A):

==================  =========================================================================
type                scalar equations (rows of Φ)
==================  =========================================================================
``spherical``       ``p_A − p_B`` (3: x, y, z, inertial)
``revolute``        ``p_A − p_B`` (3) and ``a·(S_B·u_1)``, ``a·(S_B·u_2)`` with ``u_1, u_2``
                    perpendicular to ``axis_b`` (the same axis in B's frame)
``universal``       ``p_A − p_B`` (3) and ``a·(S_B·axis_b)`` (the two cross axes stay square)
``prismatic``       ``(p_B − p_A)·(S_A·n_1)``, ``(p_B − p_A)·(S_A·n_2)`` (``n_i ⊥ axis``) and
                    the relative rotation locked: ``(S_A e_x)·(S_B e_y)``,
                    ``(S_A e_y)·(S_B e_z)``, ``(S_A e_z)·(S_B e_x)`` (frames aligned at
                    assembly)
``point_on_line``   ``(p_B − p_A)·(S_A·n_1)``, ``(p_B − p_A)·(S_A·n_2)``: p_B on the line
                    through p_A along ``axis``
``point_on_plane``  ``(p_B − p_A)·(S_A·axis)``: p_B in the plane through p_A normal to ``axis``
``constraint``      the given expressions of z, t and parameters
==================  =========================================================================

Rows that vanish identically (the z-row and the two tilt rows of a revolute closing joint
about z in a planar model) are dropped when the rows are built (:func:`constraint_rows`);
rows that are dependent only numerically are found by the rank of Φ_z at the initial
configuration (:mod:`jourdain.loops.closed_loop`).

Reactions: the virtual work of the constraint forces is ``δΦᵀ·λ``. For the rows
``p_A − p_B``, λ is therefore the force that B exerts on A at the joint point (inertial
components; −λ acts on B). For a row ``a·(S_B u)`` it is the moment about ``a × S_B u`` on A.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import symengine as se

from ..errors import ModelError
from ..model.expressions import Expr, Vec3, as_expr, as_vector, axis_vector, free_names
from ..stages.kinematics import _cross, _dot, _mv

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


def _sub(a: Vec3, b: Vec3) -> Vec3:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def perpendiculars(u: Vec3) -> tuple[Vec3, Vec3]:
    """Two unit vectors perpendicular to the unit axis ``u`` and to each other (``u``'s
    components are numbers or parameter expressions: the choice avoids dividing by a
    component that may be zero by picking the coordinate axis least aligned with ``u``
    at the symbolic level of exact axes)."""
    e = (se.Integer(1), se.Integer(0), se.Integer(0))
    if u[1] == 0 and u[2] == 0:
        e = (se.Integer(0), se.Integer(1), se.Integer(0))
    w = _cross(u, e)
    n = se.sqrt(_dot(w, w))
    n1 = tuple(c / n for c in w)
    n2 = _cross(u, n1)
    return n1, n2


_IDENT = ((se.Integer(1), se.Integer(0), se.Integer(0)),
          (se.Integer(0), se.Integer(1), se.Integer(0)),
          (se.Integer(0), se.Integer(0), se.Integer(1)))


@dataclass(frozen=True)
class ConstraintRow:
    """One scalar constraint equation Φ_i(z, t) = 0 of a closing joint.

    ``label``: its name (``hinge.x``, ``hinge.tilt1``, ``c.1``); ``kind``: ``force`` (λ is a
    force on A, inertial ``direction``), ``moment`` (a moment on A about the inertial
    ``direction``) or ``generic``; ``direction``: 3 expressions, or None.
    """

    joint: str
    label: str
    expr: Expr
    kind: str
    direction: Vec3 | None


def constraint_rows(kin: object, closing: Sequence[ClosingJoint]) -> list[ConstraintRow]:
    """The scalar rows Φ_i of the closing joints from the tree's kinematics ``kin``
    (:func:`jourdain.stages.kinematics.kinematics`), identically zero rows dropped."""
    def frame(body: str) -> tuple[Vec3, tuple]:
        if body == "world":
            return ZERO3, _IDENT
        bk = kin[body]  # type: ignore[index]
        r = tuple(bk.r_O.rows[i][0] for i in range(3))
        return r, bk.S.rows

    rows: list[ConstraintRow] = []
    for cj in closing:
        n = cj.name
        if cj.type == "constraint":
            for i, e in enumerate(cj.expressions):
                rows.append(ConstraintRow(n, f"{n}.{i + 1}", e, "generic", None))
            continue
        rA, SA = frame(cj.body_a)
        rB, SB = frame(cj.body_b)
        pA = tuple(rA[i] + _mv(SA, cj.point_a)[i] for i in range(3))
        pB = tuple(rB[i] + _mv(SB, cj.point_b)[i] for i in range(3))
        ex = _IDENT
        if cj.type in ("spherical", "revolute", "universal"):
            d = _sub(pA, pB)
            for i, c in enumerate("xyz"):
                rows.append(ConstraintRow(n, f"{n}.F{c}", d[i], "force", ex[i]))
        if cj.type == "revolute":
            a = _mv(SA, cj.axis)  # type: ignore[arg-type]
            for k, u in enumerate(perpendiculars(cj.axis_b), 1):  # type: ignore[arg-type]
                b = _mv(SB, u)
                rows.append(ConstraintRow(n, f"{n}.M{k}", _dot(a, b), "moment", _cross(a, b)))
        elif cj.type == "universal":
            a = _mv(SA, cj.axis)  # type: ignore[arg-type]
            b = _mv(SB, cj.axis_b)  # type: ignore[arg-type]
            rows.append(ConstraintRow(n, f"{n}.M", _dot(a, b), "moment", _cross(a, b)))
        elif cj.type in ("prismatic", "point_on_line", "point_on_plane"):
            d = _sub(pB, pA)
            normals = ((cj.axis,) if cj.type == "point_on_plane"
                       else perpendiculars(cj.axis))  # type: ignore[arg-type]
            for k, nv in enumerate(normals, 1):
                w = _mv(SA, nv)  # type: ignore[arg-type]
                # δΦ = δ(p_B − p_A)·w + ...: the force on A along w is −λ
                rows.append(ConstraintRow(n, f"{n}.N{k}" if len(normals) > 1 else f"{n}.N",
                                          _dot(d, w), "force", tuple(-c for c in w)))
            if cj.type == "prismatic":
                for lab, i, j in (("Mz", 0, 1), ("Mx", 1, 2), ("My", 2, 0)):
                    a = _mv(SA, ex[i])
                    b = _mv(SB, ex[j])
                    rows.append(ConstraintRow(n, f"{n}.{lab}", _dot(a, b), "moment",
                                              _cross(a, b)))
    return [r for r in rows if r.expr != 0]


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


__all__ = ["KINDS", "ClosingJoint", "ConstraintRow", "constraint_rows", "grubler"]
