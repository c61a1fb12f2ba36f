"""Kinematic quantities of points and bodies as expressions of y, ẏ, t, for force laws.

Built from the kinematics of the bodies (:mod:`jourdain.stages.kinematics`, METHOD.md §1): positions
``r = r_O + S·p``, velocities ``v = J_T·ẏ + v̄``, angular velocities ``ω = J_R·ẏ + ω̄`` (body
frame). :class:`Resolver` replaces the symbols of the :mod:`kinematic quantities
<jourdain.model.quantities>` in force expressions by these expressions, so q̄^e, q and the
linearization contain them exactly. :func:`bushing_wrenches` gives the deflection of a
:class:`jourdain.model.forces.Bushing` and the wrenches on its two bodies.
"""

from __future__ import annotations

from collections.abc import Mapping

import symengine as se

from .errors import ModelError
from .model.bodies import WORLD
from .model.forces import BUSHING_COMPONENTS, Bushing, deflection, deflection_d
from .model.joints import IDENTITY, Mat3, Vec3
from .model.quantities import Quantity
from .stages.kinematics import (
    Z3,
    BodyKinematics,
    Kinematics,
    _add,
    _cross,
    _dot,
    _mm,
    _mtm,
    _mtv,
    _mv,
    _scale,
    _vec,
)

ZERO = se.Integer(0)
HALF = se.Rational(1, 2)


def _sub(a: Vec3, b: Vec3) -> Vec3:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


class Frames:
    """Orientation, origin, velocities and angular velocity of each body frame (and of the
    inertial frame, ``"world"``) as expressions of y, ẏ, t."""

    def __init__(self, kin: Kinematics) -> None:
        self.kin = kin

    def S(self, body: str) -> Mat3:
        """Body → inertial rotation (identity for the world)."""
        return IDENTITY if body == WORLD else self.kin[body].S.rows  # type: ignore[return-value]

    def omega(self, body: str) -> Vec3:
        """Angular velocity in the body's own axes, ``J_R·ẏ + ω̄``."""
        return Z3 if body == WORLD else _vec(self.kin[body].omega)

    def to_frame(self, vec_I: Vec3, frame: str) -> Vec3:
        """Components in ``frame`` of an inertial vector."""
        return vec_I if frame == WORLD else _mtv(self.S(frame), vec_I)

    def to_inertial(self, vec: Vec3, frame: str) -> Vec3:
        return vec if frame == WORLD else _mv(self.S(frame), vec)

    def point(self, body: str, p: Vec3) -> tuple[Vec3, Vec3]:
        """Inertial position and velocity of the point ``p`` (body frame) of ``body``."""
        if body == WORLD:
            return p, Z3
        r, v, _, _ = self._state(self.kin[body], p)
        return r, v

    def _state(self, bk: BodyKinematics, p: Vec3) -> tuple[Vec3, Vec3, dict[int, Vec3], Vec3]:
        """Position, velocity ``J_T·ẏ + v̄``, J_T columns and ā of the point ``p`` (body
        frame) of the body ``bk``."""
        r, cols, v_bar, a_bar = bk.point(p)
        v = v_bar
        for j, c in sorted(cols.items()):
            v = _add(v, _scale(c, self.kin.yd[j]))
        return r, v, dict(cols), a_bar

    def body_point(self, body: str, p: Vec3, point_frame: str) -> Vec3:
        """The coordinates in ``body``'s frame of the place ``p`` given in ``point_frame``
        (the material point of ``body`` that is there at the instant)."""
        if point_frame == body:
            return p
        r, _ = self.point(point_frame, p)
        return _mtv(self.S(body), _sub(r, _vec(self.kin[body].r_O)))

    def material_point(self, body: str, p: Vec3, point_frame: str
                       ) -> tuple[Vec3, Vec3, dict[int, Vec3], Vec3]:
        """Position, velocity, J_T columns and ā (inertial) of the material point of ``body``
        at the point ``p`` given in ``point_frame``."""
        if point_frame == body:
            if body == WORLD:
                return p, Z3, {}, Z3
            return self._state(self.kin[body], p)
        # where the point is now, then the body-frame coordinates of that place: the material
        # point's velocity and acceleration follow from the body's motion alone
        r, _ = self.point(point_frame, p)
        if body == WORLD:
            return r, Z3, {}, Z3
        bk = self.kin[body]
        p_body = _mtv(self.S(body), _sub(r, _vec(bk.r_O)))
        # ṗ_body ≠ 0 in general, but the material point is the one at p_body *now*: its
        # velocity and acceleration are those of the body point p_body held fixed
        return self._state(bk, p_body)


