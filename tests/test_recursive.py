"""The compiled recursion (jourdain.numeric.recursive) against the symbolic stages.

The symbolic Newton–Euler equations and their projection (M = J̄ᵀM̄J̄, k = J̄ᵀq̄^c, q = J̄ᵀq̄^e,
Q̄ from the joints) are compiled entry by entry with ``numeric.lambdify``; the recursion forms
the same products body by body from per-joint expressions. Both must agree to rounding on every
example model and on a model with every joint type, every force element, a rheonomic joint, a
coordinate shared by two joints, inputs and bodies without inertia.
"""

from pathlib import Path

import numpy as np
import pytest

import jourdain as jd
from jourdain import models
from jourdain.numeric import _eom_function, dynamics_function, lambdify, mkq_function
from jourdain.stages.reactions import reactions
from tests.tolerance import assert_close_eval, newton_euler_tol, ydd_of

EXAMPLES = sorted((Path(__file__).parent.parent / "examples").glob("*.toml"))


def every_joint_and_force() -> jd.System:
    """A branching tree with revolute, prismatic, cylindrical, universal, spherical, planar, free,
    fixed and rheonomic general joints (one sharing a coordinate with another), springs between
    bodies, forces and torques in body and inertial frames, a generalized force with an input,
    a point mass and a massless link."""
    q = jd.symbols("a b s c1 c2 u1 u2 e1 e2 e3 x y th fx fy fz r1 r2 r3 g1 h h2")
    (a, b, s, c1, c2, u1, u2, e1, e2, e3, x, y, th, fx, fy, fz, r1, r2, r3, g1, h, h2) = q
    t = jd.symbols("t")
    F, k1, d1, Om = jd.symbols("F k1 d1 Om")
    box = jd.box(1.3, 0.2, 0.3, 0.4)
    bodies = [
        jd.Body("base", "world", jd.Revolute("j0", a, (0.3, 0.4, 0.866)), mass=1.3,
                com=(0.1, 0.05, 0.2), inertia=box),
        jd.Body("slider", "base", jd.Prismatic("j1", s, (1, 1, 0), position=(0.1, 0, 0.3)),
                mass=0.7, com=(0, 0.1, 0), inertia=((0.02, 0.001, 0), (0.001, 0.03, 0.002),
                                                     (0, 0.002, 0.025))),
        jd.Body("cyl", "slider", jd.Cylindrical("j2", (c1, c2), "y", position=(0, 0.2, 0.1)),
                mass=0.9, com=(0.05, 0, -0.1), inertia=jd.cylinder(0.9, 0.05, 0.3, "z")),
        jd.Body("cardan", "base", jd.Universal("j3", (u1, u2), ("x", "z"),
                                               position=(-0.2, 0.1, 0.3)),
                mass=0.5, com=(0, 0, 0.15), inertia=jd.box(0.5, 0.05, 0.06, 0.3)),
        jd.Body("ball", "cardan", jd.Spherical("j4", (e1, e2, e3), "zxz", position=(0, 0, 0.3)),
                mass=0.8, com=(0.02, -0.03, 0.1), inertia=jd.box(0.8, 0.1, 0.2, 0.15)),
        jd.Body("plate", "world", jd.Planar("j5", (x, y, th), "z", position=(1, 0, 0)),
                mass=1.1, com=(0.1, 0, 0), inertia=jd.box(1.1, 0.3, 0.2, 0.05)),
        jd.Body("drone", "plate", jd.Free("j6", (fx, fy, fz, r1, r2, r3), position=(0, 0, 0.5)),
                mass=0.6, com=(0.01, 0.02, 0.0), inertia=jd.box(0.6, 0.2, 0.2, 0.05)),
        jd.Body("weld", "drone", jd.Fixed("j7", position=(0.1, 0, 0)), mass=0.2,
                com=(0.05, 0, 0), inertia=jd.point_mass()),
        # rheonomic: a driven spin Om·t about z and the coordinate g1 about x, which also
        # turns the next body (a coordinate shared by two joints)
        jd.Body("rotor", "ball", jd.General("j8", [jd.Rot("z", Om * t), jd.Rot("x", g1)],
                                            coordinates=[g1], position=(0, 0, 0.2)),
                mass=0.4, com=(0, 0.05, 0), inertia=jd.disc(0.4, 0.1, "y")),
        jd.Body("tip", "rotor", jd.General("j9", [jd.Rot("x", -g1 + b)], coordinates=[b],
                                           position=(0, 0.1, 0)),
                mass=0.3, com=(0, 0.1, 0), inertia=jd.point_mass()),
        jd.Body("link", "tip", jd.Revolute("j10", h, "y", position=(0, 0.2, 0)),
                mass=0, inertia=jd.point_mass()),
        jd.Body("bob", "link", jd.Revolute("j11", h2, "x", position=(0, 0, 0.3)),
                mass=0.25, com=(0, 0, 0.1), inertia=jd.point_mass()),
    ]
    forces = [
        jd.Gravity((0, 0, -9.81)),
        jd.SpringDamper("spring", "base", (0.1, 0.1, 0.2), "ball", (0, 0, 0.05),
                        stiffness=k1, damping=d1, rest_length=0.2),
        jd.SpringDamper("tether", "world", (1, 1, 1), "drone", (0.05, 0, 0), stiffness=3.0,
                        damping=0.2, rest_length=0.5),
        jd.Force("push", "cyl", (0.3, F, 0), frame="cyl", point=(0, 0, 0.1)),
        jd.Force("wind", "plate", (0.2, 0, 0.1 * t), frame="world", point=(0.1, 0.05, 0)),
        jd.Torque("motor", "cardan", (0, 0, 0.1 * u1 + 0.05), frame="base"),
        jd.GeneralizedForce("drive", a, -0.4 * a - 0.1 * jd.symbols("a_d")),
    ]
    return jd.System(list(q), bodies, forces, parameters={"k1": 40.0, "d1": 0.3, "Om": 2.0},
                     inputs=[F], name="every joint and force")


