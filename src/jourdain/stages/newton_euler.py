"""Newton–Euler equations of the free bodies (``docs/method.md`` §2):

    M̄ · J̄ · ÿ + q̄^c = q̄^e + Q̄ · g

Produces M̄ (``M_bar``), J̄ (``J_bar``), q̄^c (``q_c``), q̄^e (``q_e``) and the forces on each
body (:class:`NewtonEuler`); Q̄ and g are the reactions stage's (:mod:`jourdain.stages.reactions`).

Rows are ordered as in the seed: the 3p translational rows of all bodies (inertial frame), then the
3p rotational rows (each body's own frame, about its centre of mass).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import symengine as se

from ..errors import ModelError
from ..measures import Resolver, bushing_deflection, bushing_loads, bushing_wrench
from ..model.bodies import WORLD, Body
from ..model.forces import (
    Bushing,
    Force,
    GeneralizedForce,
    Gravity,
    SpringDamper,
    Torque,
    deflection,
    deflection_d,
    rate,
)
from ..model.joints import IDENTITY, Joint, Mat3, Rot, Vec3, rotation_matrix
from ..symbolic import SymMatrix
from .kinematics import (
    Z3,
    BodyKinematics,
    Kinematics,
    _add,
    _cross,
    _dot,
    _mm,
    _mtv,
    _mv,
    _scale,
    step_axis,
)
from .planar import check_planar

if TYPE_CHECKING:
    from ..model.system import System

ZERO = se.Integer(0)


@dataclass(frozen=True)
class BodyForces:
    """Resultant applied force ``f`` (inertial, at the centre of mass) and torque ``l`` (body
    frame, about the centre of mass) on one body: its rows of q̄^e.

    ``f = f_other + m·gravity``: ``gravity`` is the field strength of the model's Gravity elements
    (inertial) and ``f_other`` the rest, kept apart so that the projection can collect masses.
    """

    name: str
    f: Vec3
    l: Vec3
    f_other: Vec3 = (ZERO, ZERO, ZERO)
    gravity: Vec3 = (ZERO, ZERO, ZERO)


@dataclass(frozen=True)
class NewtonEuler:
    """Result of :func:`newton_euler`.

    Attributes
    ----------
    M_bar : SymMatrix (6p×6p)
        ``diag(m_1 E, …, m_p E, I_1, …, I_p)``.
    J_bar : SymMatrix (6p×f)
        ``[J_T1; …; J_Tp; J_R1; …; J_Rp]``.
    q_c : SymMatrix (6p×1)
        ``[m_i ā_i; …; I_i ᾱ_i + ω̃_i I_i ω_i; …]``: Coriolis, centrifugal and gyroscopic forces.
    q_e : SymMatrix (6p×1)
        ``[f_i^e; …; l_i^e; …]``: applied forces (inertial) and torques (body frames).
    joints : tuple of (Joint, child body name, parent name)
        The joints whose constrained directions form Q̄ (reactions stage).
    kinematics : Kinematics
    forces : tuple of BodyForces
    """

    kinematics: Kinematics
    M_bar: SymMatrix
    J_bar: SymMatrix
    q_c: SymMatrix
    q_e: SymMatrix
    joints: tuple[tuple[Joint, str, str], ...]
    forces: tuple[BodyForces, ...]

    @property
    def system(self) -> System:
        return self.kinematics.system


def newton_euler(kin: Kinematics) -> NewtonEuler:
    """Assemble M̄, J̄, q̄^c and q̄^e from the kinematics of every body."""
    system = kin.system
    bodies = system.bodies
    p = len(bodies)
    check_planar(kin)  # a planar inertia holds where ω stays about its axis
    # q̄^c: Newton m ā, Euler I ᾱ + ω × (I ω)
    qc_T: list[se.Basic] = []
    qc_R: list[se.Basic] = []
    for body, bk in zip(bodies, kin.bodies, strict=True):
        qc_T.extend(_scale(_v(bk.a_bar), body.mass))
        qc_R.extend(_euler_gyro(body, bk))
    forces = applied_forces(kin)
    qe = [x for bf in forces for x in bf.f] + [x for bf in forces for x in bf.l]
    # M̄ block diagonal
    n = 6 * p
    rows = [[ZERO] * n for _ in range(n)]
    for i, body in enumerate(bodies):
        for a in range(3):
            rows[3 * i + a][3 * i + a] = body.mass
            for b in range(3):
                rows[3 * p + 3 * i + a][3 * p + 3 * i + b] = body.inertia[a][b]
    J_bar = SymMatrix(tuple(r for bk in kin.bodies for r in bk.J_T.rows)
                      + tuple(r for bk in kin.bodies for r in bk.J_R.rows))
    joints = tuple((b.joint, b.name, b.parent) for b in bodies)
    return NewtonEuler(kin, SymMatrix.from_rows(rows), J_bar, SymMatrix.column(qc_T + qc_R),
                       SymMatrix.column(qe), joints, forces)


def _v(m: SymMatrix) -> Vec3:
    return (m.rows[0][0], m.rows[1][0], m.rows[2][0])


def _euler_gyro(body: Body, bk: BodyKinematics) -> Vec3:
    if not body.has_inertia:
        return Z3
    I = body.inertia
    w = _v(bk.omega)
    return _add(_mv(I, _v(bk.alpha_bar)), _cross(w, _mv(I, w)))


class _Accumulator:
    """Per-body resultant force (inertial) and torque about the centre of mass (body frame)."""

    def __init__(self, kin: Kinematics) -> None:
        self.kin = kin
        self.sys = kin.system
        self.f: dict[str, list[list[se.Basic]]] = {b.name: [[], [], []] for b in self.sys.bodies}
        self.l: dict[str, list[list[se.Basic]]] = {b.name: [[], [], []] for b in self.sys.bodies}
        self.gravity: Vec3 = Z3

    def S(self, name: str) -> Mat3:
        return self.kin[name].S.rows  # type: ignore[return-value]

    def to_body(self, vec: Vec3, frame: str, body: str) -> tuple[Vec3, Vec3]:
        """(inertial, body-frame) components of ``vec`` given in ``frame``."""
        if frame == body:
            return _mv(self.S(body), vec), vec
        vI = vec if frame == WORLD else _mv(self.S(frame), vec)
        return vI, _mtv(self.S(body), vI)

    def add_force(self, body: str, F_I: Vec3, F_B: Vec3, point: Vec3) -> None:
        """Force (inertial F_I = S·F_B) acting at ``point`` of ``body`` (body frame)."""
        if body == WORLD:
            return
        c = self.sys.body(body).com
        arm = (point[0] - c[0], point[1] - c[1], point[2] - c[2])
        for a in range(3):
            self.f[body][a].append(F_I[a])
        self.add_torque(body, _cross(arm, F_B))

    def add_torque(self, body: str, T_B: Vec3) -> None:
        if body == WORLD:
            return
        for a in range(3):
            self.l[body][a].append(T_B[a])

    def result(self) -> tuple[BodyForces, ...]:
        out = []
        for b in self.sys.bodies:
            other = tuple(se.Add(*c) if c else ZERO for c in self.f[b.name])
            weight = _scale(self.gravity, b.mass) if b.mass != 0 else Z3
            out.append(BodyForces(b.name, _add(other, weight), tuple(
                se.Add(*c) if c else ZERO for c in self.l[b.name]), other, self.gravity))
        return tuple(out)


def applied_forces(kin: Kinematics, elements: Sequence[object] | None = None
                   ) -> tuple[BodyForces, ...]:
    """Resultant applied force and torque on every body from the model's force elements (or
    from ``elements`` only, for example one element to trace a fault to it).

    Kinematic quantities in the force laws (:mod:`jourdain.model.quantities`) are replaced by
    their expressions in y, ẏ, t here (:class:`jourdain.measures.Resolver`)."""
    acc = _Accumulator(kin)
    sys = kin.system
    res = Resolver(kin)
    for fe in sys.forces if elements is None else elements:
        if isinstance(fe, Gravity):
            acc.gravity = _add(acc.gravity, fe.vector)
        elif isinstance(fe, Force):
            F_I, F_B = acc.to_body(res.resolve_all(fe.vector), fe.frame, fe.body)
            if fe.body != WORLD:
                point = res.frames.body_point(fe.body, fe.point, fe.point_frame)
                acc.add_force(fe.body, F_I, F_B, point)
        elif isinstance(fe, Torque):
            _, T_B = acc.to_body(res.resolve_all(fe.vector), fe.frame, fe.body)
            acc.add_torque(fe.body, T_B)
        elif isinstance(fe, SpringDamper):
            _spring_damper(acc, fe, res)
        elif isinstance(fe, GeneralizedForce):
            _generalized_force(acc, sys, fe, res)
        elif isinstance(fe, Bushing):
            _bushing(acc, fe, res)
    return acc.result()


def _bushing(acc: _Accumulator, fe: Bushing, res: Resolver) -> None:
    """A bushing's wrench on its two bodies (see :class:`jourdain.model.forces.Bushing`)."""
    frames = res.frames
    x, xd, geo = bushing_deflection(frames, fe)
    w = res.resolve_all(bushing_wrench(fe, x, xd))
    for body, F_I, vec, point in bushing_loads(frames, fe, w, geo):
        if F_I is not None:
            acc.add_force(body, F_I, vec, point)
        else:
            acc.add_torque(body, vec)


