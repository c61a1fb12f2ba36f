"""Linearization M̃·η̈ + P·η̇ + Q·η = h + B·Δu (METHOD.md §5) and its split into D, G, K, N (§6):
closed forms derived by hand, and M̃, P, Q, h against central finite differences of the
nonlinear equations of motion (evaluated by the separate compiled code of System.evaluate)."""

import numpy as np
import pytest
import symengine as se

import jourdain as jd
from jourdain.models import double_pendulum, heavy_top, spatial_chain


def pendulum(damping: bool = False) -> jd.System:
    """Point mass m on a massless rod of length l, φ from the downward vertical."""
    phi, m, l, g, d = jd.symbols("phi m l g d")
    bob = jd.Body("bob", "world", jd.Revolute("pivot", phi, "z"), mass=m, com=(0, -l, 0),
                  inertia=jd.point_mass())
    forces = [jd.Gravity((0, -g, 0))]
    if damping:
        forces.append(jd.RotationalSpringDamper("damper", phi, damping=d))
    return jd.System([phi], [bob], forces, parameters={"m": 2.0, "l": 0.5, "g": 9.81, "d": 0.3})


def test_pendulum_stiffness_is_mgl():
    s = pendulum()
    lin = s.linearize({"phi": 0})
    m, l, g = jd.symbols("m l g")
    # symbolic: K = m g l exactly (difference expands to zero)
    assert se.expand(lin.K[0, 0] - m * g * l) == 0
    assert se.expand(lin.M_tilde[0, 0] - m * l**2) == 0
    num = lin.evaluate(parameters={"m": 3.0, "l": 0.7, "g": 9.81})
    np.testing.assert_allclose(num["K"], [[3.0 * 9.81 * 0.7]], rtol=1e-14)
    np.testing.assert_allclose(num["h"], [0.0], atol=1e-15)
    assert lin.is_time_invariant and lin.is_conservative
    # upright: negative stiffness
    up = s.linearize({"phi": jd.pi}).evaluate()
    np.testing.assert_allclose(up["K"], [[-2.0 * 9.81 * 0.5]], rtol=1e-14)


def test_pendulum_off_equilibrium_has_residual_h():
    """At φ_s = 0.3 (not an equilibrium) h = −m g l sin 0.3 and Q = m g l cos 0.3."""
    with pytest.warns(jd.NominalMotionWarning, match="is not a solution"):
        lin = pendulum().linearize({"phi": 0.3})
    num = lin.evaluate()
    mgl = 2.0 * 9.81 * 0.5
    np.testing.assert_allclose(num["h"], [-mgl * np.sin(0.3)], rtol=1e-13)
    np.testing.assert_allclose(num["Q"], [[mgl * np.cos(0.3)]], rtol=1e-13)
    assert not lin.is_conservative


def test_double_pendulum_matrices_closed_form():
    """Two uniform rods (relative angle φ2) hanging down: M̃ and K from T and V by hand."""
    s = double_pendulum()
    p = s.parameter_values
    m1, m2, l1, l2, g = (p[n] for n in ("m1", "m2", "l1", "l2", "g"))
    num = s.linearize({"phi1": 0, "phi2": 0}).evaluate()
    M22 = m2 * l2**2 / 3
    M12 = M22 + m2 * l1 * l2 / 2
    M11 = m1 * l1**2 / 3 + m2 * l1**2 + M22 + m2 * l1 * l2
    K11 = (m1 / 2 + m2) * g * l1 + m2 * g * l2 / 2
    K12 = K22 = m2 * g * l2 / 2
    np.testing.assert_allclose(num["M_tilde"], [[M11, M12], [M12, M22]], rtol=1e-13)
    np.testing.assert_allclose(num["K"], [[K11, K12], [K12, K22]], rtol=1e-13)
    for key in ("P", "N", "h"):
        assert np.abs(num[key]).max() == 0.0


