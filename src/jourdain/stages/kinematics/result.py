"""The kinematics stage (``docs/method.md`` §1): :func:`kinematics` gives every body's r, S, ω,
J_T, J_R, v̄, ω̄, ā, ᾱ (:class:`BodyKinematics`, :class:`Kinematics`); :func:`joint_motions`
gives each joint's relative motion (:class:`JointMotion`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType
from typing import TYPE_CHECKING

import symengine as se

from ...errors import refuse_closed
from ...identity import IdentityMap
from ...model.forces import acceleration, rate
from ...model.joints import Mat3, Vec3
from ...symbolic import SymMatrix

if TYPE_CHECKING:
    from ...model.system import System
from .frames import Node
from .recursion import _Context, _Frame, _joint_steps, _translate
from .vectors import Z3, _add, _cross, _dense, _mat, _mv, _times, _vec


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
    #: shared kinematics: the step at the centre of mass (its frame is the body frame moved
    #: to the centre of mass), in :attr:`Kinematics.nodes`
    node: Node | None = field(default=None, repr=False, compare=False)

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
    #: shared kinematics (:func:`kinematics`): the elementary steps of the recursion, parents
    #: first, the inertial frame's first; None otherwise
    nodes: tuple[Node, ...] | None = field(default=None, repr=False, compare=False)

    def __getitem__(self, name: str) -> BodyKinematics:
        for b in self.bodies:
            if b.name == name:
                return b
        self.system.body(name)  # raises ModelError naming the body
        raise KeyError(name)


#: systems with at least this many coordinates get the shared kinematics by default: below,
#: the body-by-body sums read like a textbook's (a double pendulum's M), are the shortest
#: code for planar chains, and are what the integrator compiles up to
#: ``jourdain.numeric.cost.SYMBOLIC_MAX_F`` = 24 coordinates
SHARED_FROM_F = 25


def kinematics(system: System, shared: bool | None = None) -> Kinematics:
    """Kinematics of every body of ``system`` (METHOD.md §1), built recursively along the tree.

    ``shared`` (default: ``f >= SHARED_FROM_F``): carry the Jacobian columns in each frame's
    own components and record the steps (:attr:`Kinematics.nodes`), so that the projection can
    form M, k, q from composite bodies (:mod:`jourdain.stages.composite`) in time and memory
    that grow like f² instead of f³; J_T of each body is then ``S·(local column)``, a short
    expression of shared ones, rather than the sum of the pieces ``S_k·v_k`` of every step
    above, which reads better but grows with the depth of the tree.

    A closed system (with closing joints) is refused with :class:`ClosedSystemError`: every
    stage after this one would treat it as the open tree. Its kinematics are its tree's,
    ``kinematics(system.tree)``, and the closing joints enter through the constraint stage
    (:func:`jourdain.stages.constraints.constraints`)."""
    refuse_closed(system, "the tree-only stages (kinematics and all that is derived from it "
                  "for a tree) would leave the loops open",
                  "use the system's own methods or functions (evaluate, simulate, linearize, "
                  "reactions), or system.tree for the open tree")
    y = system.coordinates
    f = len(y)
    ctx = _Context({c: i for i, c in enumerate(y)}, tuple(rate(c) for c in y), system.t,
                   shared=f >= SHARED_FROM_F if shared is None else shared)
    world = _Frame()
    if ctx.shared:
        ctx.step(world, None, None, ())
    frames: dict[str, _Frame] = {"world": world}
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
        if ctx.shared:
            F.JT, C.JT = _inertial(F), _inertial(C)
        col = SymMatrix.column
        out.append(BodyKinematics(
            name=body.name, r=col(C.r), S=SymMatrix.from_rows(F.S), omega=col(F.omega),
            J_T=_dense(C.JT, f), J_R=_dense(F.JR, f), v_bar=col(C.v_bar),
            omega_bar=col(F.omega_bar), a_bar=col(C.a_bar), alpha_bar=col(F.alpha_bar),
            r_O=col(F.r), J_T_O=_dense(F.JT, f), v_bar_O=col(F.v_bar), a_bar_O=col(F.a_bar),
            cols_T=MappingProxyType(C.JT), cols_R=MappingProxyType(F.JR),
            cols_T_O=MappingProxyType(F.JT), a_bar_pieces=C.a_pieces, node=C.node,
        ))
    return Kinematics(system, tuple(out), y, ctx.yd, tuple(acceleration(c) for c in y), system.t,
                      ctx.pieces, tuple(ctx.nodes) if ctx.shared else None)


def _inertial(F: _Frame) -> dict[int, Vec3]:
    """The columns of J_T of F's origin in inertial components: S·(local column), or the
    vector formed at the step of a coordinate without an angular part."""
    if F.identity:
        return dict(F.JT_loc)
    S, JR, fixed = _times(F.S), F.JR, F.JT_fixed
    return {j: fixed[j] if j in fixed and j not in JR else S(c)
            for j, c in F.JT_loc.items()}


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
