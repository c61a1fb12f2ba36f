"""The constraint stage (METHOD.md §7, ``docs/method.md`` "Closed loops"): the rows that tie the
tree's coordinates together, between kinematics and projection.

Cut at its closing joints, a closed mechanism is a tree in the coordinates ``y`` (f of them)
whose closing joints impose r scalar rows

    Φ(y, t) = 0,     Φ̇ = Φ_y·ẏ + Φ_t = 0,     Φ̈ = Φ_y·ÿ + c = 0

with ``c = (Φ_y·ẏ)_y·ẏ + 2·Φ_yt·ẏ + Φ_tt`` (the part of Φ̈ without ÿ). Holonomic rows are
velocity rows ``A·ẏ + a = 0`` with ``A = Φ_y``, ``a = Φ_t`` (:attr:`Constraints.A`,
:attr:`Constraints.a`); velocity constraints (rolling without slip) are rows in the same place.
The constrained directions of each row, as wrenches on the bodies in the rows of M̄, are the
columns ``Q̄_c`` that extend the tree's Q̄ (``Q̄ = [Q̄_tree, Q̄_c]``), and by the virtual work of
the constraint forces ``J̄ᵀ·Q̄_c = Φ_yᵀ``: a row ``p_A − p_B`` is the force λ·e on A at p_A and
−λ·e on B at p_B, a moment row the moment λ·(a × S_B u) on A and its opposite on B.

The velocity map onto the admissible motions, ``ẏ = L·z + l`` with ``Φ_y·L = 0`` and
``Φ_y·l + Φ_t = 0``, depends on the choice of independent coordinates (coordinate
partitioning, done in numbers at a configuration): it lives in the per-run workspace
(:class:`jourdain.loops.evaluator.LoopEvaluator`), never on the system. With it the closed
system's global Jacobian is ``L̄ = J̄·L`` and the projection with ``L̄ᵀ`` gives ``M = LᵀM_tree·L``,
``k = Lᵀ(k_tree + M_tree·γ)``, ``q = Lᵀq_tree`` (``ÿ = L·ż + γ``).

A tree has zero rows: every matrix here has r = 0 rows and ``L = E``, ``l = 0``.

=======================  ===================================================================
field                    shape, meaning
=======================  ===================================================================
``rows``                 r :class:`ConstraintRow`: joint, label (``closure.Fx``), kind
``Phi``                  r×1   Φ(y, t)
``Phi_y``                r×f   ∂Φ/∂y (= A)
``Phi_t``                r×1   ∂Φ/∂t (= a)
``c``                    r×1   Φ̈ at ÿ = 0
``Q_bar``                6p×r  constrained directions of the rows (a ``generic`` row of
                               expressions has none: its column is zero, its reaction is the
                               generalized force Φ_yᵀλ only)
=======================  ===================================================================

Closing joint rows, with ``p_A = r_O,A + S_A·point_a``, ``p_B = r_O,B + S_B·point_b``
(inertial) and ``a = S_A·axis`` (the joint axis fixed in A):

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
``constraint``      the given expressions of y, t and parameters
==================  =========================================================================

Rows that vanish identically (the z-row and the two tilt rows of a revolute closing joint about
z in a planar model) are dropped here; rows dependent only numerically are found by the rank of
Φ_y at the initial configuration (:mod:`jourdain.loops.partitioning`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import symengine as se

from ..model.closing import ZERO3, ClosingJoint
from ..model.expressions import Expr, Vec3
from ..model.forces import rate
from ..symbolic import SymMatrix
from .contact_rows import contact_rows
from .kinematics import Kinematics, _cross, _dot, _mv
from .rows import ConstraintRow

if TYPE_CHECKING:
    from ..model.system import System


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


def constraint_rows(kin: Kinematics, closing: Sequence[ClosingJoint]) -> list[ConstraintRow]:
    """The scalar rows Φ_i of the closing joints from the tree's kinematics ``kin``
    (:func:`jourdain.stages.kinematics.kinematics`), identically zero rows dropped."""
    def frame(body: str) -> tuple[Vec3, tuple]:
        if body == "world":
            return ZERO3, _IDENT
        bk = kin[body]
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
        at: dict[str, Any] = {"body_a": cj.body_a, "body_b": cj.body_b, "p_a": pA, "p_b": pB}
        ex = _IDENT
        if cj.type in ("spherical", "revolute", "universal"):
            d = _sub(pA, pB)
            for i, c in enumerate("xyz"):
                rows.append(ConstraintRow(n, f"{n}.F{c}", d[i], "force", ex[i], **at))
        if cj.type == "revolute":
            a = _mv(SA, cj.axis)  # type: ignore[arg-type]
            for k, u in enumerate(perpendiculars(cj.axis_b), 1):  # type: ignore[arg-type]
                b = _mv(SB, u)
                rows.append(ConstraintRow(n, f"{n}.M{k}", _dot(a, b), "moment", _cross(a, b),
                                          **at))
        elif cj.type == "universal":
            a = _mv(SA, cj.axis)  # type: ignore[arg-type]
            b = _mv(SB, cj.axis_b)  # type: ignore[arg-type]
            rows.append(ConstraintRow(n, f"{n}.M", _dot(a, b), "moment", _cross(a, b), **at))
        elif cj.type in ("prismatic", "point_on_line", "point_on_plane"):
            d = _sub(pB, pA)
            normals = ((cj.axis,) if cj.type == "point_on_plane"
                       else perpendiculars(cj.axis))  # type: ignore[arg-type]
            # δΦ = (δp_B − δp_A)·w + (p_B − p_A)·δw, w fixed in A: the force −λ·w acts on A
            # at the point of A that coincides with p_B (its moment about p_A is the second
            # term), and +λ·w on B at p_B
            at_b = {**at, "p_a": pB}
            for k, nv in enumerate(normals, 1):
                w = _mv(SA, nv)  # type: ignore[arg-type]
                rows.append(ConstraintRow(n, f"{n}.N{k}" if len(normals) > 1 else f"{n}.N",
                                          _dot(d, w), "force", tuple(-c for c in w), **at_b))
            if cj.type == "prismatic":
                for lab, i, j in (("Mz", 0, 1), ("Mx", 1, 2), ("My", 2, 0)):
                    a = _mv(SA, ex[i])
                    b = _mv(SB, ex[j])
                    rows.append(ConstraintRow(n, f"{n}.{lab}", _dot(a, b), "moment",
                                              _cross(a, b), **at))
    return [r for r in rows if r.expr != 0]


@dataclass(frozen=True)
class Constraints:
    """Result of :func:`constraints`: the constraint rows of a system (r = 0 for a tree).

    Holonomic rows first (``r_h`` of them: the closing joints', then the contacts' touching
    rows), then the velocity rows of contacts. ``Phi`` (r_h×1), ``Phi_y`` (r_h×f), ``Phi_t``
    (r_h×1) of the holonomic rows; every row at the velocity level ``A·ẏ + a = 0``: ``A``
    (r×f, ``Φ_y`` in the holonomic rows), ``a`` (r×1), ``c`` (r×1) its time derivative at
    ÿ = 0 (``A·ÿ + c = 0``), ``Q_bar`` (6p×r) the rows' constrained directions in the rows of
    M̄ (``J̄ᵀ·Q̄_c = Aᵀ``).
    """

    kinematics: Kinematics
    rows: tuple[ConstraintRow, ...]
    Phi: SymMatrix
    Phi_y: SymMatrix
    Phi_t: SymMatrix
    c: SymMatrix
    Q_bar: SymMatrix
    A: SymMatrix
    a: SymMatrix

    @property
    def system(self) -> System:
        """The system whose kinematics the rows are written with (the tree)."""
        return self.kinematics.system

    @property
    def labels(self) -> list[str]:
        """The rows' names, ``<closing joint>.<component>``, ``<contact>.N``, ..."""
        return [r.label for r in self.rows]

    @property
    def r(self) -> int:
        """Number of rows (before the rank test at a configuration)."""
        return len(self.rows)

    @property
    def r_h(self) -> int:
        """Number of holonomic rows (the rows of Φ)."""
        return sum(1 for r in self.rows if r.holonomic)


