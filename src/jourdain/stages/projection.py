"""Projection with J̄ᵀ, which eliminates the reaction forces (``docs/method.md`` §3):

    M(y,t)·ÿ + k(y,ẏ,t) = q(y,ẏ,t),   M = J̄ᵀ M̄ J̄,  k = J̄ᵀ q̄^c,  q = J̄ᵀ q̄^e

Produces M, k, q (:class:`EquationsOfMotion`).

The products are formed body by body from the sparse columns of J_T and J_R, never as dense
6p×6p products; terms that share the same Jacobian columns are collected first (so M_jk of a chain
reads ``(m_i + m_{i+1} + …)·(J_T,j · J_T,k)``), and only the upper triangle of M is built, so M is
exactly symmetric. Large systems (shared kinematics) get the same sums regrouped by composite
bodies, which grow like f² instead of f³ (:mod:`jourdain.stages.composite`).
"""

from __future__ import annotations

from dataclasses import dataclass

import symengine as se

from ..identity import IdentityMap
from ..model.joints import Mat3
from ..symbolic import SymMatrix
from .composite import composite_projection
from .kinematics import ROOT, FrameTag, _add, _cross, _dot, _mv, _scale, relative_rotation
from .newton_euler import NewtonEuler

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
    def forcing(self) -> SymMatrix:
        """q - k (f×1), the right-hand side of M·ÿ = q - k, written as one flat sum per row."""
        return SymMatrix.column(_difference(q, k) for q, k in
                                zip(self.q.entries(), self.k.entries(), strict=True))

    @property
    def y(self) -> tuple[se.Symbol, ...]:
        return self.newton_euler.kinematics.y

    @property
    def yd(self) -> tuple[se.Symbol, ...]:
        return self.newton_euler.kinematics.yd


def projection(ne: NewtonEuler) -> EquationsOfMotion:
    """Project the Newton–Euler equations with J̄ᵀ: M = J̄ᵀM̄J̄, k = J̄ᵀq̄^c, q = J̄ᵀq̄^e."""
    shared = composite_projection(ne)
    if shared is not None:
        return EquationsOfMotion(ne, *shared)
    kin = ne.kinematics
    system = kin.system
    f = len(kin.y)
    # translational part: group bodies by identical Jacobian columns
    # Bodies down a chain inherit the very same column objects from their parents, so groups are
    # keyed by object identity (jourdain.identity): exact and O(1), where == on deep expressions
    # may walk whole trees and SymEngine's hash confuses x + y with -x - y.
    mass_of_pair: dict[tuple[int, int], IdentityMap[tuple[tuple, tuple, list]]] = {}
    force_of_col: list[IdentityMap[tuple[tuple, list]]] = [IdentityMap() for _ in range(f)]
    gyro_of_col: list[IdentityMap[tuple[tuple, list]]] = [IdentityMap() for _ in range(f)]
    weight_of_col: list[IdentityMap[tuple[tuple, list]]] = [IdentityMap() for _ in range(f)]
    M_terms: list[list[list[se.Basic]]] = [[[] for _ in range(f)] for _ in range(f)]
    k_terms: list[list[se.Basic]] = [[] for _ in range(f)]
    q_terms: list[list[se.Basic]] = [[] for _ in range(f)]
    for body, bk, bf in zip(system.bodies, kin.bodies, ne.forces, strict=True):
        m = body.mass
        T = bk.cols_T
        ma = ([(o, v, m) for o, v in bk.a_bar_pieces],
              _scale((bk.a_bar.rows[0][0], bk.a_bar.rows[1][0], bk.a_bar.rows[2][0]), m))
        keys = sorted(T)
        f_nonzero = any(x != 0 for x in bf.f_other)
        g_nonzero = any(x != 0 for x in bf.gravity)
        for ii, j in enumerate(keys):
            cj = T[j]
            if m != 0:
                for kk in keys[ii:]:
                    ck = T[kk]
                    mass_of_pair.setdefault((j, kk), IdentityMap()).setdefault(
                        (*cj, *ck), (cj, ck, []))[2].append(m)
                gyro_of_col[j].setdefault(cj, (cj, []))[1].append(ma)
                if g_nonzero:
                    weight_of_col[j].setdefault(cj, (cj, []))[1].append((ROOT, bf.gravity, m))
            if f_nonzero:
                force_of_col[j].setdefault(cj, (cj, []))[1].append(bf.f_other)
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
            if gyro_R is not None:  # the body has inertia
                for kk in rkeys[ii:]:
                    M_terms[j][kk].append(_dot(cj, IR[kk]))
                k_terms[j].append(_dot(cj, gyro_R))
            if l_nonzero:
                q_terms[j].append(_dot(cj, bf.l))
    dots = _Dots(kin.column_pieces)
    for (j, kk), groups in mass_of_pair.items():
        for cj, ck, masses in groups.values():
            M_terms[j][kk].append(dots.columns(cj, ck) * se.Add(*masses))
    for j in range(f):
        for cj, piece_lists in gyro_of_col[j].values():
            k_terms[j].append(dots.with_pieces(cj, [p for ps, _ in piece_lists for p in ps],
                                               _sum([ma_i for _, ma_i in piece_lists])))
        for cj, weights in weight_of_col[j].values():
            q_terms[j].append(dots.with_pieces(cj, weights))  # one inertial piece each
        for cj, vecs in force_of_col[j].values():
            q_terms[j].append(_dot(cj, _sum(vecs)))
    k = [se.Add(*ts) if ts else ZERO for ts in k_terms]
    q = [se.Add(*ts) if ts else ZERO for ts in q_terms]
    return EquationsOfMotion(ne, SymMatrix.symmetric_from_terms(M_terms), SymMatrix.column(k), SymMatrix.column(q))


