"""Wheeled vehicles and skates in the ground plane (velocity constraints, METHOD.md §7), with
the closed forms they are checked against (``tests/test_wheeled.py``).

* :func:`differential_drive`: a chassis on two wheels with a common axle, each a
  :class:`~jourdain.model.contacts.RollingDisc`, driven by motor torques between chassis and
  wheels (the two-wheeled cart of Kane's examples, the differential-drive robot);
* :func:`skate_on_incline`: a skate (:class:`~jourdain.model.contacts.KnifeEdge`) on a plane
  inclined by ``alpha``, under gravity.
"""

from __future__ import annotations

from typing import Any

import symengine as se

from ..model import Body, General, Gravity, Planar, Revolute, Rot, Trans, symbols
from ..model.contacts import KnifeEdge, RollingDisc
from ..model.forces import GeneralizedForce, RotationalSpringDamper
from ..pipeline import System

#: default data of :func:`differential_drive` (SI units)
DIFFERENTIAL_DRIVE = {
    "mc": 10.0, "Ic": 0.4, "b": 0.1,     # chassis: mass, yaw inertia about its centre, offset
    "mw": 1.0, "Jw": 0.03, "Iw": 0.02,   # each wheel: mass, axial and diametral inertia
    "r": 0.15, "d": 0.25, "g": 9.81,     # wheel radius, half track, gravity
    "tauL": 0.0, "tauR": 0.0,            # motor torques on the wheels (about their axle)
}

#: default data of :func:`skate_on_incline`
SKATE = {"m": 2.0, "I": 0.05, "alpha": 0.3, "g": 9.81}


def differential_drive(speeds: str = "body") -> System:
    """A chassis on two wheels rolling without slip on a common axle: the differential drive.

    The chassis moves in the plane (coordinates ``x, y`` of the axle's midpoint A, heading
    ``psi``; A at the wheels' height ``r`` above the ground ``z = 0``); its centre of mass lies
    ``b`` ahead of A (mass ``mc``, yaw inertia ``Ic`` about its centre of mass). The wheels
    (mass ``mw``, axial inertia ``Jw``, diametral ``Iw``) turn by ``thetaL``, ``thetaR``
    (relative to the chassis, about its y axis) at ``(0, ±d, 0)``, left at ``+d``. Motor
    torques ``tauL``, ``tauR`` act between the chassis and each wheel (generalized forces on
    ``thetaL``, ``thetaR``; parameters, since general systems take no inputs yet). The
    planar joint carries the weight, so the wheels' touching rows vanish identically and are
    dropped: the contact forces are the tangential ones ``left.T1, left.T2, right.T1,
    right.T2`` (along world x and y).

    ``speeds="body"``: ``v = cos(psi)·x_d + sin(psi)·y_d`` (A's forward speed) and
    ``w = psi_d``; ``speeds="wheels"``: ``thetaL_d, thetaR_d``.

    Closed form. No slip: A has no lateral velocity, and each wheel centre moves forward at
    ``r·θ̇``: ``v − w·d = r·θ̇_L``, ``v + w·d = r·θ̇_R``. With
    ``m = mc + 2·mw + 2·Jw/r²`` and ``I = Ic + mc·b² + 2·mw·d² + 2·Iw + 2·Jw·d²/r²``
    (kinetic energy ``T = ½·m·v² + ½·I·w²``) and the motors' power
    ``τ_L·θ̇_L + τ_R·θ̇_R = (τ_L + τ_R)/r·v + d·(τ_R − τ_L)/r·w``::

        m·v̇ − mc·b·w² = (τ_L + τ_R)/r
        I·ẇ + mc·b·v·w = d·(τ_R − τ_L)/r

    (the terms in ``b`` as Chaplygin's sleigh's). The ground's forces on the wheels: along the
    heading, from each wheel's spin ``Jw·θ̈_i = τ_i − r·F_i``, ``F_i = (τ_i − Jw·θ̈_i)/r``;
    across it, only their sum is determined (a rigid axle: the two lateral rows are one),
    ``F_lat = (mc + 2·mw)·v·w + mc·b·ẇ`` (jourdain shares it evenly between the wheels, the
    least-norm multipliers, and names the rows in ``contacts_undetermined``). Free
    wheels with ``b = 0`` turn steadily
    (``v̇ = ẇ = 0``) with the centripetal force ``(mc + 2·mw)·v·w``.
    """
    if speeds not in ("body", "wheels"):
        raise ValueError(f'speeds must be "body" or "wheels", got {speeds!r}')
    x, y, psi, thL, thR = symbols("x y psi thetaL thetaR")
    p: dict[str, Any] = {k: symbols(k) for k in DIFFERENTIAL_DRIVE}
    r, d = p["r"], p["d"]
    chassis = Body("chassis", "world",
                   General("plane", [Trans(vector=(x, y, r)), Rot("z", psi)],
                           coordinates=(x, y, psi)),
                   mass=p["mc"], com=(p["b"], 0, 0), inertia=(p["Ic"], p["Ic"], p["Ic"]))
    wheel_inertia = (p["Iw"], p["Jw"], p["Iw"])
    left = Body("wheelL", "chassis", Revolute("axleL", thL, "y", position=(0, d, 0)),
                mass=p["mw"], inertia=wheel_inertia)
    right = Body("wheelR", "chassis", Revolute("axleR", thR, "y", position=(0, -d, 0)),
                 mass=p["mw"], inertia=wheel_inertia)
    xd, yd, psid = symbols("x_d y_d psi_d")
    chosen: list[str] | dict[str, se.Basic] = (
        {"v": se.cos(psi) * xd + se.sin(psi) * yd, "w": psid} if speeds == "body"
        else ["thetaL", "thetaR"])
    return System([x, y, psi, thL, thR], [chassis, left, right],
                  [Gravity((0, 0, -p["g"])), GeneralizedForce("motorL", thL, p["tauL"]),
                   GeneralizedForce("motorR", thR, p["tauR"])],
                  parameters=dict(DIFFERENTIAL_DRIVE), name="differential drive",
                  contacts=[RollingDisc("left", "wheelL", r, "y"),
                            RollingDisc("right", "wheelR", r, "y")],
                  speeds=chosen)