def _wrench_columns(kin: Kinematics, rows: Sequence[ConstraintRow]) -> SymMatrix:
    """Q̄_c: per row, the wrench of a unit multiplier in the rows of M̄ (forces inertial in the
    translational rows, torques about the centre of mass in body axes in the rotational rows)."""
    system = kin.system
    names = system.body_names
    p = len(names)
    zero = se.Integer(0)
    cols: list[list[Expr]] = []
    for row in rows:
        col = [zero] * (6 * p)
        if row.kind != "generic":
            e = row.direction
            assert e is not None
            for body, sign, point in ((row.body_a, 1, row.p_a), (row.body_b, -1, row.p_b)):
                if body == "world":
                    continue
                i = names.index(body)
                bk = kin.bodies[i]
                S = bk.S.rows
                St = tuple(tuple(S[j][k] for j in range(3)) for k in range(3))
                if row.kind == "force":
                    assert point is not None
                    arm = _sub(point, tuple(bk.r.rows[k][0] for k in range(3)))
                    torque = _cross(arm, e)
                    for k in range(3):
                        col[3 * i + k] += sign * e[k]
                else:
                    torque = e
                tb = _mv(St, torque)  # type: ignore[arg-type]  # 3×3
                for k in range(3):
                    col[3 * p + 3 * i + k] += sign * tb[k]
        cols.append([se.expand(c) if c != 0 else zero for c in col])
    return SymMatrix.from_rows(list(zip(*cols, strict=True))) if cols else \
        SymMatrix.zeros(6 * p, 0)