class Resolver:
    """Replaces the symbols of kinematic quantities in expressions by their definitions."""

    def __init__(self, kin: Kinematics) -> None:
        self.kin = kin
        self.frames = Frames(kin)
        self.values: dict[str, tuple[se.Basic, ...]] = {}

    def value(self, q: Quantity) -> tuple[se.Basic, ...]:
        """The components of ``q`` (3 for a vector, 1 for a scalar)."""
        out = self.values.get(q.name)
        if out is None:
            out = self._compute(q)
            self.values[q.name] = out
        return out

    def _compute(self, q: Quantity) -> tuple[se.Basic, ...]:
        F = self.frames
        if q.kind == "angular_velocity":
            w_I = F.to_inertial(F.omega(q.body), q.body)
            return F.to_frame(w_I, q.frame) if q.frame != q.body else F.omega(q.body)
        r, v, cols, a_bar = F.material_point(q.body, q.point, q.point_frame)
        if q.kind == "position":
            return F.to_frame(r, q.frame)
        if q.kind == "velocity":
            return F.to_frame(v, q.frame)
        if q.kind == "acceleration":
            moving = [str(self.kin.y[j]) for j, c in sorted(cols.items())
                      if any(x != 0 for x in c)]
            if moving:
                raise ModelError(
                    f'quantity "{q.name}": {q.describe()}: the acceleration of this point '
                    f"depends on the accelerations of {moving} (a = J_T·ÿ + ā); a force law "
                    "using it would put ÿ into q and make the equations of motion implicit, which jourdain "
                    "does not support. Accelerations may be used only for points whose motion "
                    "is prescribed (no coordinate); for others, write the force law with "
                    "positions and velocities")
            return F.to_frame(a_bar, q.frame)
        rb, vb, _, _ = F.material_point(q.body_b, q.point_b, q.body_b)  # type: ignore[arg-type]
        d = _sub(rb, r)
        if q.kind == "relative_position":
            return F.to_frame(d, q.frame)
        if q.kind == "relative_velocity":
            return F.to_frame(_sub(vb, v), q.frame)
        L = se.sqrt(_dot(d, d))
        if q.kind == "distance":
            return (L,)
        return (_dot(d, _sub(vb, v)) / L,)  # distance_rate

    def resolve(self, e: se.Basic) -> se.Basic:
        """``e`` with every quantity symbol replaced by its expression in y, ẏ, t."""
        subs = {}
        for s in e.free_symbols:
            q = getattr(s, "quantity", None)
            if q is not None:
                vals = self.value(q)
                subs[s] = vals[0 if s.component is None else s.component]
        return e.subs(subs) if subs else e

    def resolve_all(self, exprs: tuple) -> tuple:
        return tuple(self.resolve(e) for e in exprs)

    def rate(self, e: se.Basic) -> se.Basic:
        """Total time derivative of an expression of y and t: ``Σ ∂e/∂y_j·ẏ_j + ∂e/∂t``."""
        kin = self.kin
        free = e.free_symbols
        terms = [se.diff(e, y) * yd for y, yd in zip(kin.y, kin.yd, strict=True) if y in free]
        if kin.t in free:
            terms.append(se.diff(e, kin.t))
        return se.Add(*terms) if terms else ZERO


def _trace(A: Mat3) -> se.Basic:
    return A[0][0] + A[1][1] + A[2][2]


def relative_rotation_of(frames: Frames, a: str, b: str) -> Mat3:
    """``R = S_aᵀ·S_b``: the axes of b in a's components."""
    if a == WORLD:
        return frames.S(b)
    if b == WORLD:
        Sa = frames.S(a)
        return tuple(tuple(Sa[j][i] for j in range(3)) for i in range(3))  # type: ignore
    return _mtm(frames.S(a), frames.S(b))


def rotation_measure(R: Mat3) -> Vec3:
    """``s = ½·vee(R − Rᵀ) = sin θ·n`` of a rotation R by θ about n (see :class:`Bushing`)."""
    return (HALF * (R[2][1] - R[1][2]), HALF * (R[0][2] - R[2][0]), HALF * (R[1][0] - R[0][1]))


def rotation_measure_rate_matrix(R: Mat3) -> Mat3:
    """``H = ½(tr R·E − R)``, with ``ṡ = H·ω_rel`` and ``δs = H·δφ_rel`` (ω_rel, δφ_rel the
    angular velocity and virtual rotation of b relative to a, in a's axes)."""
    tr = _trace(R)
    return tuple(tuple(HALF * ((tr if i == j else ZERO) - R[i][j]) for j in range(3))
                 for i in range(3))  # type: ignore[return-value]


def _turn(R: Mat3, v: Vec3) -> Vec3:
    """R·v, v itself for the identity (no products of ones and zeros in the expressions)."""
    return v if R == IDENTITY else _mv(R, v)


def _turn_back(R: Mat3, v: Vec3) -> Vec3:
    """Rᵀ·v"""
    return v if R == IDENTITY else _mtv(R, v)


