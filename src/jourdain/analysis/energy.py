"""Kinetic and potential energy of a system, from the body velocities and positions.

``T = ½ Σ_i (m_i v_iᵀ v_i + ω_iᵀ I_i ω_i)`` with ``v_i = J_Ti·ẏ + v̄_i`` (inertial frame, centre
of mass) and ``ω_i = J_Ri·ẏ + ω̄_i`` (body frame, where ``I_i`` is constant), so rheonomic terms
are included. ``V`` is the potential of gravity (``-Σ m_i gᵀ r_i``), of linear spring–dampers
(``½ c (L - L₀)²``) and of generalized forces linear in their own coordinate
(``Q = a + b·y`` gives ``V = -(a·y + ½ b·y²)``, e.g. rotational springs; likewise on an expression
e of the coordinates, ``Q = a + b·e``), and of bushings without damping and laws whose stiffness
is symmetric (``V = ½ xᵀK x − w₀ᵀx`` in the deflection x). Every other applied force (and any
force law with kinematic quantities) is non-conservative; its work is what the simulation's
energy balance reports.

These expressions are computed independently of ``M`` and ``k``, so the energy along a simulated
motion checks the equations of motion as well as the integrator.
"""

from __future__ import annotations

from dataclasses import dataclass

import symengine as se

from ..measures import Frames, bushing_deflection
from ..model.bodies import WORLD
from ..model.expressions import free_names
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
from ..model.validation import force_expressions  # moved out of model.system (issue 16)
from ..stages.kinematics import Kinematics

ZERO = se.Integer(0)


@dataclass(frozen=True)
class Energy:
    """Result of :func:`energy`.

    Attributes
    ----------
    T : kinetic energy, an expression in y, ẏ, t and parameters
    V : potential energy of the conservative force elements, in y, t and parameters
    conservative : True when no force does work other than through ``V`` and the kinematics
        does not depend on time explicitly (then ``T + V`` is constant along a motion)
    nonconservative : names of the force elements whose work is not in ``V``
    rheonomic : the kinematics depends on time explicitly (a prescribed motion, whose drive
        does work that no force element accounts for)
    """

    kinematics: Kinematics
    T: se.Basic
    V: se.Basic
    conservative: bool
    nonconservative: tuple[str, ...]
    rheonomic: bool = False


def _dot(a: tuple, b: tuple) -> se.Basic:
    return se.Add(*(x * y for x, y in zip(a, b, strict=True)))


def energy(kin: Kinematics) -> Energy:
    """Kinetic energy ``T`` and potential energy ``V`` of ``kin.system`` (see module docs)."""
    sys = kin.system
    yd = kin.yd
    T_terms: list[se.Basic] = []
    pos: dict[str, tuple] = {}
    for body, bk in zip(sys.bodies, kin.bodies, strict=True):
        v = tuple(
            se.Add(*(bk.J_T[i, j] * yd[j] for j in bk.cols_T), bk.v_bar[i, 0]) for i in range(3)
        )
        w = tuple(bk.omega[i, 0] for i in range(3))
        pos[body.name] = tuple(bk.r[i, 0] for i in range(3))
        if body.mass != 0:
            T_terms.append(body.mass * _dot(v, v))
        Iw = tuple(se.Add(*(body.inertia[i][j] * w[j] for j in range(3))) for i in range(3))
        T_terms.append(_dot(w, Iw))
    T = se.Rational(1, 2) * se.Add(*T_terms)

    V_terms: list[se.Basic] = []
    noncons: list[str] = []
    rates = {str(r) for r in yd}
    inputs = set(sys.input_names)
    rows: dict[se.Basic, tuple[se.Basic, dict[se.Basic, se.Basic], str]] = {}
    for fe in sys.forces:
        if isinstance(fe, Gravity):
            for body in sys.bodies:
                if body.mass != 0:
                    V_terms.append(-body.mass * _dot(fe.vector, pos[body.name]))
        elif _has_quantities(fe):
            noncons.append(fe.name)
        elif isinstance(fe, SpringDamper):
            if fe.law is not None or fe.damping != 0:
                noncons.append(fe.name)
            if fe.law is None:
                ra = _point(kin, fe.body_a, fe.point_a)
                rb = _point(kin, fe.body_b, fe.point_b)
                d = tuple(b - a for a, b in zip(ra, rb, strict=True))
                L = se.sqrt(_dot(d, d))
                V_terms.append(se.Rational(1, 2) * fe.stiffness * (L - fe.rest_length) ** 2)
        elif isinstance(fe, GeneralizedForce):
            c = fe.coordinate
            if not fe.on_coordinate:
                V = _expression_potential(fe, sys, rates | inputs)
                if V is None:
                    noncons.append(fe.name)
                else:
                    V_terms.append(V)
                continue
            row = _linear_row(fe, sys, rates | inputs)
            if row is None:
                noncons.append(fe.name)
            else:
                rows[c], damped = (*row[:2], fe.name), row[2]
                if damped:
                    noncons.append(fe.name)
        elif isinstance(fe, Bushing):
            V = _bushing_potential(kin, fe, sys, rates | inputs)
            if V is None:
                noncons.append(fe.name)
            else:
                V_terms.append(V)
        elif isinstance(fe, Force | Torque):
            noncons.append(fe.name)
    V_rows, unpaired = _linear_potential(rows)
    V_terms.extend(V_rows)
    noncons.extend(unpaired)
    rheonomic = False
    for body in sys.bodies:
        j = body.joint
        exprs = [*j.position, *(x for row in j.orientation for x in row)]
        for s in j.steps:
            exprs.extend([s.angle] if hasattr(s, "angle") else list(s.vector))
        if "t" in free_names(exprs):
            rheonomic = True
    V = se.Add(*V_terms) if V_terms else ZERO
    return Energy(kin, T, V, not noncons and not rheonomic, tuple(noncons), rheonomic)