def constraints(kin: Kinematics, closing: Sequence[ClosingJoint] | None = None,
                contacts: Sequence[Any] | None = None) -> Constraints:
    """The constraint rows of the ``closing`` joints and ``contacts`` (default: those of
    ``kin.system``): Φ, Φ_y, Φ_t of the holonomic rows, A, a, c of all rows and Q̄_c, from the
    tree's kinematics ``kin`` (zero rows for a tree)."""
    system = kin.system
    rows = constraint_rows(kin, system.closing if closing is None else closing)
    hol, vel = contact_rows(kin, system.contacts if contacts is None else contacts)
    rows = [*rows, *[r for r in hol if r.expr != 0], *vel]
    y = kin.y
    yd = [rate(c) for c in y]
    t = kin.t
    f = len(y)
    H = [r for r in rows if r.holonomic]
    Phi = [r.expr for r in H]
    Phi_y = [[se.diff(e, yj) for yj in y] for e in Phi]
    Phi_t = [se.diff(e, t) for e in Phi]
    A, a, w = [], [], []
    for i in range(len(Phi)):
        A.append(Phi_y[i])
        a.append(Phi_t[i])
        w.append(se.Add(*(Phi_y[i][j] * yd[j] for j in range(f))) + Phi_t[i])
    zero = {d: se.Integer(0) for d in yd}
    for r in rows[len(H):]:
        A.append([se.diff(r.expr, d) for d in yd])
        a.append(se.expand(r.expr.subs(zero)))
        w.append(r.expr)
    # c = ∂w/∂y·ẏ + ∂w/∂t: the part of ẇ without ÿ (w = A ẏ + a)
    c = [se.Add(*(se.diff(wi, y[j]) * yd[j] for j in range(f))) + se.diff(wi, t) for wi in w]

    def col(v: list) -> SymMatrix:
        return SymMatrix.column(v) if v else SymMatrix.zeros(0, 1)

    def mat(m: list, n: int) -> SymMatrix:
        return SymMatrix.from_rows(m) if m else SymMatrix.zeros(0, n)

    return Constraints(kin, tuple(rows), col(Phi), mat(Phi_y, f), col(Phi_t), col(c),
                       _wrench_columns(kin, rows), mat(A, f), col(a))


__all__ = ["ConstraintRow", "Constraints", "constraint_rows", "constraints", "perpendiculars"]