CASES = {
    "double pendulum": models.double_pendulum,
    "heavy top": models.heavy_top,
    "cart pendulum 3 (shared coordinates, input)": lambda: models.n_link_pendulum_on_cart(3),
    "spatial chain 5": lambda: models.spatial_chain(5),
    "every joint and force": every_joint_and_force,
    # a closed example's tree, asked for by name (its closed numbers: tests/test_closed_system.py)
    # (not the flexible rotor: its symbolic code, 66 000 operations, takes 20 s to compile;
    # the elastic body's expansion is checked on the two smaller elastic examples)
    **{f"example {p.stem}": (lambda p=p: jd.load_model(p).system.tree) for p in EXAMPLES
       if p.stem != "flexible_rotor"},
}


def _symbolic(system: jd.System):
    eom = system.equations_of_motion()
    ne = eom.newton_euler
    mats = {"M_bar": ne.M_bar, "J_bar": ne.J_bar, "q_c": ne.q_c, "q_e": ne.q_e,
            "M": eom.M, "k": eom.k, "q": eom.q}
    try:
        mats["Q_bar"] = reactions(ne).Q_bar
    except jd.ModelError:
        pass
    return lambdify(system, mats)


@pytest.mark.parametrize("make", list(CASES.values()), ids=list(CASES))
def test_recursion_equals_symbolic_projection(make, rng):
    system = make()
    ref, new = _symbolic(system), _eom_function(system)
    assert set(ref.names) <= set(new.names)
    pv = np.array(list(system.parameter_values.values()), dtype=float)
    p = len(system.bodies)
    # an elastic body's coordinates at deflections it is made for (mass-normalized modes of a
    # 0.3 kg strip: q = 2 would bend it by metres, and its quadratic foreshortening terms would
    # then set the rounding, not M)
    elastic = {str(c) for g in system.groups for c in g.coordinates}
    size = np.array([1e-2 if c in elastic else 1.0 for c in system.coordinate_names])
    for _ in range(3):
        y = rng.uniform(-2, 2, system.f) * size
        yd = rng.uniform(-2, 2, system.f) * size
        t = float(rng.uniform(0, 3))
        u = rng.uniform(-1, 1, len(system.inputs))
        a, b = ref(y, yd, t, pv, u), new(y, yd, t, pv, u)
        for name in ref.names:
            if a[name].size == 0:  # Q̄ of a free body: no constrained direction
                assert b[name].shape == a[name].shape
                continue
            # each entry is a sum over at most 6p body rows of products of kinematic terms;
            # the scale is that of the largest entry of the matrix (the terms are not larger
            # than a few times it for these well-scaled models)
            assert_close_eval(b[name], a[name], 6 * p, np.abs(a[name]).max() + 1.0,
                              err_msg=f"{system.name}: {name}")
        assert np.array_equal(b["M"], b["M"].T)


def test_mkq_function_equals_full_function(rng):
    """The recursion's function with M, k, q only gives the numbers of the full one bit for
    bit; the integrator's (symbolic code for this small planar model) agrees to rounding."""
    system = models.n_link_pendulum_on_cart(3)
    full, mkq = _eom_function(system), dynamics_function(system)
    pv = np.array(list(system.parameter_values.values()))
    y, yd = rng.uniform(-2, 2, system.f), rng.uniform(-2, 2, system.f)
    a, b = full(y, yd, 0.0, pv, [0.4]), mkq(y, yd, 0.0, pv, [0.4])
    for name in ("M", "k", "q"):
        assert np.array_equal(a[name], b[name])
    c = mkq_function(system)(y, yd, 0.0, pv, [0.4])
    for name in ("M", "k", "q"):
        assert_close_eval(c[name], a[name], 6 * len(system.bodies), np.abs(a[name]).max() + 1)


