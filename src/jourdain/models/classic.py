"""Textbook systems: the n-link pendulum on a cart, the double pendulum, the heavy symmetric top."""

from __future__ import annotations

import symengine as se

from ..model import (
    Body,
    Force,
    General,
    Gravity,
    Prismatic,
    Revolute,
    Rot,
    Spherical,
    point_mass,
    rod,
    symbols,
)
from ..pipeline import System


def n_link_pendulum_on_cart(n: int) -> System:
    """n-link pendulum on a cart, the same system as
    ``sympy.physics.mechanics.models.n_link_pendulum_on_cart(n, cart_force=True)``.

    Coordinates ``q0`` (cart position along x) and ``q1 … qn`` (absolute link angles about z,
    measured from the upward y axis); masses ``m0`` (cart) … ``mn`` (point masses at the link
    ends); lengths ``l0 … l(n-1)``; gravity ``g`` along -y; input ``F``, the horizontal force on
    the cart. Links are massless. Absolute angles are joint angles ``q_i - q_(i-1)`` of general
    joints, which the kinematics merges back into ``R_z(q_i)``.
    """
    if n < 1:
        raise ValueError("n must be at least 1")
    q = [se.Symbol(f"q{i}") for i in range(n + 1)]
    m = [se.Symbol(f"m{i}") for i in range(n + 1)]
    l = [se.Symbol(f"l{i}") for i in range(n)]
    g, F = symbols("g F")
    bodies = [Body("cart", "world", Prismatic("slider", q[0], "x"), mass=m[0],
                   inertia=point_mass())]
    for i in range(1, n + 1):
        if i == 1:
            joint = Revolute("hinge1", q[1], "z")
        else:
            joint = General(f"hinge{i}", [Rot("z", q[i] - q[i - 1])], coordinates=[q[i]],
                            position=(0, l[i - 2], 0))
        bodies.append(Body(f"link{i}", "cart" if i == 1 else f"link{i - 1}", joint, mass=m[i],
                           com=(0, l[i - 1], 0), inertia=point_mass()))
    params = {f"m{i}": 1.0 for i in range(n + 1)}
    params.update({f"l{i}": 1.0 for i in range(n)})
    params["g"] = 9.81
    return System(q, bodies, [Gravity((0, -g, 0)), Force("cart_force", "cart", (F, 0, 0))],
                  parameters=params, inputs=[F], name=f"{n}-link pendulum on a cart",
                  units={"g": "m/s^2", **{f"m{i}": "kg" for i in range(n + 1)},
                         **{f"l{i}": "m" for i in range(n)}})


def double_pendulum() -> System:
    """Planar double pendulum of two uniform rods hanging from revolute joints about z.

    ``phi1``: angle of the first rod from the downward vertical; ``phi2``: angle of the second
    rod relative to the first. Rods of mass ``m1, m2`` and length ``l1, l2`` along the body's
    -y axis; gravity ``g`` along -y.
    """
    phi1, phi2 = symbols("phi1 phi2")
    m1, m2, l1, l2, g = symbols("m1 m2 l1 l2 g")
    bodies = [
        Body("rod1", "world", Revolute("hinge1", phi1, "z"), mass=m1, com=(0, -l1 / 2, 0),
             inertia=rod(m1, l1, "y")),
        Body("rod2", "rod1", Revolute("hinge2", phi2, "z", position=(0, -l1, 0)), mass=m2,
             com=(0, -l2 / 2, 0), inertia=rod(m2, l2, "y")),
    ]
    return System([phi1, phi2], bodies, [Gravity((0, -g, 0))],
                  parameters={"m1": 1.0, "m2": 0.5, "l1": 1.0, "l2": 0.7, "g": 9.81},
                  units={"m1": "kg", "m2": "kg", "l1": "m", "l2": "m", "g": "m/s^2",
                         "phi1": "rad", "phi2": "rad"},
                  name="double pendulum")


def heavy_top() -> System:
    """Heavy symmetric top on a fixed point, in Euler angles ``psi`` (precession), ``theta``
    (nutation), ``phi`` (spin) of the z-x-z sequence.

    Centre of mass at distance ``L`` on the symmetry axis (body z); moments of inertia ``A``
    (transverse) and ``C`` (axial) about the centre of mass; gravity ``g`` along -z.
    """
    psi, theta, phi = symbols("psi theta phi")
    m, L, A, C, g = symbols("m L A C g")
    body = Body("top", "world", Spherical("pivot", (psi, theta, phi), "zxz"), mass=m,
                com=(0, 0, L), inertia=(A, A, C))
    return System([psi, theta, phi], [body], [Gravity((0, 0, -g))],
                  parameters={"m": 1.0, "L": 0.1, "A": 0.004, "C": 0.006, "g": 9.81},
                  units={"m": "kg", "L": "m", "A": "kg*m^2", "C": "kg*m^2", "g": "m/s^2"},
                  name="heavy symmetric top")
