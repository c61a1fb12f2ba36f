"""The recursion in planar vectors (jourdain.numeric.planar_recursion) and the evaluation path
chosen by cost (jourdain.numeric.cost).

References: M, k, q of the symbolic projection (kinematics, Newton–Euler and J̄ᵀ formed
symbolically, compiled entry by entry, no recursion), and ÿ = M⁻¹(q − k) of the spatial
recursion's numbers (System.evaluate), to the solve's cond(M)·eps bound. The planar models
cover articulated bodies (relative angles, branching trees with sliders, a three-column planar
joint), shared coordinates (absolute angles of the pendulum on a cart: LDLᵀ of M), a rheonomic
joint, inputs, springs, and loads across the plane (carried by the joints).
"""

import ctypes

import numpy as np
import pytest

import jourdain as jd
from jourdain import models
from jourdain.numeric import cost, evaluation_path, lambdify, mkq_function, planar_function
from jourdain.numeric.planar_recursion import is_planar, plane_normal
from tests.tolerance import assert_close_eval, assert_close_solved, eval_tol, ydd_of, ydd_tol


def planar_mechanism() -> jd.System:
    """A plate on a planar joint (x, y, θ: three columns in one joint), a link on it driven by
    a rheonomic spin Om·t plus its own angle, a slider along an oblique direction of the plane,
    a point mass, a spring between bodies, an input torque about z, and a force with a
    component across the plane and a torque about x (both carried by the joints)."""
    x, y, th, a, s, b = jd.symbols("x y th a s b")
    t, Om, T = jd.symbols("t Om T")
    bodies = [
        jd.Body("plate", "world", jd.Planar("j0", (x, y, th), "z"), mass=2.0,
                com=(0.1, 0.05, 0.02), inertia=jd.box(2.0, 0.4, 0.3, 0.05)),
        jd.Body("link", "plate", jd.General("j1", [jd.Rot("z", Om * t + a)], coordinates=[a],
                                            position=(0.2, 0.1, 0.0)),
                mass=0.7, com=(0.15, 0.0, 0.01), inertia=((0.01, 0.001, 0.002),
                                                          (0.001, 0.02, 0.0),
                                                          (0.002, 0.0, 0.025))),
        jd.Body("slider", "link", jd.Prismatic("j2", s, (0.6, 0.8, 0.0), position=(0.3, 0, 0)),
                mass=0.4, com=(0.0, 0.02, 0.0), inertia=jd.box(0.4, 0.1, 0.05, 0.05)),
        jd.Body("bob", "slider", jd.Revolute("j3", b, "z", position=(0.05, 0.0, 0.0)),
                mass=0.3, com=(0.2, 0.0, 0.0), inertia=jd.point_mass()),
    ]
    forces = [
        jd.Gravity((0, -9.81, 0)),
        jd.SpringDamper("spring", "plate", (0.0, 0.2, 0.0), "bob", (0.1, 0.0, 0.0),
                        stiffness=30.0, damping=0.4, rest_length=0.3),
        jd.Torque("motor", "link", (0, 0, T), frame="world"),
        jd.Force("push", "slider", (0.3, -0.2, 5.0), frame="slider", point=(0.0, 0.1, 0.0)),
        jd.Torque("twist", "bob", (2.0, 0.0, 0.0), frame="bob"),
    ]
    return jd.System([x, y, th, a, s, b], bodies, forces, parameters={"Om": 1.5}, inputs=[T],
                     name="planar mechanism")


def pendulum_in_plane(axis: str) -> jd.System:
    """A three-link pendulum with hinges about ``axis`` (x or y) and a slider in that plane on
    its second link, gravity across the axis: a planar mechanism in the y-z or z-x plane."""
    a, b, s, c = jd.symbols("a b s c")
    other = {"x": ((0, 0.5, 0.1), (0, 0.6, 0.8)), "y": ((0.1, 0, 0.5), (0.8, 0, 0.6))}[axis]
    bodies = [
        jd.Body("l1", "world", jd.Revolute("j1", a, axis), mass=1.0, com=other[0],
                inertia=jd.box(1.0, 0.1, 0.2, 0.3)),
        jd.Body("l2", "l1", jd.Revolute("j2", b, axis, position=other[0]), mass=0.8,
                com=other[0], inertia=jd.box(0.8, 0.3, 0.1, 0.2)),
        jd.Body("sl", "l2", jd.Prismatic("j3", s, other[1], position=other[0]), mass=0.3,
                com=(0, 0, 0), inertia=jd.box(0.3, 0.05, 0.05, 0.05)),
        jd.Body("l3", "sl", jd.Revolute("j4", c, axis), mass=0.5, com=other[0],
                inertia=jd.box(0.5, 0.2, 0.1, 0.1)),
    ]
    return jd.System([a, b, s, c], bodies, [jd.Gravity((0, 0, -9.81))],
                     name=f"pendulum about {axis}")