def test_integrator_code_is_the_recursion_for_spatial_models(rng):
    """A spatial chain the cost model gives the spatial recursion: the integrator's M, k, q
    are the full function's, bit for bit (the same engine; the articulated bodies only for
    ÿ)."""
    from jourdain.numeric import evaluation_path

    system = models.spatial_chain(10)
    assert evaluation_path(system).path == "spatial"
    full, mkq = _eom_function(system), mkq_function(system)
    pv = np.array(list(system.parameter_values.values()))
    y, yd = rng.uniform(-2, 2, system.f), rng.uniform(-2, 2, system.f)
    a, b = full(y, yd, 0.0, pv, np.zeros(0)), mkq(y, yd, 0.0, pv, np.zeros(0))
    for name in ("M", "k", "q"):
        assert np.array_equal(a[name], b[name])


def test_generated_code_grows_with_bodies_not_f_cubed():
    """The source of the recursion grows about linearly with the number of bodies (the
    expanded entries of M grew like f³)."""
    from jourdain.numeric.recursive import recursive_source

    size = {n: len(recursive_source(models.spatial_chain(n), full=True)) for n in (8, 16, 32)}
    assert size[32] / size[16] < 2.6 and size[16] / size[8] < 2.6, size


def test_every_joint_and_force_newton_euler_residual(rng):
    """With ÿ from M·ÿ = q − k and g from N̂·g = k̂ − q̂ (bordered for the massless link), the
    numbers of System.evaluate satisfy M̄·J̄·ÿ + q̄^c = q̄^e + Q̄·g row by row (METHOD.md §2)."""
    system = every_joint_and_force()
    for _ in range(3):
        y, yd = rng.uniform(-1.5, 1.5, system.f), rng.uniform(-1, 1, system.f)
        out = system.evaluate(y, yd, t=float(rng.uniform(0, 2)), inputs=[rng.uniform(-1, 1)])
        assert "reactions_error" not in out, out.get("reactions_error")
        assert out["g_undetermined"] == []
        ydd = ydd_of(out)
        res = (out["M_bar"] @ out["J_bar"] @ ydd + out["q_c"] - out["q_e"]
               - out["Q_bar"] @ out["g"])
        assert np.abs(res).max() <= newton_euler_tol(out, ydd)


@pytest.mark.parametrize("make", [every_joint_and_force, lambda: models.random_tree(12, seed=3),
                                  models.heavy_top],
                         ids=["shared coordinate: LDLᵀ and sub-tree sums",
                              "tree: articulated bodies", "top: articulated bodies"])
def test_joint_wrenches_equal_reaction_components(make, rng):
    """CompiledFunction.dynamics gives ÿ and each joint's wrench by the ÿ route (the
    articulated-body recursion where every coordinate belongs to one joint, else LDLᵀ of M and
    the sub-tree's Newton–Euler sums); ÿ must solve M·ÿ = q − k, and the reaction components g
    of N̂·g = k̂ − q̂ (METHOD.md §4, no ÿ) along the joint's constrained directions w_k must
    compose the same wrench, Σ g_k·w_k."""
    from jourdain.stages.reactions import graph_values, joint_directions
    from tests.tolerance import subtree_tol, tree_extent, ydd_tol

    system = make()
    fn = dynamics_function(system)
    pv = np.array(list(system.parameter_values.values()))
    for _ in range(3):
        y, yd = rng.uniform(-1.5, 1.5, system.f), rng.uniform(-1, 1, system.f)
        t = float(rng.uniform(0, 2))
        u = [float(rng.uniform(-1, 1)) for _ in system.inputs] or None
        out = system.evaluate(y, yd, t=t, inputs=u)
        ydd, W = fn.dynamics(y[None], yd[None], t, pv, u)
        assert "g" in out, out.get("reactions_error")
        tol = subtree_tol(out, ydd[0], tree_extent(system, y, t))
        assert np.abs(ydd[0] - ydd_of(out)).max() <= ydd_tol(out, ydd[0])
        vals = {**dict(zip(system.parameter_symbols, pv, strict=True)),
                **dict(zip(system.y, y, strict=True)), system.t: t}
        for b, jr in enumerate(joint_directions(system)):
            if not jr.names:
                continue  # a free joint transmits nothing
            w = np.array(graph_values([x for wr in jr.wrenches for x in wr], vals), dtype=float)
            ours = out["g"][list(jr.columns)] @ w.reshape(len(jr.names), 6)
            assert np.abs(ours - W[0, b]).max() <= tol, jr.joint.name


def test_simulation_by_articulated_bodies_conserves_energy():
    """A random tree (free, spherical, universal, prismatic and revolute joints about random
    axes) integrated with the recursion's articulated-body ÿ: the energy of the conservative
    system stays constant, and the work of gravity, integrated with the motion through the
    power ẏᵀq, is the loss of potential energy."""
    system = models.random_tree(7, seed=1)
    assert "#define JD_ACCEL_ABA 1" in mkq_function(system).lib_source()
    rng = np.random.default_rng(5)
    res = system.simulate((0, 1.0), rng.uniform(-0.5, 0.5, system.f),
                          rng.uniform(-0.5, 0.5, system.f), rtol=1e-11, atol=1e-11)
    assert res.conservative and res.energy_drift < 1e-8
    np.testing.assert_allclose(res.W, -(res.potential_energy - res.potential_energy[0]),
                               atol=1e-8 * np.abs(res.potential_energy).max())
