"""The recursion of the kinematics (``docs/method.md`` §1): one elementary transformation at a
time along the tree (rotations merged about fixed axes, translations), carrying the position,
the rotation, the Jacobians J_T, J_R and the local accelerations; the shared expression graph
this builds grows linearly with the depth of the tree.

A *shared* recursion (``_Context.shared``, for large systems: :func:`.result.kinematics`)
carries the Jacobian columns of the frame's origin in the frame's own components (``JT_loc``,
each step a short expression of the previous one) instead of inertial sums that grow with the
depth, and records each step as a :class:`~.frames.Node` for the composite-body projection.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import symengine as se

from ...graph.piecewise import diff as pw_diff
from ...identity import IdentityMap
from ...model.joints import IDENTITY, Joint, Mat3, Rot, Trans, Vec3, rotation_matrix

if TYPE_CHECKING:
    pass
from .frames import ROOT, FrameTag, Node
from .vectors import Z3, ZERO, _add, _cross, _is_zero, _mm, _scale, _times, _times_t


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
    # shared recursion: the columns of J_T of the origin in this frame's components, and the
    # last step taken
    JT_loc: dict[int, Vec3] = field(default_factory=dict)
    node: Node | None = None
    # shared recursion: the inertial columns of J_T of coordinates without an angular part
    # (translations), the same vector for every frame below the step that formed them
    JT_fixed: dict[int, Vec3] = field(default_factory=dict)

    @property
    def S(self) -> Mat3:
        return self.tag.S

    @property
    def identity(self) -> bool:
        return self.tag is ROOT

    def copy(self) -> _Frame:
        return _Frame(self.r, dict(self.JT), self.v_bar, self.a_bar, dict(self.JR), self.omega,
                      self.omega_bar, self.alpha_bar, self.a_pieces, self.tag,
                      dict(self.JT_loc), self.node, dict(self.JT_fixed))


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
                self.dy[j] = pw_diff(s, sym)
        self.dt = pw_diff(s, ctx.t) if ctx.t in free else ZERO
        self.d1 = sum((c * ctx.yd[j] for j, c in self.dy.items()), self.dt)
        # d²s/dt² without the ÿ terms: d/dt of ṡ at constant ÿ
        d2 = pw_diff(self.d1, ctx.t) if (ctx.t in free) else ZERO
        for sym in free:
            j = ctx.index.get(sym)
            if j is not None:
                d2 = d2 + pw_diff(self.d1, sym) * ctx.yd[j]
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
    # the shared recursion (module docstring): its steps, the inertial frame's first
    shared: bool = False
    nodes: list[Node] = field(default_factory=list)

    def step(self, F: _Frame, A: Mat3 | None, d: Vec3 | None,
             anchors: tuple[tuple[int, Vec3, Vec3], ...]) -> None:
        """Record the step just applied to F (shared recursion only)."""
        if self.shared:
            F.node = Node(F.node, A, d, F.tag, F.JR, F.JT_loc, anchors, len(self.nodes))
            self.nodes.append(F.node)


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
    At = _times_t(A)
    F.JR = {
        j: At(_add(F.JR.get(j, Z3), _scale(u, rt.dy[j])) if j in rt.dy else F.JR[j])
        for j in keys
    }
    F.omega_bar = At(_add(F.omega_bar, _scale(u, rt.dt)))
    w_rel = _scale(u, rt.d1)
    F.alpha_bar = At(_add(_add(F.alpha_bar, _scale(u, rt.d2_local)), _cross(F.omega, w_rel)))
    F.omega = At(_add(F.omega, w_rel))
    if ctx.shared:
        F.JT_loc = {j: At(c) for j, c in F.JT_loc.items()}
        ctx.step(F, A, None, tuple((j, _scale(u, rt.dy[j]), Z3) for j in sorted(rt.dy)))


def _reorient(F: _Frame, R0: Mat3, ctx: _Context) -> None:
    """Apply a constant change of axes R0 (new axes in current-frame components)."""
    if R0 == IDENTITY:
        return
    F.tag = FrameTag(F.tag, R0, R0 if F.identity else _mm(F.S, R0), None)
    Rt = _times_t(R0)
    F.JR = {j: Rt(c) for j, c in F.JR.items()}
    F.omega, F.omega_bar, F.alpha_bar = (Rt(F.omega), Rt(F.omega_bar),
                                         Rt(F.alpha_bar))
    if ctx.shared:
        F.JT_loc = {j: Rt(c) for j, c in F.JT_loc.items()}
        ctx.step(F, R0, None, ())


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
    toI = (lambda v: v) if F.identity else _times(F.S)
    F.r = _add(F.r, toI(d))
    if ctx.shared:
        _translate_columns(F, d, rates, toI, ctx)
    else:
        _translate_inertial(F, d, rates, toI, ctx)
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


def _translate_inertial(F: _Frame, d: Vec3, rates: list[_Rates], toI: Callable[[Vec3], Vec3],
                        ctx: _Context) -> None:
    """The columns of J_T (inertial) after the translation by d, with their pieces."""
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


def _translate_columns(F: _Frame, d: Vec3, rates: list[_Rates], toI: Callable[[Vec3], Vec3],
                       ctx: _Context) -> None:
    """The columns of J_T in the frame's components after the translation by d (shared
    recursion): v_j + ω_j × d + ∂d/∂y_j, each a short expression of the one before."""
    keys = set(F.JT_loc) | set(F.JR) | {j for rt in rates for j in rt.dy}
    new = {}
    anchors = []
    for j in sorted(keys):
        col = F.JT_loc.get(j, Z3)
        if j in F.JR:
            col = _add(col, _cross(F.JR[j], d))
        dj = tuple(rt.dy.get(j, ZERO) for rt in rates)
        if not _is_zero(dj):
            col = _add(col, dj)
            anchors.append((j, Z3, dj))
            if j not in F.JR:  # S·(Sᵀ·v) of later frames would only repeat this vector
                F.JT_fixed[j] = toI(col)
        new[j] = col
    F.JT_loc = new
    ctx.step(F, None, d, tuple(anchors))


def _joint_steps(F: _Frame, joint: Joint, ctx: _Context) -> None:
    """Apply a joint's constant orientation and its elementary steps to the frame at the joint
    point."""
    _reorient(F, joint.orientation, ctx)
    for step in joint.steps:
        if isinstance(step, Rot):
            _rotate(F, step.axis, step.angle, ctx)
        elif isinstance(step, Trans):
            _translate(F, step.vector, ctx)
