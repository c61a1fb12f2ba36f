"""M, k, q of a large system by composite bodies (``docs/method.md`` §3 in the arrangement of
the composite-rigid-body algorithm), from the shared kinematics (``kinematics(system,
shared=True)``, the default from :data:`~jourdain.stages.kinematics.result.SHARED_FROM_F`
coordinates on).

The sums over bodies of ``M = J̄ᵀM̄J̄``, ``k = J̄ᵀq̄^c``, ``q = J̄ᵀq̄^e`` are regrouped, exactly,
at the steps of the recursion where each coordinate enters (its angle or vector depends on y_j:
``Node.anchors``). Below such a step b, the columns of y_j in every body are rigid transports
of the twist δ_j^b the step adds (an axis times ∂angle/∂y_j, or ∂vector/∂y_j), and the whole
twist s_j^b of y_j at b (the recursion's ``JR``, ``JT`` there) is the sum of the δ_j of its
steps at or above b. With the composite body of everything below b (mass m, first moment h,
inertia about b's origin, in b's frame: I^c_b) and the resultant wrenches w^c_b of the bodies'
inertia forces m·ā and I·ᾱ + ω × I·ω and w^e_b of the applied forces, about b's origin:

    k_j = Σ_b δ_j^b·w^c_b,     q_j = Σ_b δ_j^b·w^e_b      (b: the steps of y_j)
    M_jk = T_jk + T_kj − D_jk,  T_jk = Σ_b s_j^b·I^c_b·δ_k^b (b: the steps of y_k),
                                D_jk = Σ_b δ_j^b·I^c_b·δ_k^b (b: the steps of both)

(each pair of steps (a of y_j, b of y_k) on one path is counted once, at the lower one). Where
each coordinate enters at one step, as in a chain of joints with relative coordinates, this is
``M_jk = s_j·I^c_b·s_k`` at the step b of the lower of the two. The composite bodies and the
wrenches are summed from the leaves up, one step at a time, each a short expression of the ones
below; each entry of M is then a few dot products of six components, and nothing is expanded:
time and memory grow like f² (the f(f+1)/2 entries), where the sums body by body of
:func:`jourdain.stages.projection.projection` grow like f³. The same numbers in a different
arrangement, and a less readable one for small systems, which keep the body-by-body sums.
"""

from __future__ import annotations

from collections.abc import Sequence

import symengine as se

from ..model.joints import Mat3, Vec3
from ..symbolic import SymMatrix
from .kinematics import Z3, _add, _cross, _mtv, _mv, _scale
from .kinematics.frames import Node
from .kinematics.vectors import _times, _zero
from .newton_euler import NewtonEuler

ZERO = se.Integer(0)

#: a composite body: mass, first moment about the origin, inertia about the origin (own frame)
Composite = tuple[se.Basic, Vec3, Mat3]
#: a wrench: moment about the origin, force (own frame)
Wrench = tuple[Vec3, Vec3]