def skate_on_incline() -> System:
    """A skate (mass ``m``, yaw inertia ``I``, centre of mass on the blade) on a plane inclined
    by ``alpha``, downhill along x: the ground ``z = 0`` with gravity
    ``(g·sin(alpha), 0, −g·cos(alpha))``. Planar joint ``x, y, psi``; the blade (a knife edge at
    the body's origin, along its x axis) allows no velocity across it. Speeds
    ``u = cos(psi)·x_d + sin(psi)·y_d`` (along the blade) and ``w = psi_d``.

    Closed form: gravity's moment about the blade vanishes, so ``ẇ = 0``, and along the blade
    ``u̇ = g·sin(alpha)·cos(psi)``; across it the ground pushes with
    ``F = m·u·w + m·g·sin(alpha)·sin(psi)`` (the lateral acceleration ``u·w`` less gravity's
    lateral part). From ``psi = w·t``, ``u = 0`` at ``t = 0`` (``s = g·sin(alpha)``)::

        u = s/w·sin(w·t),  x = s/(4·w²)·(1 − cos(2·w·t)),  y = s/(2·w)·(t − sin(2·w·t)/(2·w))

    the skate does not slide down: it drifts across the slope at the mean speed ``s/(2·w)``
    while x oscillates between 0 and ``s/(2·w²)``.
    """
    x, y, psi = symbols("x y psi")
    p: dict[str, Any] = {k: symbols(k) for k in SKATE}
    m, inertia, alpha, g = p["m"], p["I"], p["alpha"], p["g"]
    skate = Body("skate", "world", Planar("plane", (x, y, psi)), mass=m,
                 inertia=(inertia, inertia, inertia))
    xd, yd, psid = symbols("x_d y_d psi_d")
    return System([x, y, psi], [skate],
                  [Gravity((g * se.sin(alpha), 0, -g * se.cos(alpha)))],
                  parameters=dict(SKATE), name="skate on an incline",
                  contacts=[KnifeEdge("blade", "skate", (0, 0, 0), "x")],
                  speeds={"u": se.cos(psi) * xd + se.sin(psi) * yd, "w": psid})


def snake(n: int) -> System:
    """A wheeled snake robot: ``n`` links of length ``l`` in the ground plane (the first on a
    planar joint ``x, y, psi``, each next on a revolute joint ``q<i>`` at the end of the one
    before, joined by torsion springs ``k``), each on a knife edge (a passive wheel pair) at
    ``a`` along it: f = n + 2 coordinates, n velocity rows, 2 speeds (the partition's). The
    large general system of the cross-check (``benchmarks/rolling_crosscheck.py``)."""
    x, y, psi = symbols("x y psi")
    qs = [symbols(f"q{i}") for i in range(1, n)]
    m, inertia, length, a, k = symbols("m I l a k")
    bodies = [Body("b0", "world", Planar("base", (x, y, psi)), mass=m, com=(length / 2, 0, 0),
                   inertia=(inertia, inertia, inertia))]
    for i, q in enumerate(qs, 1):
        bodies.append(Body(f"b{i}", f"b{i - 1}", Revolute(f"j{i}", q, "z",
                                                         position=(length, 0, 0)),
                           mass=m, com=(length / 2, 0, 0), inertia=(inertia, inertia, inertia)))
    return System([x, y, psi, *qs], bodies,
                  [RotationalSpringDamper(f"s{i}", q, k) for i, q in enumerate(qs, 1)],
                  parameters={"m": 1.0, "I": 0.1, "l": 0.5, "a": 0.2, "k": 2.0},
                  name=f"snake of {n} links",
                  contacts=[KnifeEdge(f"edge{i}", f"b{i}", (a, 0, 0), "x") for i in range(n)])


__all__ = ["DIFFERENTIAL_DRIVE", "SKATE", "differential_drive", "skate_on_incline", "snake"]
