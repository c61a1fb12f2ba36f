"""Sample models with rolling contact (velocity constraints, METHOD.md §7): the benchmark
bicycle of Meijaard, Papadopoulos, Ruina and Schwab (2007), a rolling disc, a skate (knife
edge) and a differential-drive robot. Built from their geometry and mass data: the linear
matrices of the benchmark come out of the method, they are not put in."""

from __future__ import annotations

import math
from typing import Any

import symengine as se

from ..model import (
    Body,
    General,
    Gravity,
    Planar,
    Revolute,
    Rot,
    Trans,
    symbols,
)
from ..model.contacts import KnifeEdge, RollingDisc
from ..pipeline import System

#: Table 1 of Meijaard et al. (2007), Proc. R. Soc. A 463, 1955–1982 (SI units)
BENCHMARK_BICYCLE = {
    "w": 1.02, "c": 0.08, "lam": math.pi / 10, "g": 9.81, "v": 5.0,
    "rR": 0.3, "mR": 2.0, "IRxx": 0.0603, "IRyy": 0.12,
    "xB": 0.3, "zB": -0.9, "mB": 85.0, "IBxx": 9.2, "IByy": 11.0, "IBzz": 2.8, "IBxz": 2.4,
    "xH": 0.9, "zH": -0.7, "mH": 4.0, "IHxx": 0.05892, "IHyy": 0.06, "IHzz": 0.00708,
    "IHxz": -0.00756,
    "rF": 0.35, "mF": 3.0, "IFxx": 0.1405, "IFyy": 0.28,
}


def benchmark_bicycle() -> System:
    """The Whipple bicycle of the benchmark (rear wheel R, rear frame B, front frame H, front
    wheel F; two knife-edge wheels rolling without slip) in the benchmark's axes: x forward,
    y right, z down, gravity ``g`` along +z, the ground ``z = 0``.

    Coordinates: the rear wheel centre ``x, y, zc``, the rear frame's yaw ``psi``, lean
    ``phi`` and pitch ``theta`` (z, x, y), the wheels' angles ``thetaR``, ``thetaF`` and the
    steer angle ``delta`` about the steer axis (tilted back by ``lam``, pointing down). The
    wheels' touching rows fix ``zc`` and ``theta``; their four no-slip rows leave the speeds
    ``phi_d, delta_d, thetaR_d``. Upright straight running at speed ``v`` is
    ``thetaR_d = -v/rR``, ``zc = -rR``.
    """
    x, y, zc, psi, phi, theta, thR, delta, thF = symbols(
        "x y zc psi phi theta thetaR delta thetaF")
    p: dict[str, Any] = {k: symbols(k) for k in BENCHMARK_BICYCLE}
    w, c, lam, rR, rF = p["w"], p["c"], p["lam"], p["rR"], p["rF"]
    s0 = (w + c - rF * se.tan(lam), 0, rR - rF)  # the steer axis at the front wheel's height
    rear_frame = Body(
        "B", "world",
        General("rear_frame", [Trans(vector=(x, y, zc)), Rot("z", psi), Rot("x", phi),
                               Rot("y", theta)], coordinates=(x, y, zc, psi, phi, theta)),
        mass=p["mB"], com=(p["xB"], 0, p["zB"] + rR),
        inertia=((p["IBxx"], 0, p["IBxz"]), (0, p["IByy"], 0), (p["IBxz"], 0, p["IBzz"])))
    rear_wheel = Body("R", "B", Revolute("rear_hub", thR, "y"), mass=p["mR"],
                      inertia=(p["IRxx"], p["IRyy"], p["IRxx"]))
    front_frame = Body(
        "H", "B", Revolute("steer", delta, (se.sin(lam), 0, se.cos(lam)), position=s0),
        mass=p["mH"], com=(p["xH"] - s0[0], 0, p["zH"] + rF),
        inertia=((p["IHxx"], 0, p["IHxz"]), (0, p["IHyy"], 0), (p["IHxz"], 0, p["IHzz"])))
    front_wheel = Body("F", "H", Revolute("front_hub", thF, "y",
                                          position=(rF * se.tan(lam) - c, 0, 0)),
                       mass=p["mF"], inertia=(p["IFxx"], p["IFyy"], p["IFxx"]))
    return System([x, y, zc, psi, phi, theta, thR, delta, thF],
                  [rear_frame, rear_wheel, front_frame, front_wheel],
                  [Gravity((0, 0, p["g"]))], parameters=dict(BENCHMARK_BICYCLE),
                  name="benchmark bicycle",
                  contacts=[RollingDisc("rear", "R", rR, "y", normal="-z"),
                            RollingDisc("front", "F", rF, "y", normal="-z")],
                  independent=["x", "y", "psi", "phi", "thetaR", "delta", "thetaF"],
                  speeds=["phi", "delta", "thetaR"])


def chaplygin_sleigh() -> System:
    """Chaplygin's sleigh: a body moving in the ground plane (planar joint ``x, y, psi``,
    centre of mass at the body frame's origin) on a knife edge at ``(a, 0, 0)`` along its x
    axis. Speeds chosen by definition: ``u = cos(psi)·x_d + sin(psi)·y_d`` (the edge's
    forward speed) and ``w = psi_d``. Closed form (no applied forces): ``u̇ = −a·w²``,
    ``ẇ = m·a·u·w/(I + m·a²)``, lateral force on the edge ``F = m·I·u·w/(I + m·a²)``."""
    x, y, psi = symbols("x y psi")
    m, I, a = symbols("m I a")
    sleigh = Body("sleigh", "world", Planar("plane", (x, y, psi)), mass=m,
                  inertia=(I, I, I))
    return System([x, y, psi], [sleigh], parameters={"m": 2.0, "I": 0.3, "a": 0.4},
                  name="Chaplygin sleigh",
                  contacts=[KnifeEdge("edge", "sleigh", (a, 0, 0), "x")],
                  speeds={"u": se.cos(psi) * symbols("x_d") + se.sin(psi) * symbols("y_d"),
                          "w": symbols("psi_d")})


def rolling_disc() -> System:
    """A thin uniform disc (mass ``m``, radius ``r``) rolling without slip on the ground
    ``z = 0`` (gravity ``g`` along −z): centre ``x, y, zc``, heading ``psi``, lean ``phi``
    and spin ``theta`` (z, x, y; axle y). Speeds ``psi_d, phi_d, theta_d``; ``zc`` follows
    from the contact (``r·cos(phi)``)."""
    x, y, zc, psi, phi, theta = symbols("x y zc psi phi theta")
    m, r, g = symbols("m r g")
    disc = Body("disc", "world",
                General("free", [Trans(vector=(x, y, zc)), Rot("z", psi), Rot("x", phi),
                                 Rot("y", theta)], coordinates=(x, y, zc, psi, phi, theta)),
                mass=m, inertia=(m * r**2 / 4, m * r**2 / 2, m * r**2 / 4))
    return System([x, y, zc, psi, phi, theta], [disc], [Gravity((0, 0, -g))],
                  parameters={"m": 1.0, "r": 0.5, "g": 9.81}, name="rolling disc",
                  contacts=[RollingDisc("ground", "disc", r, "y")],
                  independent=["x", "y", "psi", "phi", "theta"],
                  speeds=["psi", "phi", "theta"])


__all__ = ["BENCHMARK_BICYCLE", "benchmark_bicycle", "chaplygin_sleigh", "rolling_disc"]