def composite_projection(ne: NewtonEuler) -> tuple[SymMatrix, SymMatrix, SymMatrix] | None:
    """(M, k, q) from the shared kinematics, or None where the kinematics are not shared."""
    kin = ne.kinematics
    nodes = kin.nodes
    if nodes is None:
        return None
    f = len(kin.y)
    gravity = ne.forces[0].gravity if ne.forces else Z3
    common_g = all(bf.gravity == gravity for bf in ne.forces) and not _is_zero(gravity)
    comp, wc, we = _upward(ne, common_g)
    # M: at each step b and coordinate k it adds the twist δ_k to, the composite body below
    # meets every twist s_j known there: M_jk += s_j·I^c_b·δ_k (module docstring)
    terms: list[list[list[se.Basic]]] = [[[] for _ in range(f)] for _ in range(f)]
    for b in nodes:
        c = comp[b.index]
        if c is None or not b.anchors:
            continue
        up = b.parent
        here = {j: (dw, dv) for j, dw, dv in b.anchors}
        first = {j for j in here if up is None or (j not in up.JR and j not in up.JT)}
        moms = {j: _momentum(c, d) for j, d in here.items()}
        for k, mom in moms.items():
            for j in sorted(set(b.JR) | set(b.JT)):
                if j not in here:
                    e = _pair(_twist(b, j), mom)
                elif j > k:
                    continue  # the pair is formed at (k, j)
                elif k in first:  # s_k = δ_k: s_j·I·s_k
                    e = _pair(_twist(b, j), mom)
                elif j in first:
                    e = _pair(_twist(b, k), moms[j])
                else:  # s_j·I·δ_k + s_k·I·δ_j − δ_j·I·δ_k
                    e = se.Add(_pair(_twist(b, j), mom), _pair(_twist(b, k), moms[j]),
                               -_pair(here[j], mom))
                terms[min(j, k)][max(j, k)].append(e)
    # k, q: each twist δ_j meets the resultant wrench of everything below its step
    k_terms: list[list[se.Basic]] = [[] for _ in range(f)]
    q_terms: list[list[se.Basic]] = [[] for _ in range(f)]
    for b in nodes:
        c = comp[b.index]
        g = _mtv(b.tag.S, gravity) if common_g and c is not None and b.anchors else None
        for j, dw, dv in b.anchors:
            d = (dw, dv)
            w = wc[b.index]
            if w is not None:
                k_terms[j].append(_pair(d, w))
            w = we[b.index]
            if w is not None:
                q_terms[j].append(_pair(d, w))
            if g is not None:  # the weight m·g at the centre h/m, in b's frame
                q_terms[j].append(_pair(d, (_cross(c[1], g), _scale(g, c[0]))))  # type: ignore[index]
    rows = [[ZERO] * f for _ in range(f)]
    for j in range(f):
        for k, e in enumerate(_sums(terms[j][j:]), j):
            rows[j][k] = rows[k][j] = e
    return (SymMatrix.from_rows(rows), SymMatrix.column(_sums(k_terms)),
            SymMatrix.column(_sums(q_terms)))


def _sums(terms: list[list[se.Basic]]) -> list[se.Basic]:
    """The sum of each list of terms (a single term as it is: se.Add would copy a sum)."""
    return [(t[0] if len(t) == 1 else se.Add(*t)) if t else ZERO for t in terms]


def _upward(ne: NewtonEuler, common_g: bool
            ) -> tuple[list[Composite | None], list[Wrench | None], list[Wrench | None]]:
    """At every step: the composite body of everything below it, the resultant wrench of
    the bodies' inertia forces (w^c) and that of the applied forces (w^e, without the weights
    where gravity is common to all bodies), summed from the leaves up."""
    kin = ne.kinematics
    nodes = kin.nodes
    assert nodes is not None
    # what each body puts at its centre of mass, in its own frame
    bodies: list[list[Composite]] = [[] for _ in nodes]
    w_c: list[list[Wrench]] = [[] for _ in nodes]
    w_e: list[list[Wrench]] = [[] for _ in nodes]
    for body, bk, bf in zip(kin.system.bodies, kin.bodies, ne.forces, strict=True):
        i = bk.node.index  # type: ignore[union-attr]
        m, I = body.mass, body.inertia
        has_m, has_I = m != 0, body.has_inertia
        if has_m or has_I:
            bodies[i].append((m if has_m else ZERO, Z3, I if has_I else _Z33))
        S: Mat3 = bk.S.rows  # type: ignore[assignment]
        p_c = _scale(_mtv(S, _col(bk.a_bar)), m) if has_m else Z3
        l_c = _euler(I, _col(bk.omega), _col(bk.alpha_bar)) if has_I else Z3
        if not (_is_zero(p_c) and _is_zero(l_c)):
            w_c[i].append((l_c, p_c))
        f_e = bf.f_other if common_g else bf.f
        p_e = Z3 if _is_zero(f_e) else _mtv(S, f_e)
        if not (_is_zero(p_e) and _is_zero(bf.l)):
            w_e[i].append((bf.l, p_e))
    comp: list[Composite | None] = [None] * len(nodes)
    wc: list[Wrench | None] = [None] * len(nodes)
    we: list[Wrench | None] = [None] * len(nodes)
    for n in reversed(nodes):
        i = n.index
        comp[i] = _sum_composites(bodies[i])
        wc[i], we[i] = _sum_wrenches(w_c[i]), _sum_wrenches(w_e[i])
        up = n.parent
        if up is None:
            continue
        if comp[i] is not None:
            bodies[up.index].append(_move_composite(n, comp[i]))  # type: ignore[arg-type]
        if wc[i] is not None:
            w_c[up.index].append(_move_wrench(n, wc[i]))  # type: ignore[arg-type]
        if we[i] is not None:
            w_e[up.index].append(_move_wrench(n, we[i]))  # type: ignore[arg-type]
    return comp, wc, we