CASES = {
    "chain 5 (articulated bodies)": lambda: models.planar_chain(5),
    "tree 9 with sliders": lambda: models.planar_tree(9, seed=2, prismatic=0.4),
    "cart pendulum 3 (shared coordinates)": lambda: models.n_link_pendulum_on_cart(3),
    "double pendulum": models.double_pendulum,
    "mechanism": planar_mechanism,
    "pendulum in the y-z plane": lambda: pendulum_in_plane("x"),
    "pendulum in the z-x plane": lambda: pendulum_in_plane("y"),
}


def _accel(fn, y, yd, t, p, u):  # noqa: ANN001, ANN202 - the compiled jd_accel
    vp = ctypes.c_void_p
    c = ctypes.CFUNCTYPE(ctypes.c_int, vp, vp, ctypes.c_double, vp, vp, vp, vp)(
        fn.accel_address)
    ydd, power = np.empty(len(y)), np.zeros(1)
    arrays = [np.ascontiguousarray(v, dtype=float) for v in (y, yd, p, u if len(u) else [0.0])]
    status = c(arrays[0].ctypes.data, arrays[1].ctypes.data, t, arrays[2].ctypes.data,
               arrays[3].ctypes.data, ydd.ctypes.data, power.ctypes.data)
    return status, ydd, float(power[0])


@pytest.mark.parametrize("make", list(CASES.values()), ids=list(CASES))
def test_planar_recursion_equals_symbolic_projection(make, rng):
    system = make()
    assert is_planar(system)
    eom = system.equations_of_motion()
    ref = lambdify(system, {"M": eom.M, "k": eom.k, "q": eom.q})
    fn = planar_function(system)
    pv = np.array(list(system.parameter_values.values()), dtype=float)
    p = len(system.bodies)
    for _ in range(4):
        y, yd = rng.uniform(-2, 2, system.f), rng.uniform(-2, 2, system.f)
        t, u = float(rng.uniform(0, 3)), rng.uniform(-1, 1, len(system.inputs))
        a, b = ref(y, yd, t, pv, u), fn(y, yd, t, pv, u)
        for name in ("M", "k", "q"):
            assert_close_eval(b[name], a[name], 6 * p, np.abs(a[name]).max() + 1.0,
                              err_msg=f"{system.name}: {name}")
        assert np.array_equal(b["M"], b["M"].T)
        # ÿ of the integrator's right-hand side (articulated bodies, or LDLᵀ where coordinates
        # are shared) against the spatial recursion's M, k, q solved by LU
        out = system.evaluate(y, yd, t=t, inputs=list(u) or None)
        status, ydd, power = _accel(fn, y, yd, t, pv, u)
        assert status == 0
        assert np.abs(ydd - ydd_of(out)).max() <= ydd_tol(out, ydd), system.name
        q = np.ravel(a["q"])
        assert abs(power - yd @ q) <= eval_tol(6 * p * system.f, np.abs(yd) @ np.abs(q) + 1.0)


def test_planar_is_structural():
    """Only joints whose local expressions keep one plane of the inertial frame by literal
    zeros are planar (z first): spatial models, hinges about two axes, a slider across the
    hinges' plane are not (they get the spatial recursion, never a wrong number)."""
    x, z, th, ph = jd.symbols("x z th ph")
    box = jd.box(1, 0.1, 0.2, 0.3)
    two_axes = jd.System([th, ph], [
        jd.Body("b", "world", jd.Revolute("j", th, "z"), mass=1.0, inertia=box),
        jd.Body("c", "b", jd.Revolute("k", ph, "x", position=(0.3, 0, 0)), mass=1.0,
                inertia=box)])
    across = jd.System([th, z], [
        jd.Body("b", "world", jd.Revolute("j", th, "z"), mass=1.0, inertia=box),
        jd.Body("c", "b", jd.Prismatic("k", z, "z"), mass=1.0, inertia=box)])
    tilted = jd.System([th], [jd.Body("b", "world", jd.Revolute("j", th, (0, 0.6, 0.8)),
                                      mass=1.0, inertia=box)])
    for system in (models.spatial_chain(3), models.heavy_top(), two_axes, across, tilted):
        assert not is_planar(system), system.name
        assert evaluation_path(system).path != "planar"
    plane_x = jd.System([x, z, th], [jd.Body("b", "world", jd.Planar("j", (x, z, th), "x"),
                                             mass=1.0, inertia=box)])
    assert plane_normal(plane_x) == 0 and plane_normal(pendulum_in_plane("y")) == 1
    assert plane_normal(models.planar_chain(3)) == 2