def test_dampers_appear_in_D_only():
    """A cart on a spring-damper to the wall and a damped pendulum on it: the damping
    coefficients show up in D and nowhere else; K does not depend on them."""
    x, phi, m0, m1, l, g, c, dx, dphi = jd.symbols("x phi m0 m1 l g c dx dphi")
    cart = jd.Body("cart", "world", jd.Prismatic("slider", x, "x"), mass=m0,
                   inertia=jd.point_mass())
    bob = jd.Body("bob", "cart", jd.Revolute("pivot", phi, "z"), mass=m1, com=(0, -l, 0),
                  inertia=jd.point_mass())
    forces = [jd.Gravity((0, -g, 0)),
              jd.SpringDamper("wall", "world", (-1, 0, 0), "cart", (0, 0, 0), stiffness=c,
                              damping=dx, rest_length=1),
              jd.RotationalSpringDamper("joint_damper", phi, damping=dphi)]
    s = jd.System([x, phi], [cart, bob], forces,
                  parameters={"m0": 2.0, "m1": 0.5, "l": 0.8, "g": 9.81, "c": 40.0,
                              "dx": 1.5, "dphi": 0.2})
    lin = s.linearize({"x": 0, "phi": 0})
    num = lin.evaluate()
    np.testing.assert_allclose(num["D"], [[1.5, 0.0], [0.0, 0.2]], rtol=1e-13, atol=1e-15)
    assert np.abs(num["G"]).max() == 0.0 and np.abs(num["N"]).max() == 0.0
    np.testing.assert_allclose(num["K"], [[40.0, 0.0], [0.0, 0.5 * 9.81 * 0.8]], rtol=1e-13)
    undamped = lin.evaluate(parameters={"dx": 0.0, "dphi": 0.0})
    np.testing.assert_array_equal(undamped["K"], num["K"])
    assert np.abs(undamped["D"]).max() == 0.0
    assert not lin.is_conservative  # D ≠ 0


def rotor() -> jd.System:
    """A symmetric disc on a shaft that tilts about x (α) and y (β) at a fixed pivot, spinning
    about its axis (φ, Cardan x-y-z); rotational springs c on α, β; a speed controller
    −d·(φ̇ − Ω) on φ. COM on the axis at distance L from the pivot; no gravity."""
    al, be, ph = jd.symbols("alpha beta phi")
    m, L, A, C, c, d, Om = jd.symbols("m L A C c d Omega")
    disc = jd.Body("disc", "world", jd.Spherical("pivot", (al, be, ph), "xyz"), mass=m,
                   com=(0, 0, L), inertia=(A, A, C))
    forces = [jd.RotationalSpringDamper("spring_a", al, stiffness=c),
              jd.RotationalSpringDamper("spring_b", be, stiffness=c),
              jd.GeneralizedForce("motor", ph, -d * (jd.rate(ph) - Om))]
    return jd.System([al, be, ph], [disc], forces,
                     # A = 0.02: a disc's axial moment is at most twice the transverse one
                     parameters={"m": 2.0, "L": 0.2, "A": 0.02, "C": 0.03, "c": 50.0,
                                 "d": 0.1, "Omega": 100.0})


def test_rotor_steady_rotation_gyroscopic_matrix():
    """About φ_s = Ω t: h = 0 (the motion solves the equations), G couples α and β with C Ω,
    D holds the controller gain only, K = diag(c, c, 0)."""
    s = rotor()
    lin = s.linearize({"alpha": 0, "beta": 0, "phi": jd.symbols("Omega") * jd.t})
    assert lin.is_time_invariant
    for Om in (50.0, 120.0):
        num = lin.evaluate(t=0.7, parameters={"Omega": Om})
        C = 0.03
        np.testing.assert_allclose(num["h"], 0.0, atol=1e-12)
        np.testing.assert_allclose(np.abs(num["G"][0, 1]), C * Om, rtol=1e-13)
        np.testing.assert_allclose(num["G"], -num["G"].T, atol=0)
        G = num["G"].copy()
        G[0, 1] = G[1, 0] = 0.0
        assert np.abs(G).max() < 1e-12 * C * Om
        np.testing.assert_allclose(num["D"], np.diag([0.0, 0.0, 0.1]), atol=1e-13)
        np.testing.assert_allclose(num["K"], np.diag([50.0, 50.0, 0.0]), atol=1e-12)
        np.testing.assert_allclose(num["M_tilde"], np.diag([0.02 + 2 * 0.04, 0.02 + 2 * 0.04,
                                                            0.03]), rtol=1e-13)
        assert np.abs(num["N"]).max() < 1e-12