_Z33: Mat3 = (Z3, Z3, Z3)


def _col(m: SymMatrix) -> Vec3:
    return (m.rows[0][0], m.rows[1][0], m.rows[2][0])


def _is_zero(v: Vec3) -> bool:
    return v[0] == 0 and v[1] == 0 and v[2] == 0


def _euler(I: Mat3, w: Vec3, alpha: Vec3) -> Vec3:
    """I·α + ω × I·ω"""
    return _add(_mv(I, alpha), _cross(w, _mv(I, w)))


def _twist(a: Node, j: int) -> tuple[Vec3, Vec3]:
    """s_j at the step a: the whole twist of coordinate j there (every step above included)."""
    return a.JR.get(j, Z3), a.JT.get(j, Z3)


def _pair(s: tuple[Vec3, Vec3], w: Wrench) -> se.Basic:
    """s·w = ω·(moment) + v·(force), one sum of the non-zero products"""
    return se.Add(*[a * b for a, b in zip((*s[0], *s[1]), (*w[0], *w[1]), strict=True)
                    if not (_zero(a) or _zero(b))])


def _momentum(c: Composite, s: tuple[Vec3, Vec3]) -> Wrench:
    """I^c·s of the composite body c moving with the twist s = (ω, v): (angular momentum about
    the origin h × v + I·ω, momentum m·v + ω × h)."""
    m, h, I = c
    w, v = s
    return _add(_cross(h, v), _mv(I, w)), _add(_scale(v, m), _cross(w, h))


def _sum3(vs: Sequence[Vec3]) -> Vec3:
    if len(vs) == 1:
        return vs[0]
    return (se.Add(*(v[0] for v in vs)), se.Add(*(v[1] for v in vs)),
            se.Add(*(v[2] for v in vs)))


def _sum_composites(cs: list[Composite]) -> Composite | None:
    if not cs:
        return None
    if len(cs) == 1:
        return cs[0]
    I = tuple(tuple(se.Add(*(c[2][a][b] for c in cs)) for b in range(3)) for a in range(3))
    return se.Add(*(c[0] for c in cs)), _sum3([c[1] for c in cs]), I  # type: ignore[return-value]


def _sum_wrenches(ws: list[Wrench]) -> Wrench | None:
    if not ws:
        return None
    return _sum3([w[0] for w in ws]), _sum3([w[1] for w in ws])


def _move_composite(n: Node, c: Composite) -> Composite:
    """The composite body c of the frame after step n, in the frame before it."""
    m, h, I = c
    if n.A is not None:
        A = _times(n.A)
        AI = tuple(A((I[0][b], I[1][b], I[2][b])) for b in range(3))  # columns of A·I
        rows = tuple(A((AI[0][a], AI[1][a], AI[2][a])) for a in range(3))  # of A·I·Aᵀ
        return m, A(h), rows  # type: ignore[return-value]
    if n.d is None:
        return c
    d = n.d
    # parallel axes with the first moment h about n's origin:
    # I + m(d·d E − d dᵀ) + 2(h·d)E − h dᵀ − d hᵀ, the diagonal without the terms that cancel
    J = tuple(tuple(
        se.Add(I[a][a], *(m * d[b] ** 2 + 2 * h[b] * d[b] for b in range(3) if b != a))
        if a == b else se.Add(I[a][b], -m * d[a] * d[b], -h[a] * d[b], -d[a] * h[b])
        for b in range(3)) for a in range(3))
    return m, _add(h, _scale(d, m)), J  # type: ignore[return-value]


def _move_wrench(n: Node, w: Wrench) -> Wrench:
    """The wrench w about the origin after step n, about the origin before it (parent
    components)."""
    if n.A is not None:
        return _mv(n.A, w[0]), _mv(n.A, w[1])
    if n.d is None:
        return w
    return _add(w[0], _cross(n.d, w[1])), w[1]