def _spring_damper(acc: _Accumulator, fe: SpringDamper, res: Resolver) -> None:
    ra, va = res.frames.point(fe.body_a, fe.point_a)
    rb, vb = res.frames.point(fe.body_b, fe.point_b)
    d = (rb[0] - ra[0], rb[1] - ra[1], rb[2] - ra[2])
    L = se.sqrt(_dot(d, d))
    e = _scale(d, 1 / L)
    L_d = _dot(e, (vb[0] - va[0], vb[1] - va[1], vb[2] - va[2]))
    T = res.resolve(fe.tension(L, L_d))
    F_on_a = _scale(e, T)  # tension pulls a towards b
    F_on_b = _scale(e, -T)
    for body, point, F in ((fe.body_a, fe.point_a, F_on_a), (fe.body_b, fe.point_b, F_on_b)):
        if body != WORLD:
            acc.add_force(body, F, _mtv(acc.S(body), F), point)


def joint_step_frames(joint: Joint) -> list[tuple[Mat3, Vec3, Mat3]]:
    """For each step k of ``joint``: (R_before, p_before, R_after).

    R_before turns the frame before step k into the parent's body frame, p_before is that frame's
    origin in the parent frame; R_after turns the child body frame into the frame after step k.
    """
    R, pvec = joint.orientation, joint.position
    before = []
    for s in joint.steps:
        before.append((R, pvec))
        if isinstance(s, Rot):
            R = _mm(R, rotation_matrix(s.axis, s.angle))
        else:
            pvec = _add(pvec, _mv(R, s.vector))
    out = []
    for k, (Rb, pb) in enumerate(before):
        Ra = IDENTITY
        for s in joint.steps[k + 1:]:
            if isinstance(s, Rot):
                Ra = _mm(Ra, rotation_matrix(s.axis, s.angle))
        out.append((Rb, pb, Ra))
    return out