def test_time_variant_result_refuses_to_split():
    """An unbalanced (asymmetric) rotor turning at Ω t: M̃ depends on t."""
    al, ph = jd.symbols("alpha phi")
    disc = jd.Body("disc", "world", jd.Universal("pivot", (al, ph), ("x", "z")), mass=1.0,
                   com=(0, 0, 0.2), inertia=(0.01, 0.02, 0.03))
    s = jd.System([al, ph], [disc], [])
    lin = s.linearize({"alpha": 0, "phi": 5 * jd.t})
    assert not lin.is_time_invariant and "M_tilde" in lin.time_dependence
    with pytest.raises(jd.TimeVariantError, match="time-variant"):
        _ = lin.K
    with pytest.raises(jd.TimeVariantError):
        _ = lin.is_conservative
    num0, num1 = lin.evaluate(t=0.0), lin.evaluate(t=0.1)
    assert "K" not in num0
    assert abs(num0["M_tilde"][0, 0] - num1["M_tilde"][0, 0]) > 1e-4


def test_nominal_trajectory_residual_against_compiled_equations():
    """For y_s(t) that does not solve the equations, h(t) = q − k − M·ÿ_s on the trajectory."""
    s = double_pendulum()
    t = jd.t
    ys = {"phi1": 0.4 * jd.sin(2 * t), "phi2": 0.1 + 0.3 * t**2}
    lin = s.linearize(ys)
    for tv in (0.0, 0.3, 1.1):
        y = [0.4 * np.sin(2 * tv), 0.1 + 0.3 * tv**2]
        yd = [0.8 * np.cos(2 * tv), 0.6 * tv]
        ydd = [-1.6 * np.sin(2 * tv), 0.6]
        ref = s.evaluate(y, yd, t=tv)
        h_ref = ref["q"] - ref["k"] - ref["M"] @ ydd
        num = lin.evaluate(t=tv)
        np.testing.assert_allclose(num["h"], h_ref, rtol=1e-12, atol=1e-12)
        assert np.abs(num["h"]).max() > 0.1


def _residual(s, y, yd, ydd, t, inputs=None):
    out = s.evaluate(y, yd, t=t, inputs=inputs)
    return out["M"] @ ydd + out["k"] - out["q"]


@pytest.mark.parametrize("model", ["spatial_chain", "heavy_top", "cart"])
def test_matrices_against_central_differences(model, rng):
    """At random nominal states y_s(t) = a + b t + c t²: M̃ = M(y_s), Q = ∂r/∂y, P = ∂r/∂ẏ,
    B = −∂r/∂u with r = M·ÿ_s + k − q, by central differences of the compiled equations."""
    if model == "spatial_chain":
        s = spatial_chain(3)
    elif model == "heavy_top":
        s = heavy_top()
    else:
        s = jd.models.n_link_pendulum_on_cart(2)
    f = s.f
    a, b, c = rng.uniform(-1, 1, (3, f))
    if model == "heavy_top":
        a[1] = 0.8  # keep θ away from the Euler-angle singularity
    t0 = float(rng.uniform(0, 1))
    nominal = {n: float(a[i]) + float(b[i]) * jd.t + float(c[i]) * jd.t**2
               for i, n in enumerate(s.coordinate_names)}
    u0 = {n: float(rng.uniform(-1, 1)) for n in s.input_names}
    nominal.update(u0)
    num = s.linearize(nominal).evaluate(t=t0)
    y, yd, ydd = a + b * t0 + c * t0**2, b + 2 * c * t0, 2 * c
    eps = 1e-6
    Q = np.zeros((f, f))
    P = np.zeros((f, f))
    for j in range(f):
        e = np.zeros(f)
        e[j] = eps
        Q[:, j] = (_residual(s, y + e, yd, ydd, t0, u0 or None)
                   - _residual(s, y - e, yd, ydd, t0, u0 or None)) / (2 * eps)
        P[:, j] = (_residual(s, y, yd + e, ydd, t0, u0 or None)
                   - _residual(s, y, yd - e, ydd, t0, u0 or None)) / (2 * eps)
    scale = max(1.0, np.abs(Q).max(), np.abs(P).max())
    np.testing.assert_allclose(num["M_tilde"], s.evaluate(y, yd, t=t0, inputs=u0 or None)["M"],
                               rtol=1e-12, atol=1e-13)
    assert np.abs(num["Q"] - Q).max() < 1e-7 * scale
    assert np.abs(num["P"] - P).max() < 1e-7 * scale
    np.testing.assert_allclose(num["h"], -_residual(s, y, yd, ydd, t0, u0 or None), atol=1e-11)
    if u0:
        B = np.zeros((f, len(u0)))
        for j, name in enumerate(s.input_names):
            up = {**u0, name: u0[name] + eps}
            um = {**u0, name: u0[name] - eps}
            B[:, j] = -(_residual(s, y, yd, ydd, t0, up) - _residual(s, y, yd, ydd, t0, um)) / (
                2 * eps)
        np.testing.assert_allclose(num["B"], B, atol=1e-8)


