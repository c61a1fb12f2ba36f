"""Sample models with rolling contact (velocity constraints, METHOD.md §7): the benchmark
bicycle of Meijaard, Papadopoulos, Ruina and Schwab (2007), a rolling disc, a skate (knife
edge) and a differential-drive robot. Built from their geometry and mass data: the linear
matrices of the benchmark come out of the method, they are not put in."""

from __future__ import annotations

import math

import symengine as se

from ..model import (
    Body,
    General,
    Gravity,
    Revolute,
    Rot,
    Trans,
    symbols,
)
from ..model.contacts import RollingDisc
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
    p = {k: symbols(k) for k in BENCHMARK_BICYCLE}
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


__all__ = ["BENCHMARK_BICYCLE", "benchmark_bicycle"]