def _generalized_force(acc: _Accumulator, sys: System, fe: GeneralizedForce,
                       res: Resolver) -> None:
    """Realize a generalized force on a coordinate as a torque/force pair on its joint step; on
    an expression e(y, t), the shares ``value·∂e/∂y_j`` on each coordinate y_j (virtual work)."""
    if fe.on_coordinate:
        c = fe.coordinate
        value = res.resolve(fe.value.subs({deflection: c, deflection_d: rate(c)}))
        _coordinate_pair(acc, sys, fe, c, value)
        return
    e = res.resolve(fe.coordinate)
    bad = sorted({str(s) for s in e.free_symbols} & {str(r) for r in res.kin.yd})
    if bad:
        raise ModelError(f'generalized force "{fe.name}": its coordinate {fe.coordinate} depends '
                         f"on the rates {bad}; it must be an expression of the coordinates, the "
                         "parameters and t (positions, relative positions and distances among "
                         "the kinematic quantities)")
    value = res.resolve(fe.value.subs({deflection: e, deflection_d: res.rate(e)}))
    free = e.free_symbols
    shares = [(y, se.diff(e, y)) for y in res.kin.y if y in free]
    if not shares:
        raise ModelError(f'generalized force "{fe.name}": its coordinate {fe.coordinate} does '
                         "not depend on any coordinate, so the force does no virtual work")
    for y, de in shares:
        if de != 0:
            _coordinate_pair(acc, sys, fe, y, value * de)


def _coordinate_pair(acc: _Accumulator, sys: System, fe: GeneralizedForce, coordinate: se.Basic,
                     value: se.Basic) -> None:
    """The generalized force ``value`` on ``coordinate`` as a torque/force pair on the two
    bodies of the joint step that the coordinate drives."""
    for body in sys.bodies:
        j = body.joint
        for k, step in enumerate(j.steps):
            if step.parameter is not None and step.parameter == coordinate:
                Rb, _, Ra = joint_step_frames(j)[k]
                u = step_axis(step)
                v_child = _mtv(Ra, _scale(u, value))
                v_parent = _scale(_mv(Rb, u), -value)
                if isinstance(step, Rot):
                    acc.add_torque(body.name, v_child)
                    acc.add_torque(body.parent, v_parent)
                else:
                    # force pair at the child frame's origin
                    acc.add_force(body.name, _mv(acc.S(body.name), v_child), v_child, Z3)
                    if body.parent != WORLD:
                        p_child = joint_child_origin(j)
                        acc.add_force(body.parent, _mv(acc.S(body.parent), v_parent), v_parent,
                                      p_child)
                return
    raise ModelError(
        f'generalized force "{fe.name}": coordinate "{coordinate}" is not the angle or distance '
        "of a single joint step (Rot/Trans with that coordinate alone); apply it as forces or "
        "torques on bodies instead"
    )


def joint_transform(joint: Joint) -> tuple[Mat3, Vec3]:
    """(R, p): the child body frame's axes and origin in the parent's body frame
    (x_parent = p + R·x_child), from the joint's position, orientation and steps."""
    R, pvec = joint.orientation, joint.position
    for s in joint.steps:
        if isinstance(s, Rot):
            R = _mm(R, rotation_matrix(s.axis, s.angle))
        else:
            pvec = _add(pvec, _mv(R, s.vector))
    return R, pvec


def joint_child_origin(joint: Joint) -> Vec3:
    """Origin of the child body frame in the parent's body frame."""
    return joint_transform(joint)[1]