def _linear_row(fe: GeneralizedForce, sys: object, varying: set[str]
                ) -> tuple[se.Basic, dict[se.Basic, se.Basic], bool] | None:
    """A generalized force on a coordinate whose spring part (the value at zero rates) is
    ``a + Σ_j B_j·y_j`` with constant a, B_j: (a, {y_j: B_j}, damped); None otherwise."""
    c = fe.coordinate
    value = fe.value.subs({deflection: c, deflection_d: rate(c)})
    coords = sys.coordinates  # type: ignore[attr-defined]
    rate_syms = [rate(y) for y in coords]
    free = value.free_symbols
    damped = any(r in free for r in rate_syms)
    spring = value.subs({r: 0 for r in rate_syms if r in free}) if damped else value
    names = free_names([spring])
    if names & (varying | {"t"}):
        return None
    B = {y: spring.diff(y) for y in coords if y in spring.free_symbols}
    if not all(_constant(b, sys, varying) for b in B.values()):
        return None
    a = spring.subs({y: 0 for y in B}) if B else spring
    return a, B, damped


def _linear_potential(rows: dict[se.Basic, tuple[se.Basic, dict[se.Basic, se.Basic], str]]
                      ) -> tuple[list[se.Basic], list[str]]:
    """``V = −Σ a_k·y_k − ½ Σ B_kj·y_k·y_j`` of the linear generalized forces ``rows``
    (coordinate -> (a, {y_j: B_kj}, force name)) where B is symmetric among them (a spring
    between coordinates, such as an elastic body's −K_e·q_e); the forces whose row has no
    symmetric partner are returned by name, as non-conservative."""
    terms: list[se.Basic] = []
    bad: list[str] = []
    for c, (a, B, name) in rows.items():
        ok = all(y in rows and se.expand(rows[y][1].get(c, ZERO) - b) == 0
                 for y, b in B.items())
        if not ok:
            bad.append(name)
            continue
        terms.append(-a * c)
        terms.extend(-se.Rational(1, 2) * b * c * y for y, b in B.items())
    return terms, bad


def _point(kin: Kinematics, body: str, p: tuple) -> tuple:
    if body == WORLD:
        return tuple(p)
    r, _, _, _ = kin[body].point(tuple(p))
    return r


def _has_quantities(fe: object) -> bool:
    """True when a force law uses kinematic quantities (treated as non-conservative)."""
    return any(hasattr(s, "quantity") for e in force_expressions(fe) for s in e.free_symbols)


def _constant(e: se.Basic, sys: object, varying: set[str]) -> bool:
    names = free_names([e])
    return not names & (set(sys.coordinate_names) | varying | {"t"})  # type: ignore[attr-defined]


def _expression_potential(fe: GeneralizedForce, sys: object, varying: set[str]
                          ) -> se.Basic | None:
    """``-(a·e + ½ b·e²)`` for a value ``a + b·deflection`` (a, b constant) on an expression e
    of the coordinates and parameters; None when the force is not of that form."""
    e = fe.coordinate
    if "t" in free_names([e]):
        return None
    v = fe.value
    if v.diff(deflection_d) != 0 or not _constant(v.subs({deflection: 0}), sys, varying):
        return None
    b = v.diff(deflection)
    if not _constant(b, sys, varying) or b.diff(deflection) != 0:
        return None
    a = v.subs({deflection: 0})
    return -(a * e + se.Rational(1, 2) * b * e**2)


def _bushing_potential(kin: Kinematics, fe: Bushing, sys: object, varying: set[str]
                       ) -> se.Basic | None:
    """``½ xᵀK x − w₀ᵀx`` of a bushing without damping and laws, K symmetric and constant;
    None otherwise (its work is then reported as non-conservative)."""
    K = fe.stiffness
    if not fe.linear or any(v != 0 for r in fe.damping for v in r):
        return None
    if any(not _constant(v, sys, varying) for v in (*fe.preload, *(v for r in K for v in r))):
        return None
    if any(se.expand(K[i][j] - K[j][i]) != 0 for i in range(6) for j in range(i)):
        return None
    x, _, _ = bushing_deflection(Frames(kin), fe)
    terms = [se.Rational(1, 2) * K[i][j] * x[i] * x[j] for i in range(6) for j in range(6)
             if K[i][j] != 0]
    terms += [-fe.preload[i] * x[i] for i in range(6) if fe.preload[i] != 0]
    return se.Add(*terms) if terms else ZERO
