"""The constraint stage's rows of contacts (:mod:`jourdain.model.contacts`): a rolling disc's
holonomic row (the rim touches the ground) and its two velocity rows (no slip), a knife edge's
velocity row, general velocity rows. Each velocity row ``w = A_i·ẏ + a_i`` is formed as the
velocity of the body's *material* point at the contact along the row's direction, so its
constrained direction (a force along it at the contact point, ``Q̄``'s column) satisfies
``J̄ᵀ·Q̄_c = A_iᵀ`` exactly (Jourdain's principle: the contact force does no virtual power).

Rolling disc (centre C, axle a = S·axis, ground normal n, radius R): the rim's point nearest
the ground is ``P = C − R·(n − (n·a)·a)/√(1 − (n·a)²)`` and its height ``n·P`` is the
holonomic row; its variation is the material point's normal displacement at P, because the
rim's tangent there is parallel to the ground (so the same force column serves). A torus
(tube radius ρ) touches at ``P − ρ·n`` below the centre line's lowest point, where its surface
is parallel to the ground too. The disc lying flat (``n·a = ±1``) has no contact point: the
evaluation reports it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import symengine as se

from ..model.contacts import Contact, KnifeEdge, RollingDisc, VelocityConstraint
from ..model.expressions import Expr, Vec3
from ..model.forces import rate
from .kinematics import Kinematics, _cross, _dot, _mv
from .rows import ConstraintRow


def _add(a: Vec3, b: Vec3) -> Vec3:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def _scale(s: Expr, a: Vec3) -> Vec3:
    return (s * a[0], s * a[1], s * a[2])


def _ground_axes(n: Vec3) -> tuple[Vec3, Vec3]:
    """Two ground directions (world axes) for the normal ``n`` (a signed world axis), with
    ``t1 × t2 = n``."""
    one, zero = se.Integer(1), se.Integer(0)
    k = next(i for i in range(3) if n[i] != 0)
    i, j = (k + 1) % 3, (k + 2) % 3
    t1: Any = tuple(one if m == i else zero for m in range(3))
    t2: Any = tuple(one if m == j else zero for m in range(3))
    return t1, _scale(n[k], t2)


def material_velocity(kin: Kinematics, body: str, P: Vec3, f: int) -> tuple[list[Expr], Vec3]:
    """The velocity of ``body``'s material point at the inertial point ``P`` (an expression of
    y, t): its columns over ẏ (inertial, one 3-vector per coordinate) and its rheonomic part.
    Not :meth:`BodyKinematics.point`, which takes a point fixed in the body: a contact point
    moves over the body, and its arm from the body's origin is formed inertially here
    (``(S·J_R)×(P − r_O)``) instead of as ``S·(J_R × Sᵀ·(P − r_O))``, whose products of S
    would be left unsimplified in the generated code."""
    bk = kin[body]
    S: Any = bk.S.rows
    rO = tuple(bk.r_O.rows[i][0] for i in range(3))
    arm = (P[0] - rO[0], P[1] - rO[1], P[2] - rO[2])
    zero = (se.Integer(0),) * 3
    cols: list = [zero] * f
    for j, c in bk.cols_T_O.items():
        cols[j] = _add(cols[j], c)
    for j, c in bk.cols_R.items():
        cols[j] = _add(cols[j], _cross(_mv(S, c), arm))
    wb = tuple(bk.omega_bar.rows[i][0] for i in range(3))
    vb = tuple(bk.v_bar_O.rows[i][0] for i in range(3))
    return cols, _add(vb, _cross(_mv(S, wb), arm))


def _velocity_row(cols: list, vbar: Vec3, e: Vec3, yd: Sequence[se.Symbol]) -> Expr:
    """``e·v`` as an expression linear in ẏ."""
    terms = [_dot(e, c) * yd[j] for j, c in enumerate(cols) if any(x != 0 for x in c)]
    return se.Add(*terms) + _dot(e, vbar)


def contact_rows(kin: Kinematics, contacts: Sequence[Contact]) -> tuple[list, list]:
    """The rows of ``contacts``: (holonomic rows, velocity rows) as
    :class:`jourdain.stages.constraints.ConstraintRow` (``expr`` Φ_i, resp. the velocity
    expression ``w_i = A_i·ẏ + a_i``)."""
    y = kin.y
    yd = [rate(c) for c in y]
    f = len(y)
    hol: list = []
    vel: list = []
    for c in contacts:
        n = c.name
        if isinstance(c, VelocityConstraint):
            for i, e in enumerate(c.expressions, 1):
                vel.append(ConstraintRow(n, f"{n}.{i}", e, "generic", None, holonomic=False))
            continue
        bk = kin[c.body]
        S: Any = bk.S.rows
        rO = tuple(bk.r_O.rows[i][0] for i in range(3))
        nv = c.normal
        if isinstance(c, RollingDisc):
            C = _add(rO, _mv(S, c.center))
            a = _mv(S, c.axis)
            na = _dot(nv, a)
            s = se.sqrt(1 - na * na)
            d = tuple(-(nv[i] - na * a[i]) / s for i in range(3))
            P = _add(_add(C, _scale(c.radius, d)), _scale(-c.tube_radius, nv))
            at: dict[str, Any] = {"body_a": c.body, "body_b": "world", "p_a": P, "p_b": P}
            hol.append(ConstraintRow(n, f"{n}.N", _dot(nv, P), "force", nv, **at))
            cols, vbar = material_velocity(kin, c.body, P, f)
            for k, tk in enumerate(_ground_axes(nv), 1):
                vel.append(ConstraintRow(n, f"{n}.T{k}", _velocity_row(cols, vbar, tk, yd),
                                         "force", tk, holonomic=False, **at))
        elif isinstance(c, KnifeEdge):
            p = _add(rO, _mv(S, c.point))
            e = _mv(S, c.direction)
            lat = _cross(nv, e)
            size = se.sqrt(_dot(lat, lat))
            lat = tuple(x / size for x in lat)
            cols, vbar = material_velocity(kin, c.body, p, f)
            at = {"body_a": c.body, "body_b": "world", "p_a": p, "p_b": p}
            vel.append(ConstraintRow(n, f"{n}.T", _velocity_row(cols, vbar, lat, yd), "force",
                                     lat, holonomic=False, **at))
    return hol, vel


__all__ = ["contact_rows", "material_velocity"]