def test_simulation_by_planar_articulated_bodies_conserves_energy():
    """A planar tree of 30 bodies (f > 24: never the symbolic path) simulated with the planar
    recursion's ÿ: the energy of the conservative system stays constant and the work of
    gravity through the power ẏᵀq is the loss of potential energy."""
    system = models.planar_tree(30, seed=4)
    assert evaluation_path(system).path == "planar"
    assert "jd_plane_aba" in mkq_function(system).lib_source()
    rng = np.random.default_rng(3)
    res = system.simulate((0, 0.5), rng.uniform(-0.5, 0.5, system.f),
                          rng.uniform(-0.5, 0.5, system.f), rtol=1e-11, atol=1e-11)
    assert res.conservative and res.energy_drift < 1e-8
    np.testing.assert_allclose(res.W, -(res.potential_energy - res.potential_energy[0]),
                               atol=1e-8 * np.abs(res.potential_energy).max())


def test_path_chosen_by_cost():
    """Models far from the break-even points, where the measured paths differ by 2-4×
    (benchmarks/paths.py): a long planar chain takes the planar recursion, a long spatial
    chain the spatial one, the small pendulum on a cart (shared coordinates) the symbolic
    code; the prediction is what mkq_function compiles."""
    cases = {"planar": models.planar_chain(40), "spatial": models.spatial_chain(16),
             "symbolic": models.n_link_pendulum_on_cart(3)}
    for path, system in cases.items():
        choice = evaluation_path(system)
        assert choice.path == path, (system.name, dict(choice.cost))
        assert min(choice.cost.values()) == choice.cost[path]
    assert "jd_plane_recursion" in mkq_function(cases["planar"]).lib_source()
    assert "JD_ACCEL_ABA" in mkq_function(cases["spatial"]).lib_source()


def test_symbolic_projection_derived_only_where_it_can_win(monkeypatch):
    """With a symbolic solve priced out of reach the projection is never derived; priced in,
    it is derived, counted and taken."""
    system = models.planar_chain(3)
    calls = []
    real = cost.projection

    def spy(*args):  # noqa: ANN002, ANN202
        calls.append(1)
        return real(*args)

    monkeypatch.setattr(cost, "projection", spy)
    costly = {**cost.COST_NS, "symbolic": {"node": 0.3, "call": 4.0, "entry": 0.5,
                                           "solve": 1e9, "base": 10.0}}
    monkeypatch.setattr(cost, "COST_NS", costly)
    evaluation_path.cache_clear()
    choice = evaluation_path(system)
    assert choice.path == "planar" and not calls and "nodes" not in choice.features
    cheap = {**cost.COST_NS, "symbolic": {"node": 1e-6, "call": 0.0, "entry": 0.0,
                                          "solve": 0.0, "base": 0.0}}
    monkeypatch.setattr(cost, "COST_NS", cheap)
    evaluation_path.cache_clear()
    choice = evaluation_path(system)
    assert choice.path == "symbolic" and calls and choice.features["nodes"] > 0
    evaluation_path.cache_clear()


def test_closed_system_refused_by_name():
    """The paths compute the open tree's ÿ: a closed system is refused, naming the way to its
    tree; its tree takes a path as any tree does."""
    system = models.four_bar()
    with pytest.raises(jd.ClosedSystemError, match="system.tree"):
        evaluation_path(system)
    assert evaluation_path(system.tree).path in ("symbolic", "planar", "spatial")


def test_large_planar_tree_on_the_heap(rng):
    """A planar tree of 150 bodies keeps the planar engine's work on the heap (threads may have
    small stacks); its M, k, q equal the spatial recursion's, and its ÿ solves them."""
    from jourdain.numeric import dynamics_function

    system = models.planar_tree(150, seed=7)
    fn, ref = planar_function(system), dynamics_function(system)
    assert "#define JD_PLANE_STACK 0" in fn.lib_source()
    pv = np.array(list(system.parameter_values.values()), dtype=float)
    y, yd = rng.uniform(-1, 1, system.f), rng.uniform(-1, 1, system.f)
    a, b = ref(y, yd, 0.0, pv, []), fn(y, yd, 0.0, pv, [])
    for name in ("M", "k", "q"):
        assert_close_eval(b[name], a[name], 6 * len(system.bodies), np.abs(a[name]).max() + 1.0)
    status, ydd, _ = _accel(fn, y, yd, 0.0, pv, np.zeros(0))
    assert status == 0
    M, rhs = a["M"], np.ravel(a["q"]) - np.ravel(a["k"])
    assert_close_solved(ydd, np.linalg.solve(M, rhs), [M, M])