def bushing_deflection(frames: Frames, fe: Bushing
                       ) -> tuple[tuple[se.Basic, ...], tuple[se.Basic, ...], dict]:
    """Deflection x (6), its rate ẋ (6) and the geometry needed for the wrenches
    (a :class:`Bushing`'s docstring gives the definitions). The ends' axes are the bodies'
    turned by the constant ``axes_a``, ``axes_b``: ``S_A = S_a·A_a``, ``S_B = S_b·A_b``."""
    a, b = fe.body_a, fe.body_b
    Aa, Ab = fe.axes_a, fe.axes_b
    at_a = fe.frame == a
    body_F, A_F = (a, Aa) if at_a else (b, Ab)
    ra, va = frames.point(a, fe.point_a)
    rb, vb = frames.point(b, fe.point_b)
    R_ab = relative_rotation_of(frames, a, b)
    R = R_ab
    if Aa != IDENTITY:
        R = _mtm(Aa, R)
    if Ab != IDENTITY:
        R = _mm(R, Ab)
    H = rotation_measure_rate_matrix(R)
    w_A = _turn_back(Aa, frames.omega(a))
    w_B = _turn_back(Ab, frames.omega(b))
    w_rel = _sub(_mv(R, w_B), w_A)  # end a's axes
    d = _turn_back(A_F, frames.to_frame(_sub(rb, ra), body_F))
    w_F = _turn_back(A_F, frames.omega(body_F))
    dd = _sub(_turn_back(A_F, frames.to_frame(_sub(vb, va), body_F)), _cross(w_F, d))
    s = rotation_measure(R)
    sd = _mv(H, w_rel)
    geo = {"R": R, "H": H, "d": d, "body_F": body_F, "A_F": A_F}
    return (*d, *s), (*dd, *sd), geo


def bushing_wrench(fe: Bushing, x: tuple, xd: tuple,
                   resolve: Mapping | None = None) -> tuple[se.Basic, ...]:
    """``w = preload − K·x − C·ẋ`` (laws replacing their rows): the wrench on body b, conjugate
    to x, in the bushing's frame."""
    out = []
    for i in range(6):
        law = fe.laws[i]
        if law is not None:
            out.append(fe.preload[i] - law.subs({deflection: x[i], deflection_d: xd[i]}))
            continue
        terms = [fe.preload[i]]
        terms += [-fe.stiffness[i][j] * x[j] for j in range(6) if fe.stiffness[i][j] != 0]
        terms += [-fe.damping[i][j] * xd[j] for j in range(6) if fe.damping[i][j] != 0]
        out.append(se.Add(*terms))
    return tuple(out)


def bushing_loads(frames: Frames, fe: Bushing, w: tuple, geo: dict
                  ) -> list[tuple[str, Vec3 | None, Vec3, Vec3]]:
    """The loads of wrench ``w`` (on b, conjugate to x) on the two bodies, from the virtual
    work ``wᵀ·δx`` with ``δd = S_Fᵀ(δr_b − δr_a) − δφ_F × d`` and ``δs = H·(δφ_B − δφ_A)``:

    * the force ``S_F·f`` at point b on body b, ``−S_F·f`` at point a on body a;
    * the torque ``−d × f`` (frame F's axes) on the body of frame F;
    * the torque ``Hᵀ·m`` (end a's axes) on body b and ``−Hᵀ·m`` on body a.

    Returns ``(body, inertial force or None for a torque, vector in the body's axes, point)``
    for each load (the world's are left out)."""
    a, b = fe.body_a, fe.body_b
    body_F, A_F = geo["body_F"], geo["A_F"]
    f, m = tuple(w[:3]), tuple(w[3:])
    R, H, d = geo["R"], geo["H"], geo["d"]
    minus = se.Integer(-1)
    f_body = _turn(A_F, f)
    f_I = frames.to_inertial(f_body, body_F)
    out: list[tuple[str, Vec3 | None, Vec3, Vec3]] = []
    if b != WORLD:
        out.append((b, f_I, f_body if body_F == b else frames.to_frame(f_I, b), fe.point_b))
    if a != WORLD:
        f_a = f_body if body_F == a else frames.to_frame(f_I, a)
        out.append((a, _scale(f_I, minus), _scale(f_a, minus), fe.point_a))
    if body_F != WORLD:
        out.append((body_F, None, _turn(A_F, _scale(_cross(d, f), minus)), Z3))
    Hm = _mtv(H, m)
    if any(v != 0 for v in Hm):
        if b != WORLD:
            out.append((b, None, _turn(fe.axes_b, _mtv(R, Hm)), Z3))
        if a != WORLD:
            out.append((a, None, _turn(fe.axes_a, _scale(Hm, minus)), Z3))
    return out


__all__ = ["BUSHING_COMPONENTS", "Frames", "Resolver", "bushing_deflection", "bushing_loads",
           "bushing_wrench", "rotation_measure", "rotation_measure_rate_matrix"]
