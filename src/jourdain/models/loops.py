"""Sample closed mechanisms (systems with closing joints) shared by the tests, the examples and
the benchmarks."""

from __future__ import annotations

from ..model import Body, Gravity, Prismatic, Revolute, rod, symbols
from ..model.closing import ClosingJoint
from ..pipeline import System  # jourdain.System: the model with its stages (issue 16)


def four_bar(independent: tuple[str, ...] | None = ("theta1",)) -> System:
    """Planar four-bar linkage in the x-y plane, gravity ``g`` along −y.

    Crank (length ``a``, mass ``m1``) hinged to the ground at the origin, angle ``theta1``
    from the x axis; coupler (``b``, ``m2``) hinged at the crank's end, angle ``theta2``
    relative to the crank; rocker (``c``, ``m3``) hinged to the ground at ``(d, 0, 0)``,
    absolute angle ``theta3``. The loop is closed by a revolute joint ``closure`` about z
    between the coupler's end and the rocker's end. Uniform rods along each body's x axis.
    """
    th1, th2, th3 = symbols("theta1 theta2 theta3")
    a, b, c, d, m1, m2, m3, g = symbols("a b c d m1 m2 m3 g")
    bodies = [
        Body("crank", "world", Revolute("ground1", th1, "z"), mass=m1, com=(a / 2, 0, 0),
             inertia=rod(m1, a, "x")),
        Body("coupler", "crank", Revolute("knee", th2, "z", position=(a, 0, 0)), mass=m2,
             com=(b / 2, 0, 0), inertia=rod(m2, b, "x")),
        Body("rocker", "world", Revolute("ground2", th3, "z", position=(d, 0, 0)), mass=m3,
             com=(c / 2, 0, 0), inertia=rod(m3, c, "x")),
    ]
    tree = System([th1, th2, th3], bodies, [Gravity((0, -g, 0))],
                  parameters={"a": 0.4, "b": 1.0, "c": 0.8, "d": 1.1, "m1": 1.0, "m2": 2.0,
                              "m3": 1.5, "g": 9.81},
                  units={"a": "m", "b": "m", "c": "m", "d": "m", "m1": "kg", "m2": "kg",
                         "m3": "kg", "g": "m/s^2"},
                  name="four-bar linkage")
    closure = ClosingJoint("closure", "revolute", "coupler", "rocker", point_a=(b, 0, 0),
                           point_b=(c, 0, 0), axis="z")
    return tree.closed_by([closure], independent=independent)


def slider_crank(independent: tuple[str, ...] | None = ("phi",)) -> System:
    """Planar slider-crank: crank (radius ``r``, mass ``m1``) hinged at the origin, angle
    ``phi`` from the x axis; connecting rod (``l``, ``m2``) hinged at the crank pin, angle
    ``psi`` relative to the crank; slider (``m3``) on the x axis, position ``s``. The loop is
    closed by a revolute joint ``wrist`` about z between the rod's end and the slider."""
    phi, psi, s = symbols("phi psi s")
    r, l, m1, m2, m3, g = symbols("r l m1 m2 m3 g")
    bodies = [
        Body("crank", "world", Revolute("main", phi, "z"), mass=m1, com=(r / 2, 0, 0),
             inertia=rod(m1, r, "x")),
        Body("rod", "crank", Revolute("pin", psi, "z", position=(r, 0, 0)), mass=m2,
             com=(l / 2, 0, 0), inertia=rod(m2, l, "x")),
        Body("slider", "world", Prismatic("guide", s, "x"), mass=m3,
             inertia=(0.01, 0.01, 0.01)),
    ]
    tree = System([phi, psi, s], bodies, [Gravity((0, -g, 0))],
                  parameters={"r": 0.3, "l": 1.0, "m1": 1.0, "m2": 1.5, "m3": 2.0, "g": 9.81},
                  units={"r": "m", "l": "m", "m1": "kg", "m2": "kg", "m3": "kg",
                         "g": "m/s^2"},
                  name="slider-crank")
    wrist = ClosingJoint("wrist", "revolute", "rod", "slider", point_a=(l, 0, 0), axis="z")
    return tree.closed_by([wrist], independent=independent)


def n_four_bar(n: int) -> System:
    """The N four-bar mechanism of the IFToMM multibody benchmark library: n + 1 cranks of
    length ``L`` pinned to the ground at ``x = i·L`` (angles ``th0 … thn`` from the x axis)
    and n couplers of length ``L`` hinged at the tops of cranks 0 … n−1 (angles ``ph0 …`` relative
    to their crank), each closed by a revolute joint ``close<i>`` at the top of crank i+1:
    n parallelograms in a row, one degree of freedom. Uniform rods of mass ``m``, gravity
    ``g`` along −y. Where the cranks lie horizontal every bar is on the x axis and the
    constraint Jacobian loses rank (the benchmark's singular positions)."""
    if n < 1:
        raise ValueError("n must be at least 1")
    L, m, g = symbols("L m g")
    th = [symbols(f"th{i}") for i in range(n + 1)]
    ph = [symbols(f"ph{i}") for i in range(n)]
    bodies = []
    for i in range(n + 1):
        bodies.append(Body(f"crank{i}", "world", Revolute(f"ground{i}", th[i], "z",
                                                          position=(i * L, 0, 0)),
                           mass=m, com=(L / 2, 0, 0), inertia=rod(m, L, "x")))
        if i < n:
            bodies.append(Body(f"coupler{i}", f"crank{i}",
                               Revolute(f"top{i}", ph[i], "z", position=(L, 0, 0)), mass=m,
                               com=(L / 2, 0, 0), inertia=rod(m, L, "x")))
    coords = [c for i in range(n + 1) for c in ([th[i], ph[i]] if i < n else [th[i]])]
    tree = System(coords, bodies, [Gravity((0, -g, 0))],
                  parameters={"L": 1.0, "m": 1.0, "g": 9.81}, name=f"{n} four-bar")
    closing = [ClosingJoint(f"close{i}", "revolute", f"coupler{i}", f"crank{i + 1}",
                            point_a=(L, 0, 0), point_b=(L, 0, 0), axis="z") for i in range(n)]
    return tree.closed_by(closing, independent=("th0",))