def test_bad_nominal_motion_is_reported():
    s = double_pendulum()
    with pytest.raises(jd.ModelError, match="phi2"):
        s.linearize({"phi1": 0})
    with pytest.raises(jd.ModelError, match="psi"):
        s.linearize({"phi1": 0, "phi2": 0, "psi": 1})
    with pytest.raises(jd.ModelError, match="Omega"):
        s.linearize({"phi1": jd.symbols("Omega") * jd.t, "phi2": 0})
    # text goes through the model files' parser (issue 38): never eval or sympify
    with pytest.raises(jd.ModelError):
        s.linearize({"phi1": "__import__('os')", "phi2": 0})
    with pytest.raises(jd.ModelError):
        s.linearize({"phi1": float("nan"), "phi2": 0})
    lin = s.linearize({"phi1": 0, "phi2": 0})
    with pytest.raises(jd.EvaluationError, match="unknown parameter"):
        lin.evaluate(parameters={"mass": 1.0})
    with pytest.raises(jd.EvaluationError):
        lin.evaluate(t=float("inf"))


def test_compiled_matches_graph_evaluation():
    s = jd.models.n_link_pendulum_on_cart(2)
    with pytest.warns(jd.NominalMotionWarning):
        lin = s.linearize({"q0": 0, "q1": 0.2, "q2": -0.1, "F": 1.0})
    fn = lin.compile()
    pars = {"m1": 1.7, "l0": 0.6}
    a, b = lin.evaluate(parameters=pars), fn(parameters=pars)
    for key in ("M_tilde", "P", "Q", "h", "B", "K", "N"):
        np.testing.assert_allclose(a[key], b[key], rtol=1e-12, atol=1e-12)


def test_numeric_path_matches_symbolic(rng):
    """linearize_numeric (floating-point forward mode) against the symbolic matrices evaluated,
    on a nominal trajectory with inputs and at a rotor's steady rotation."""
    s = jd.models.n_link_pendulum_on_cart(3)
    nominal = {n: float(rng.uniform(-1, 1)) + float(rng.uniform(-1, 1)) * jd.t**2
               for n in s.coordinate_names}
    nominal["F"] = 0.7
    pars = {"m2": 1.4, "g": 9.7}
    sym = s.linearize(nominal).evaluate(t=0.4, parameters=pars)
    num = jd.linearize_numeric(s, nominal, t=0.4, parameters=pars)
    for key in ("M_tilde", "P", "Q", "h", "B"):
        np.testing.assert_allclose(getattr(num, key), sym[key], rtol=1e-11, atol=1e-11)
    assert num.time_dependence  # a trajectory: time-variant
    with pytest.raises(jd.TimeVariantError):
        _ = num.K
    # bodies with full inertia tensors (the numeric path forms M̃ = J̄ᵀM̄J̄ and ∂(M·ÿ_s)/∂y
    # from J̄ and its derivatives)
    c = spatial_chain(3)
    nominal = {n: float(rng.uniform(-1, 1)) + float(rng.uniform(-2, 2)) * jd.t**2
               for n in c.coordinate_names}
    sym = c.linearize(nominal).evaluate(t=0.6)
    num = jd.linearize_numeric(c, nominal, t=0.6)
    for key in ("M_tilde", "P", "Q", "h"):
        np.testing.assert_allclose(getattr(num, key), sym[key], rtol=1e-11, atol=1e-11)
    r = rotor()
    nl = jd.linearize_numeric(r, {"alpha": 0, "beta": 0, "phi": jd.symbols("Omega") * jd.t},
                              t=0.3)
    assert nl.is_time_invariant
    np.testing.assert_allclose(abs(nl.G[0, 1]), 0.03 * 100.0, rtol=1e-12)
    with pytest.raises(jd.EvaluationError):
        jd.state_space(nl, parameters={"Omega": 5.0})  # numbers for one parameter set only


