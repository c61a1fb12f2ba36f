"""Projection with J̄ᵀ, which eliminates the reaction forces (METHOD.md §3):

    M(y,t)·ÿ + k(y,ẏ,t) = q(y,ẏ,t),   M = J̄ᵀ M̄ J̄,  k = J̄ᵀ q̄^c,  q = J̄ᵀ q̄^e

The products are formed body by body from the sparse columns of J_T and J_R, never as dense
6p×6p products; terms that share the same Jacobian columns are collected first (so M_jk of a chain
reads ``(m_i + m_{i+1} + …)·(J_T,j · J_T,k)``), and only the upper triangle of M is built, so M is
exactly symmetric.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import symengine as se

from .kinematics import _add, _cross, _dot, _mv, _scale
from .model.joints import IDENTITY, Mat3, Vec3, rotation_matrix
from .newton_euler import NewtonEuler
from .symbolic import SymMatrix

ZERO = se.Integer(0)


@dataclass(frozen=True)
class EquationsOfMotion:
    """Result of :func:`projection`: ``M·ÿ + k = q``.

    ``M`` (f×f, symmetric), ``k`` (f×1: Coriolis, centrifugal and gyroscopic forces), ``q``
    (f×1: applied generalized forces); ``newton_euler`` is the stage it came from.
    """

    newton_euler: NewtonEuler
    M: SymMatrix
    k: SymMatrix
    q: SymMatrix

    @property
    def system(self):  # noqa: ANN201 - System, avoided import cycle
        return self.newton_euler.system

    @property
    def y(self) -> tuple[se.Symbol, ...]:
        return self.newton_euler.kinematics.y

    @property
    def yd(self) -> tuple[se.Symbol, ...]:
        return self.newton_euler.kinematics.yd


def projection(ne: NewtonEuler) -> EquationsOfMotion:
    """Project the Newton–Euler equations with J̄ᵀ: M = J̄ᵀM̄J̄, k = J̄ᵀq̄^c, q = J̄ᵀq̄^e."""
    kin = ne.kinematics
    system = kin.system
    f = len(kin.y)
    # translational part: group bodies by identical Jacobian columns
    # Bodies down a chain inherit the very same column tuples from their parents, so groups are
    # keyed by object identity: exact and O(1), where == on deep expressions may walk whole trees
    # and SymEngine's hash confuses x + y with -x - y. The stored column keeps the id valid.
    mass_of_pair: dict[tuple[int, int], dict[tuple, tuple[tuple, tuple, list]]] = {}
    force_of_col: list[dict[tuple, tuple[tuple, list]]] = [dict() for _ in range(f)]
    gyro_of_col: list[dict[tuple, tuple[tuple, list]]] = [dict() for _ in range(f)]
    M_terms: list[list[list[se.Basic]]] = [[[] for _ in range(f)] for _ in range(f)]
    k_terms: list[list[se.Basic]] = [[] for _ in range(f)]
    q_terms: list[list[se.Basic]] = [[] for _ in range(f)]
    for body, bk, bf in zip(system.bodies, kin.bodies, ne.forces, strict=True):
        m = body.mass
        T = bk.cols_T
        ma = [(o, _scale(v, m)) for o, v in bk.a_bar_pieces]
        keys = sorted(T)
        hT = {j: _h(c) for j, c in T.items()}
        f_nonzero = any(x != 0 for x in bf.f)
        for ii, j in enumerate(keys):
            cj = T[j]
            if m != 0:
                for kk in keys[ii:]:
                    mass_of_pair.setdefault((j, kk), {}).setdefault(
                        hT[j] + hT[kk], (cj, T[kk], []))[2].append(m)
                gyro_of_col[j].setdefault(hT[j], (cj, []))[1].append(ma)
            if f_nonzero:
                force_of_col[j].setdefault(hT[j], (cj, []))[1].append(bf.f)
        # rotational part
        R = bk.cols_R
        has_I = body.has_inertia
        gyro_R = None
        if has_I:
            I = body.inertia
            w = (bk.omega.rows[0][0], bk.omega.rows[1][0], bk.omega.rows[2][0])
            ab = (bk.alpha_bar.rows[0][0], bk.alpha_bar.rows[1][0], bk.alpha_bar.rows[2][0])
            gyro_R = _add(_mv(I, ab), _cross(w, _mv(I, w)))
            IR = {j: _mv(I, c) for j, c in R.items()}
        l_nonzero = any(x != 0 for x in bf.l)
        rkeys = sorted(R)
        for ii, j in enumerate(rkeys):
            cj = R[j]
            if has_I:
                for kk in rkeys[ii:]:
                    M_terms[j][kk].append(_dot(cj, IR[kk]))
                k_terms[j].append(_dot(cj, gyro_R))
            if l_nonzero:
                q_terms[j].append(_dot(cj, bf.l))
    pure = kin.pure_columns
    for (j, kk), groups in mass_of_pair.items():
        for cj, ck, masses in groups.values():
            M_terms[j][kk].append(_column_dot(cj, ck, pure) * se.Add(*masses))
    for j in range(f):
        for cj, piece_lists in gyro_of_col[j].values():
            k_terms[j].append(_pieces_dot(cj, [p for ps in piece_lists for p in ps], pure))
        for cj, vecs in force_of_col[j].values():
            q_terms[j].append(_dot(cj, _sum(vecs)))
    M = [[ZERO] * f for _ in range(f)]
    for j in range(f):
        for kk in range(j, f):
            e = se.Add(*M_terms[j][kk]) if M_terms[j][kk] else ZERO
            M[j][kk] = e
            M[kk][j] = e
    k = [se.Add(*ts) if ts else ZERO for ts in k_terms]
    q = [se.Add(*ts) if ts else ZERO for ts in q_terms]
    return EquationsOfMotion(ne, SymMatrix.from_rows(M), SymMatrix.column(k), SymMatrix.column(q))


def _relative(oa: tuple, ob: tuple) -> Mat3 | None:
    """S_aᵀ·S_b for two frame orientations (kinematics.orientation) when it is simple: the
    identity within one frame, a single turn for frames turned about one fixed axis; else None."""
    if oa == ("I",) and ob == ("I",) or (oa[0] == "S" and ob[0] == "S" and oa[1] is ob[1]):
        return IDENTITY
    if oa[0] == "axis" and ob == ("I",):
        return rotation_matrix(oa[1], -oa[2])
    if oa == ("I",) and ob[0] == "axis":
        return rotation_matrix(ob[1], ob[2])
    if oa[0] == "axis" and ob[0] == "axis" and oa[1] == ob[1]:
        return rotation_matrix(oa[1], ob[2] - oa[2])
    return None


def _inertial(o: tuple, v: Vec3) -> Vec3:
    if o[0] == "I":
        return v
    return _mv(rotation_matrix(o[1], o[2]) if o[0] == "axis" else o[1], v)


def _column_dot(a: tuple, b: tuple, pure: Mapping[int, tuple]) -> se.Basic:
    """a·b; for columns a = S_a·x and b = S_b·y formed as x·(S_aᵀS_b·y): x·y in one frame, and
    a rotation by θ_b - θ_a for frames turned about one fixed axis (so a planar chain gives
    cos(q2 - q1) rather than the inertial components' sin·sin + cos·cos, and no sin² + cos²)."""
    ra, rb = pure.get(id(a)), pure.get(id(b))
    if ra is None or rb is None or ra[0] is not a or rb[0] is not b:
        return _dot(a, b)
    R = _relative(ra[1], rb[1])
    return _dot(a, b) if R is None else _dot(ra[2], _mv(R, rb[2]))


def _pieces_dot(c: tuple, pieces: list, pure: Mapping[int, tuple]) -> se.Basic:
    """c·Σ S_k·v_k, piece by piece in c's frame where the relative rotation is simple, after
    adding up the pieces of each frame (so terms of one frame cancel before any product)."""
    by_frame: dict = {}
    for o, v in pieces:
        key = id(o[1]) if o[0] == "S" else o
        entry = by_frame.setdefault(key, [o, []])
        entry[1].append(v)
    rc = pure.get(id(c))
    if rc is not None and rc[0] is not c:
        rc = None
    terms = []
    rest = []
    for o, vs in by_frame.values():
        v = _sum(vs)
        R = None if rc is None else _relative(rc[1], o)
        if R is None:
            rest.append(_inertial(o, v))
        else:
            terms.append(_dot(rc[2], _mv(R, v)))
    if rest:
        terms.append(_dot(c, _sum(rest)))
    return se.Add(*terms) if terms else ZERO


def _h(v: tuple) -> int:
    return id(v)


def _sum(vecs: list) -> tuple:
    if len(vecs) == 1:
        return vecs[0]
    return tuple(se.Add(*(v[a] for v in vecs)) for a in range(3))
