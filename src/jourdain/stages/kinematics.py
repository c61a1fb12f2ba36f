"""Kinematics of every body (METHOD.md §1): r, S, ω, J_T, J_R, v̄, ω̄, ā, ᾱ.

Conventions
-----------
* Translational quantities (``r``, ``J_T``, ``v_bar``, ``a_bar``) are in the **inertial frame**.
* Rotational quantities (``omega``, ``J_R``, ``omega_bar``, ``alpha_bar``) are in the **body
  frame**, where the inertia tensor is constant.
* ``S`` turns body-frame components into inertial ones: ``x_inertial = S · x_body``.

So ``v = J_T·ẏ + v̄`` (inertial) and ``ω = J_R·ẏ + ω̄`` (body frame), and likewise
``a = J_T·ÿ + ā``, ``α = J_R·ÿ + ᾱ``.

Method
------
The quantities are built *recursively* along the tree, one elementary transformation at a time
(as in recursive Newton–Euler algorithms), never by differentiating the composed position
vectors. Each new expression refers to the previous ones, so the result is a shared expression
graph whose size grows linearly with the depth of the tree instead of exponentially. Only the
angles and distances of the elementary steps (short user expressions) are differentiated.
Consecutive rotations about the same fixed axis are merged into one angle, so a planar chain
measured with absolute angles gives ``S = R_z(q_i)`` rather than a product of rotations.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType
from typing import TYPE_CHECKING

import symengine as se

from ..errors import ModelError
from ..identity import IdentityMap
from ..model.forces import acceleration, rate
from ..model.joints import IDENTITY, Joint, Mat3, Rot, Trans, Vec3, rotation_matrix
from ..symbolic import SymMatrix

if TYPE_CHECKING:
    from ..model.system import System

ZERO = se.Integer(0)
Z3: Vec3 = (ZERO, ZERO, ZERO)


# --- small vector helpers on 3-tuples of SymEngine expressions ---------------------------------
def _add(a: Vec3, b: Vec3) -> Vec3:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def _scale(a: Vec3, s: se.Basic) -> Vec3:
    return (a[0] * s, a[1] * s, a[2] * s)


def _cross(a: Vec3, b: Vec3) -> Vec3:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _dot(a: Vec3, b: Vec3) -> se.Basic:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _mv(A: Mat3, v: Vec3) -> Vec3:
    """A·v"""
    return (
        A[0][0] * v[0] + A[0][1] * v[1] + A[0][2] * v[2],
        A[1][0] * v[0] + A[1][1] * v[1] + A[1][2] * v[2],
        A[2][0] * v[0] + A[2][1] * v[1] + A[2][2] * v[2],
    )


def _mtv(A: Mat3, v: Vec3) -> Vec3:
    """Aᵀ·v"""
    return (
        A[0][0] * v[0] + A[1][0] * v[1] + A[2][0] * v[2],
        A[0][1] * v[0] + A[1][1] * v[1] + A[2][1] * v[2],
        A[0][2] * v[0] + A[1][2] * v[1] + A[2][2] * v[2],
    )


def _mm(A: Mat3, B: Mat3) -> Mat3:
    return tuple(
        tuple(A[i][0] * B[0][j] + A[i][1] * B[1][j] + A[i][2] * B[2][j] for j in range(3))
        for i in range(3)
    )  # type: ignore[return-value]


def _is_zero(v: Vec3) -> bool:
    return v[0] == 0 and v[1] == 0 and v[2] == 0


class FrameTag:
    """Identity of a frame orientation, linked to its parent orientation.

    ``A`` gives this frame's axes in the parent's (v_parent = A·v_this), ``S`` the inertial
    orientation, ``axis`` = (u, θ) when all rotations from the inertial frame are about one fixed
    axis u (then S = R_u(θ)). Relative rotations between two frames are products of the shallow
    ``A`` matrices between them (:func:`relative_rotation`), not products of the deep ``S``.
    """

    __slots__ = ("parent", "A", "S", "axis", "depth")

    def __init__(self, parent: FrameTag | None, A: Mat3, S: Mat3,
                 axis: tuple[Vec3, se.Basic] | None) -> None:
        self.parent, self.A, self.S, self.axis = parent, A, S, axis
        self.depth: int = 0 if parent is None else parent.depth + 1


ROOT = FrameTag(None, IDENTITY, IDENTITY, None)


def step_axis(step: Rot | Trans) -> Vec3:
    """The axis of an elementary step; a translation given by a vector has none."""
    if step.axis is None:
        raise ModelError("a translation given by a vector has no axis")
    return step.axis


def relative_rotation(a: FrameTag, b: FrameTag) -> Mat3 | None:
    """S_aᵀ·S_b (b's axes in a's frame); None when a is b (the identity)."""
    if a is b:
        return None
    if a is ROOT and b.axis is not None:
        return rotation_matrix(b.axis[0], b.axis[1])
    if b is ROOT and a.axis is not None:
        return rotation_matrix(a.axis[0], -a.axis[1])
    if a.axis is not None and b.axis is not None and a.axis[0] == b.axis[0]:
        return rotation_matrix(a.axis[0], b.axis[1] - a.axis[1])
    # down from the common ancestor c: S_a = S_c·A_(c→a), S_b = S_c·A_(c→b)
    pa: list[Mat3] = []
    pb: list[Mat3] = []
    x, y = a, b
    while x is not y:
        if x.depth >= y.depth:
            pa.append(x.A)
            x = x.parent  # type: ignore[assignment]
        else:
            pb.append(y.A)
            y = y.parent  # type: ignore[assignment]
    Ra = _chain(pa[::-1])
    Rb = _chain(pb[::-1])
    if Ra is None:
        return Rb
    if Rb is None:
        return tuple(tuple(Ra[j][i] for j in range(3)) for i in range(3))  # type: ignore[return-value]
    return _mtm(Ra, Rb)


def _chain(ms: list[Mat3]) -> Mat3 | None:
    out = None
    for m in ms:
        out = m if out is None else _mm(out, m)
    return out


def _mtm(A: Mat3, B: Mat3) -> Mat3:
    """Aᵀ·B"""
    return tuple(
        tuple(A[0][i] * B[0][j] + A[1][i] * B[1][j] + A[2][i] * B[2][j] for j in range(3))
        for i in range(3)
    )  # type: ignore[return-value]


@dataclass
class _Frame:
    """State of a moving frame during the recursion (mutable scratch, never returned)."""

    r: Vec3 = Z3
    JT: dict[int, Vec3] = field(default_factory=dict)
    v_bar: Vec3 = Z3
    a_bar: Vec3 = Z3
    JR: dict[int, Vec3] = field(default_factory=dict)
    omega: Vec3 = Z3
    omega_bar: Vec3 = Z3
    alpha_bar: Vec3 = Z3
    # a_bar as the sum of its pieces S_k·v_k: ((tag of frame k, v_k), ...)
    a_pieces: tuple = ()
    # the orientation: S, and the single axis when all rotations so far are about one
    tag: FrameTag = ROOT

    @property
    def S(self) -> Mat3:
        return self.tag.S

    @property
    def identity(self) -> bool:
        return self.tag is ROOT

    def copy(self) -> _Frame:
        return _Frame(self.r, dict(self.JT), self.v_bar, self.a_bar, dict(self.JR), self.omega,
                      self.omega_bar, self.alpha_bar, self.a_pieces, self.tag)


class _Rates:
    """Time derivatives of a scalar expression s(y, t) of the elementary steps."""

    __slots__ = ("dy", "dt", "d1", "d2_local")

    def __init__(self, s: se.Basic, ctx: _Context) -> None:
        idx = ctx.index.get(s) if isinstance(s, se.Symbol) else None
        if idx is not None:  # s is a coordinate itself
            self.dy = {idx: se.Integer(1)}
            self.dt = ZERO
            self.d1 = ctx.yd[idx]
            self.d2_local = ZERO
            return
        free = s.free_symbols
        self.dy = {}
        for sym in free:
            j = ctx.index.get(sym)
            if j is not None:
                self.dy[j] = se.diff(s, sym)
        self.dt = se.diff(s, ctx.t) if ctx.t in free else ZERO
        self.d1 = sum((c * ctx.yd[j] for j, c in self.dy.items()), self.dt)
        # d²s/dt² without the ÿ terms: d/dt of ṡ at constant ÿ
        d2 = se.diff(self.d1, ctx.t) if (ctx.t in free) else ZERO
        for sym in free:
            j = ctx.index.get(sym)
            if j is not None:
                d2 = d2 + se.diff(self.d1, sym) * ctx.yd[j]
        self.d2_local = d2

    @property
    def constant(self) -> bool:
        return not self.dy and self.dt == 0


@dataclass
class _Context:
    index: dict[se.Symbol, int]
    yd: tuple[se.Symbol, ...]
    t: se.Symbol
    # columns of J_T as sums of rotated local vectors S_k·v_k: col -> ((tag, v), ...)
    pieces: IdentityMap[tuple] = field(default_factory=IdentityMap)


def _rotate(F: _Frame, u: Vec3, angle: se.Basic, ctx: _Context) -> None:
    """Apply the elementary rotation about u (current frame) by ``angle``."""
    if angle == 0:
        return
    rt = _Rates(angle, ctx)
    A = rotation_matrix(u, angle)
    # orientation, merging rotations about one fixed axis into a single angle
    axis = F.tag.axis
    if F.identity:
        S, axis = A, (u, angle)
    elif axis is not None and axis[0] == u:
        theta = axis[1] + angle
        S, axis = rotation_matrix(u, theta), (u, theta)
    else:
        S, axis = _mm(F.S, A), None
    F.tag = FrameTag(F.tag, A, S, axis)
    # angular velocity and acceleration in the new frame: ω' = Aᵀ(ω + u·θ̇)
    keys = set(F.JR) | set(rt.dy)
    F.JR = {
        j: _mtv(A, _add(F.JR.get(j, Z3), _scale(u, rt.dy[j])) if j in rt.dy else F.JR[j])
        for j in keys
    }
    F.omega_bar = _mtv(A, _add(F.omega_bar, _scale(u, rt.dt)))
    w_rel = _scale(u, rt.d1)
    F.alpha_bar = _mtv(A, _add(_add(F.alpha_bar, _scale(u, rt.d2_local)), _cross(F.omega, w_rel)))
    F.omega = _mtv(A, _add(F.omega, w_rel))


def _reorient(F: _Frame, R0: Mat3) -> None:
    """Apply a constant change of axes R0 (new axes in current-frame components)."""
    if R0 == IDENTITY:
        return
    F.tag = FrameTag(F.tag, R0, R0 if F.identity else _mm(F.S, R0), None)
    F.JR = {j: _mtv(R0, c) for j, c in F.JR.items()}
    F.omega, F.omega_bar, F.alpha_bar = (_mtv(R0, F.omega), _mtv(R0, F.omega_bar),
                                         _mtv(R0, F.alpha_bar))


def _append(pieces: tuple, tag: FrameTag, v: Vec3) -> tuple:
    """pieces + S_tag·v, added to the last piece when that is in the same frame."""
    if pieces and pieces[-1][0] is tag:
        return (*pieces[:-1], (tag, _add(pieces[-1][1], v)))
    return (*pieces, (tag, v))


def _translate(F: _Frame, d: Vec3, ctx: _Context) -> None:
    """Apply the elementary translation by the vector d(y, t) given in the current frame."""
    if _is_zero(d):
        return
    rates = [_Rates(c, ctx) for c in d]
    S = F.S
    toI = (lambda v: v) if F.identity else (lambda v: _mv(S, v))
    F.r = _add(F.r, toI(d))
    keys = set(F.JT) | set(F.JR) | {j for rt in rates for j in rt.dy}
    newJT = {}
    for j in keys:
        local = Z3
        if j in F.JR:
            local = _cross(F.JR[j], d)
        dj = tuple(rt.dy.get(j, ZERO) for rt in rates)
        if not _is_zero(dj):
            local = _add(local, dj)
        if _is_zero(local):
            newJT[j] = F.JT.get(j, Z3)
            continue
        # remember the column as pieces S_k·v_k: dot products of columns are then formed from
        # the local vectors (no sin² + cos² of components, see jourdain.stages.projection)
        old = F.JT.get(j)
        if old is None:
            col = toI(local)
            pieces: tuple | None = ((F.tag, local),)
        else:
            col = _add(old, toI(local))
            rec = ctx.pieces.get(old)
            pieces = None if rec is None else _append(rec, F.tag, local)
        newJT[j] = col
        if pieces is not None:
            ctx.pieces[col] = pieces
    F.JT = newJT
    d_t: Vec3 = tuple(rt.dt for rt in rates)
    d_1: Vec3 = tuple(rt.d1 for rt in rates)
    d_2: Vec3 = tuple(rt.d2_local for rt in rates)
    F.v_bar = _add(F.v_bar, toI(_add(_cross(F.omega_bar, d), d_t)))
    acc = _add(_cross(F.alpha_bar, d), _cross(F.omega, _cross(F.omega, d)))
    if not _is_zero(d_1):
        acc = _add(acc, _add(_scale(_cross(F.omega, d_1), se.Integer(2)), d_2))
    F.a_bar = _add(F.a_bar, toI(acc))
    if not _is_zero(acc):
        F.a_pieces = _append(F.a_pieces, F.tag, acc)


def _joint_steps(F: _Frame, joint: Joint, ctx: _Context) -> None:
    """Apply a joint's constant orientation and its elementary steps to the frame at the joint
    point."""
    _reorient(F, joint.orientation)
    for step in joint.steps:
        if isinstance(step, Rot):
            _rotate(F, step.axis, step.angle, ctx)
        elif isinstance(step, Trans):
            _translate(F, step.vector, ctx)


@dataclass(frozen=True)
class BodyKinematics:
    """Kinematics of one body (fields named as in METHOD.md §1).

    ``r`` (3×1, inertial): centre of mass; ``S`` (3×3): body → inertial; ``omega`` (3×1, body
    frame): angular velocity ``J_R·ẏ + ω̄`` as an expression in y, ẏ, t; ``J_T`` (3×f, inertial),
    ``J_R`` (3×f, body frame); ``v_bar``, ``a_bar`` (inertial), ``omega_bar``, ``alpha_bar``
    (body frame). ``r_O``, ``J_T_O``, ``v_bar_O``, ``a_bar_O``: the same for the body frame's
    origin (the joint point), used for points on the body.
    """

    name: str
    r: SymMatrix
    S: SymMatrix
    omega: SymMatrix
    J_T: SymMatrix
    J_R: SymMatrix
    v_bar: SymMatrix
    omega_bar: SymMatrix
    a_bar: SymMatrix
    alpha_bar: SymMatrix
    r_O: SymMatrix
    J_T_O: SymMatrix
    v_bar_O: SymMatrix
    a_bar_O: SymMatrix
    # sparse columns (coordinate index -> 3-vector) of J_T, J_R, J_T_O for the fast stages
    cols_T: MappingProxyType = field(repr=False, compare=False)
    cols_R: MappingProxyType = field(repr=False, compare=False)
    cols_T_O: MappingProxyType = field(repr=False, compare=False)
    #: a_bar as pieces S_k·v_k, ((FrameTag, v_k), ...)
    a_bar_pieces: tuple = field(default=(), repr=False, compare=False)

    def point(self, p: Vec3) -> tuple[Vec3, dict[int, Vec3], Vec3, Vec3]:
        """Position, J_T columns, v̄ and ā (inertial) of the point ``p`` (body-frame, from the
        body frame's origin)."""
        S = _mat(self.S)
        Sp = _mv(S, p)
        r = _add(_vec(self.r_O), Sp)
        cols = dict(self.cols_T_O)
        for j, c in self.cols_R.items():
            extra = _mv(S, _cross(c, p))
            cols[j] = _add(cols.get(j, Z3), extra)
        w, wb, ab = _vec(self.omega), _vec(self.omega_bar), _vec(self.alpha_bar)
        v_bar = _add(_vec(self.v_bar_O), _mv(S, _cross(wb, p)))
        a_bar = _add(_vec(self.a_bar_O), _mv(S, _add(_cross(ab, p), _cross(w, _cross(w, p)))))
        return r, cols, v_bar, a_bar


def _vec(m: SymMatrix) -> Vec3:
    return (m.rows[0][0], m.rows[1][0], m.rows[2][0])


def _mat(m: SymMatrix) -> Mat3:
    return m.rows  # type: ignore[return-value]


def _dense(cols: dict[int, Vec3], f: int) -> SymMatrix:
    return SymMatrix(tuple(tuple(cols[j][i] if j in cols else ZERO for j in range(f))
                           for i in range(3)))


@dataclass(frozen=True)
class Kinematics:
    """Result of :func:`kinematics`: one :class:`BodyKinematics` per body, in tree order."""

    system: System
    bodies: tuple[BodyKinematics, ...]
    y: tuple[se.Symbol, ...]
    yd: tuple[se.Symbol, ...]
    ydd: tuple[se.Symbol, ...]
    t: se.Symbol
    #: columns of J_T as sums of rotated local vectors: col -> ((FrameTag, v), ...), by identity
    column_pieces: IdentityMap[tuple] = field(default_factory=IdentityMap, repr=False,
                                              compare=False)

    def __getitem__(self, name: str) -> BodyKinematics:
        for b in self.bodies:
            if b.name == name:
                return b
        self.system.body(name)  # raises ModelError naming the body
        raise KeyError(name)


def kinematics(system: System) -> Kinematics:
    """Kinematics of every body of ``system`` (METHOD.md §1), built recursively along the tree."""
    y = system.coordinates
    ctx = _Context({c: i for i, c in enumerate(y)}, tuple(rate(c) for c in y), system.t)
    f = len(y)
    frames: dict[str, _Frame] = {"world": _Frame()}
    coms: dict[str, tuple[Vec3, _Frame]] = {}
    out = []
    for body in system.bodies:
        j = body.joint
        # joint frame on the parent, then the joint's elementary transformations; a joint point at
        # the parent's centre of mass (a chain of point masses) reuses that state, so that equal
        # Jacobian columns are the same objects and the projection collects their masses
        com = coms.get(body.parent)
        if com is not None and com[0] == j.position:
            F = com[1].copy()
        else:
            F = frames[body.parent].copy()
            _translate(F, j.position, ctx)
        _joint_steps(F, j, ctx)
        frames[body.name] = F
        # centre of mass
        C = F.copy()
        _translate(C, body.com, ctx)
        coms[body.name] = (body.com, C)
        col = SymMatrix.column
        out.append(BodyKinematics(
            name=body.name, r=col(C.r), S=SymMatrix.from_rows(F.S), omega=col(F.omega),
            J_T=_dense(C.JT, f), J_R=_dense(F.JR, f), v_bar=col(C.v_bar),
            omega_bar=col(F.omega_bar), a_bar=col(C.a_bar), alpha_bar=col(F.alpha_bar),
            r_O=col(F.r), J_T_O=_dense(F.JT, f), v_bar_O=col(F.v_bar), a_bar_O=col(F.a_bar),
            cols_T=MappingProxyType(C.JT), cols_R=MappingProxyType(F.JR),
            cols_T_O=MappingProxyType(F.JT), a_bar_pieces=C.a_pieces,
        ))
    return Kinematics(system, tuple(out), y, ctx.yd, tuple(acceleration(c) for c in y), system.t,
                      ctx.pieces)


@dataclass(frozen=True)
class JointMotion:
    """Motion of a joint's child frame relative to its parent body frame (the joint alone).

    ``A`` (3×3): child axes in parent components (v_parent = A·v_child); ``d`` (3): child origin
    in the parent frame. ``J_T`` (coordinate index -> 3-vector, parent frame) and ``J_R``
    (child frame): the columns of the relative origin velocity ``ḋ = J_T·ẏ + v̄`` and relative
    angular velocity ``ρ = J_R·ẏ + ω̄``; ``v_bar`` (parent), ``omega_bar`` (child): their
    rheonomic parts; ``a_bar`` (parent), ``alpha_bar`` (child): the relative accelerations at
    ÿ = 0 (``d̈`` and ``ρ̇``). The recursive numeric evaluation (:mod:`jourdain.numeric.recursive`)
    composes these body by body, as the symbolic :func:`kinematics` composes the same steps.
    """

    A: Mat3
    d: Vec3
    J_T: MappingProxyType
    J_R: MappingProxyType
    v_bar: Vec3
    omega_bar: Vec3
    a_bar: Vec3
    alpha_bar: Vec3


def joint_motions(system: System) -> tuple[JointMotion, ...]:
    """:class:`JointMotion` of every body's joint, in body order: the same elementary steps as
    :func:`kinematics`, started from a parent frame at rest."""
    y = system.coordinates
    ctx = _Context({c: i for i, c in enumerate(y)}, tuple(rate(c) for c in y), system.t)
    out = []
    for body in system.bodies:
        j = body.joint
        F = _Frame()
        _translate(F, j.position, ctx)
        _joint_steps(F, j, ctx)
        out.append(JointMotion(F.S, F.r, MappingProxyType(dict(F.JT)),
                               MappingProxyType(dict(F.JR)), F.v_bar, F.omega_bar, F.a_bar,
                               F.alpha_bar))
    return tuple(out)