def test_general_form_gives_every_operating_point(rng):
    """linearization_general (functions of the state) evaluated at a state equals the
    linearization about a nominal motion through that state (with the same ẏ, ÿ)."""
    from jourdain import linearization_general  # with evaluate (jourdain.numeric.linearization)

    s = double_pendulum()
    gen = linearization_general(s.equations_of_motion())
    y, yd, ydd = rng.uniform(-1, 1, (3, 2))
    t0 = 0.8
    nominal = {n: float(y[i]) + float(yd[i]) * (jd.t - t0) + 0.5 * float(ydd[i]) * (jd.t - t0)**2
               for i, n in enumerate(s.coordinate_names)}
    a = gen.evaluate(y, yd, ydd, t=t0)
    b = s.linearize(nominal).evaluate(t=t0)
    for key in ("M_tilde", "P", "Q", "h"):
        np.testing.assert_allclose(a[key], b[key], rtol=1e-12, atol=1e-12)


def test_graph_tells_apart_expressions_with_equal_hashes():
    """SymEngine's hash combines the terms of a sum by exclusive-or: cx5 + dx4 and
    cx5 + dx0 + dx1 + dx2 + dx3 + dx4 collide. The derivative graph must keep them apart."""
    from jourdain.graph import evaluate_float, jet, jet_float

    cx5, dx0, dx1, dx2, dx3, dx4, q = jd.symbols("cx5 dx0 dx1 dx2 dx3 dx4 q")
    a = cx5 + dx4
    b = cx5 + dx0 + dx1 + dx2 + dx3 + dx4
    # hash(a) == hash(b) with SymEngine 0.15 (the pitfall); the test holds either way
    exprs = [a * jd.sin(q), b * jd.sin(q)]
    values = {"cx5": 1.0, "dx0": 2.0, "dx1": 3.0, "dx2": 4.0, "dx3": 5.0, "dx4": 6.0, "q": 0.3}
    np.testing.assert_allclose(evaluate_float(exprs, values),
                               [7 * np.sin(0.3), 21 * np.sin(0.3)], rtol=1e-15)
    J = jet_float(exprs, [q], values)
    np.testing.assert_allclose(J.jacobian[:, 0], [7 * np.cos(0.3), 21 * np.cos(0.3)],
                               rtol=1e-15)
    sym = jet(exprs, [q], {q: 0})
    assert se.expand(sym.gradients[0][0] - a) == 0 and se.expand(sym.gradients[1][0] - b) == 0


def test_forces_that_cancel_within_a_body_do_not_hide_the_scale():
    """The quarter car at rest: gravity on the body is held by the preloaded suspension, so
    the body's resultant q̄^e is round-off, and h = 4.5e-13 N once counted as 8 times the
    forces at work. Against the separate terms of k and q it is the round-off it is (both
    paths); an equilibrium off by 1 mm is still refused."""
    import warnings
    from pathlib import Path

    from jourdain.io.capabilities import nominal_mapping
    from jourdain.io.modelfile import load_model

    m = load_model(Path(__file__).parents[1] / "examples" / "quarter_car.toml")
    s = m.system
    nominal = nominal_mapping(s, m.nominal_motion("static"))
    with warnings.catch_warnings():
        warnings.simplefilter("error", jd.NominalMotionWarning)
        assert s.linearize(nominal).check_nominal().is_solution
        assert jd.linearize_numeric(s, nominal).nominal_check.is_solution
    off = {**nominal, "z_b": 1e-3}
    with pytest.warns(jd.NominalMotionWarning):
        assert not s.linearize(off).check_nominal().is_solution
    with pytest.warns(jd.NominalMotionWarning):
        jd.linearize_numeric(s, off)