def _difference(a: se.Basic, b: se.Basic) -> se.Basic:
    """a - b with the terms of a sum b negated one by one (SymEngine keeps -(x + y) whole)."""
    terms_b = b.args if type(b).__name__ == "Add" else (b,)
    terms_a = a.args if type(a).__name__ == "Add" else (a,)
    return se.Add(*terms_a, *(-t for t in terms_b))


#: largest number of frame pairs for which a dot product is formed piece by piece in local
#: components; longer sums are dotted in inertial components, which CSE shares better
PIECE_PAIRS = 4


class _Dots:
    """Dot products of vectors known as sums of pieces S_k·v_k (kinematics.FrameTag)."""

    def __init__(self, pieces: IdentityMap[tuple]) -> None:
        self.pieces = pieces
        self.R: IdentityMap[Mat3 | None] = IdentityMap()

    def of(self, c: tuple) -> tuple | None:
        return self.pieces.get(c)

    def rel(self, a: FrameTag, b: FrameTag) -> Mat3 | None:
        return self.R.get_or_make((a, b), lambda: relative_rotation(a, b))

    def local(self, pa: tuple, pb: list) -> se.Basic:
        terms = []
        for ta, x in pa:
            for tb, y in pb:
                R = self.rel(ta, tb)
                terms.append(_dot(x, y if R is None else _mv(R, y)))
        return se.Add(*terms)

    def columns(self, a: tuple, b: tuple) -> se.Basic:
        """a·b of two Jacobian columns."""
        pa, pb = self.of(a), self.of(b)
        if pa is None or pb is None or len(pa) * len(pb) > PIECE_PAIRS:
            return _dot(a, b)
        return self.local(pa, list(pb))

    def with_pieces(self, c: tuple, pieces: list, inertial: tuple | None = None) -> se.Basic:
        """c·Σ m_i S_k·v_k after adding the pieces of each frame, and the masses of bodies that
        share a piece (inherited from a common ancestor), so terms of one frame cancel first.
        ``inertial``: the same sum in inertial components, when known, for long sums."""
        by_frame: IdentityMap[list] = IdentityMap()
        for tag, v, m in pieces:
            by_frame.setdefault(tag, [tag, IdentityMap()])[1].setdefault(v, (v, []))[1].append(m)
        summed = [(tag, _sum([_scale(v, se.Add(*ms)) for v, ms in shared.values()]))
                  for tag, shared in by_frame.values()]
        pc = self.of(c)
        if pc is not None and len(pc) * len(summed) <= PIECE_PAIRS:
            return self.local(pc, summed)
        if inertial is not None:
            return _dot(c, inertial)
        return _dot(c, _sum([v if tag is ROOT else _mv(tag.S, v) for tag, v in summed]))


def _sum(vecs: list) -> tuple:
    if len(vecs) == 1:
        return vecs[0]
    return tuple(se.Add(*(v[a] for v in vecs)) for a in range(3))
