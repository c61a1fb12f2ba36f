"""Analysis of linearized systems against closed forms derived by hand: natural frequencies,
whirl frequencies of a gyroscopic rotor, the flutter load of Ziegler's follower-load column,
damping ratios and frequency responses of single oscillators, stability verdicts, equilibria."""

import numpy as np
import pytest

import jourdain as jd
from jourdain.models import double_pendulum
from tests.test_linearization import pendulum, rotor
from tests.tolerance import state_space_eig_tol


def test_double_pendulum_natural_frequencies_closed_form():
    """Absolute angles θ1, θ2 (uniform rods): M = [[m1 l1²/3 + m2 l1², m2 l1 l2/2],
    [m2 l1 l2/2, m2 l2²/3]], K = diag((m1/2 + m2) g l1, m2 g l2/2); det(K − ω²M) = 0 gives
    ω² = (b ∓ √(b² − 4ac)) / 2a with a = det M, b = M11 K22 + M22 K11, c = K11 K22."""
    s = double_pendulum()
    for pars in ({}, {"m1": 2.0, "m2": 1.3, "l1": 0.6, "l2": 0.9}):
        p = {**s.parameter_values, **pars}
        m1, m2, l1, l2, g = (p[n] for n in ("m1", "m2", "l1", "l2", "g"))
        M11, M12, M22 = m1 * l1**2 / 3 + m2 * l1**2, m2 * l1 * l2 / 2, m2 * l2**2 / 3
        K11, K22 = (m1 / 2 + m2) * g * l1, m2 * g * l2 / 2
        a, b, c = M11 * M22 - M12**2, M11 * K22 + M22 * K11, K11 * K22
        w2 = np.array([b - np.sqrt(b * b - 4 * a * c), b + np.sqrt(b * b - 4 * a * c)]) / (2 * a)
        m = jd.modes(s.linearize({"phi1": 0, "phi2": 0}), parameters=pars)
        osc = m.oscillating()
        # eigenvalues of A = [[0, E], [−M⁻¹K, 0]]: to their condition numbers times A's error
        _, tol = state_space_eig_tol(jd.state_space(s.linearize({"phi1": 0, "phi2": 0}),
                                                    parameters=pars))
        np.testing.assert_allclose(m.natural_frequencies[osc], np.sqrt(w2), rtol=0,
                                   atol=tol.max())
        np.testing.assert_allclose(m.damping_ratios[osc], 0.0,
                                   atol=tol.max() / np.sqrt(w2).min())
        # first mode: both rods swing the same way; second: opposite (in absolute angles)
        th = np.array([[1, 0], [1, 1]]) @ m.shapes[:, osc].real
        assert th[0, 0] * th[1, 0] > 0 and th[0, 1] * th[1, 1] < 0
        assert jd.stability(m_ss := jd.state_space(s.linearize({"phi1": 0, "phi2": 0}),
                                                    parameters=pars)).verdict == (
            "marginally stable")
        assert m_ss.A.shape == (4, 4)


def test_rotor_whirl_frequencies_closed_form():
    """A_p ω² ∓ C Ω ω − c = 0 with A_p = A + m L²: forward and backward whirl
    ω = (±CΩ + √(C²Ω² + 4 A_p c)) / 2A_p; the spin coordinate adds λ = 0 and λ = −d/C."""
    s = rotor()
    lin = s.linearize({"alpha": 0, "beta": 0, "phi": jd.symbols("Omega") * jd.t})
    p = s.parameter_values
    Ap, C, c, d = p["A"] + p["m"] * p["L"] ** 2, p["C"], p["c"], p["d"]
    for Om in (0.0, 80.0, 300.0):
        m = jd.modes(lin, parameters={"Omega": Om})
        _, tol = state_space_eig_tol(jd.state_space(lin, parameters={"Omega": Om}))
        root = np.sqrt((C * Om) ** 2 + 4 * Ap * c)
        expected = sorted([(root + C * Om) / (2 * Ap), (root - C * Om) / (2 * Ap)])
        whirl = sorted(m.eigenvalues[m.oscillating()].imag)
        np.testing.assert_allclose(whirl, expected, rtol=0, atol=tol.max())
        real = np.sort(m.eigenvalues[np.abs(m.eigenvalues.imag) < 1e-9].real)
        np.testing.assert_allclose(real, [-d / C, 0.0], rtol=0, atol=tol.max())
        st = jd.stability(lin, parameters={"Omega": Om})
        assert st.verdict == "marginally stable", st.reason


def ziegler_column() -> jd.System:
    """Ziegler's column: two massless rods of length l standing upright, point masses m1 (at
    the middle joint) and m2 (at the tip), rotational springs c1 (ground) and c2 (middle), a
    follower force F at the tip along the second rod; relative angles φ1, φ2; no gravity."""
    p1, p2, m1, m2, l, c1, c2, F = jd.symbols("phi1 phi2 m1 m2 l c1 c2 F")
    b1 = jd.Body("link1", "world", jd.Revolute("j1", p1, "z"), mass=m1, com=(0, l, 0),
                 inertia=jd.point_mass())
    b2 = jd.Body("link2", "link1", jd.Revolute("j2", p2, "z", position=(0, l, 0)), mass=m2,
                 com=(0, l, 0), inertia=jd.point_mass())
    forces = [jd.RotationalSpringDamper("s1", p1, stiffness=c1),
              jd.RotationalSpringDamper("s2", p2, stiffness=c2),
              jd.Force("follower", "link2", (0, -F, 0), point=(0, l, 0), frame="link2")]
    return jd.System([p1, p2], [b1, b2], forces,
                     parameters={"m1": 1.5, "m2": 0.8, "l": 0.5, "c1": 30.0, "c2": 20.0,
                                 "F": 0.0})


def test_follower_load_flutter_against_hand_derivation():
    """In absolute angles the linear equations are M θ̈ + Q θ = 0 with M = l²[[m1+m2, m2],
    [m2, m2]] and Q = [[c1 + c2 − Fl, Fl − c2], [−c2, c2]] (the follower force does virtual work
    −Fl sin(θ2 − θ1) δθ1). det(Q − λM) = m1 m2 l⁴ λ² − l²(m1 c2 + m2 c1 + 4 m2 c2 − 2 m2 F l) λ +
    c1 c2: the two λ = ω² merge and turn complex (flutter) at
    F_cr = (m1 c2 + m2 c1 + 4 m2 c2 − 2√(m1 m2 c1 c2)) / (2 m2 l); with m1 = 2m2, c1 = c2 this
    is Ziegler's (7/2 − √2) c/l."""
    s = ziegler_column()
    lin = s.linearize({"phi1": 0, "phi2": 0})
    p = s.parameter_values
    m1, m2, l, c1, c2 = (p[n] for n in ("m1", "m2", "l", "c1", "c2"))
    F_cr = (m1 * c2 + m2 * c1 + 4 * m2 * c2 - 2 * np.sqrt(m1 * m2 * c1 * c2)) / (2 * m2 * l)
    # the follower force is circulatory: N ≠ 0, proportional to F, zero without it
    assert np.abs(lin.evaluate(parameters={"F": 0.0})["N"]).max() == 0.0
    N1, N2 = (lin.evaluate(parameters={"F": F})["N"] for F in (10.0, 20.0))
    assert np.abs(N1).max() > 1.0
    np.testing.assert_allclose(N2, 2 * N1, rtol=1e-13)
    assert not lin.is_conservative
    assert jd.stability(lin, parameters={"F": 0.97 * F_cr}).verdict == "marginally stable"
    st = jd.stability(lin, parameters={"F": 1.03 * F_cr})
    assert st.verdict == "unstable" and "flutter" in st.reason
    F_found = jd.stability_boundary(lin, "F", 0.0, 2 * F_cr)
    assert abs(F_found - F_cr) < 1e-6 * F_cr
    sw = jd.sweep(lin, "F", np.linspace(0, 1.5 * F_cr, 31))
    assert F_cr <= sw.first_unstable() <= F_cr + 0.05 * F_cr
    assert sw.eigenvalues.shape == (31, 4)
    # Ziegler's classical value
    zl = jd.stability_boundary(lin, "F", 0.0, 10.0, parameters={"m1": 2.0, "m2": 1.0, "c1": 1.0,
                                                                 "c2": 1.0, "l": 1.0})
    assert abs(zl - (3.5 - np.sqrt(2))) < 1e-6


def test_damped_pendulum_damping_ratio_and_frequency_response():
    """m l² φ̈ + d φ̇ + m g l φ = h: ω_n = √(g/l), ζ = d / (2√(m g l · m l²)),
    H(Ω) = 1 / (m g l − Ω² m l² + iΩ d)."""
    s = pendulum(damping=True)
    lin = s.linearize({"phi": 0})
    m, l, g, d = 2.0, 0.5, 9.81, 0.3
    k, M = m * g * l, m * l * l
    modes = jd.modes(lin)
    i = modes.oscillating()[0]
    np.testing.assert_allclose(modes.natural_frequencies[i], np.sqrt(g / l), rtol=1e-12)
    np.testing.assert_allclose(modes.damping_ratios[i], d / (2 * np.sqrt(k * M)), rtol=1e-12)
    st = jd.stability(lin)
    assert st.verdict == "asymptotically stable" and st.max_real_part < 0
    w = np.linspace(0.0, 3 * np.sqrt(g / l), 50)
    fr = jd.frequency_response(lin, w, excitation="h")
    H = 1.0 / (k - w**2 * M + 1j * w * d)
    np.testing.assert_allclose(fr.magnitude[:, 0, 0], np.abs(H), rtol=1e-12)
    np.testing.assert_allclose(fr.phase[:, 0, 0], np.unwrap(np.angle(H)), atol=1e-12)
    assert fr.phase[-1, 0, 0] < -np.pi / 2  # past resonance the response lags by > 90°
    with pytest.raises(jd.EvaluationError, match="no inputs"):
        jd.frequency_response(lin, w)


def test_frequency_response_of_an_input():
    """Cart m on a spring c and damper d to the wall, force input F: η̂ = F̂ / (c − Ω²m + iΩd)."""
    x, m, c, d, F = jd.symbols("x m c d F")
    cart = jd.Body("cart", "world", jd.Prismatic("slider", x, "x"), mass=m,
                   inertia=jd.point_mass())
    s = jd.System([x], [cart],
                  [jd.SpringDamper("wall", "world", (-1, 0, 0), "cart", (0, 0, 0), stiffness=c,
                                   damping=d, rest_length=1),
                   jd.Force("push", "cart", (F, 0, 0))],
                  parameters={"m": 3.0, "c": 120.0, "d": 2.0}, inputs=[F])
    lin = s.linearize({"x": 0})
    w = np.array([0.0, 2.0, 6.3, 20.0])
    fr = jd.frequency_response(lin, w)
    np.testing.assert_allclose(fr.of("x", "F"), 1.0 / (120.0 - 3.0 * w**2 + 2j * w), rtol=1e-12)
    ss = jd.state_space(lin)
    np.testing.assert_allclose(ss.B, [[0.0], [1.0 / 3.0]], rtol=1e-14)


def test_stability_verdicts():
    # upright pendulum: divergence
    st = jd.stability(pendulum().linearize({"phi": jd.pi}))
    assert st.verdict == "unstable" and "divergence" in st.reason
    # a free cart (no spring): λ = 0 twice with one eigenvector, the motion drifts
    x, m = jd.symbols("x m")
    cart = jd.Body("cart", "world", jd.Prismatic("slider", x, "x"), mass=m,
                   inertia=jd.point_mass())
    free = jd.System([x], [cart], [], parameters={"m": 1.0})
    st = jd.stability(free.linearize({"x": 0}), cyclic=())
    assert st.verdict == "unstable" and "linearly" in st.reason
    # ... but x is cyclic: in Routh's sense (the default) its momentum ẋ is judged, not x
    st = jd.stability(free.linearize({"x": 0}))
    assert st.verdict == "marginally stable" and st.cyclic == ("x",), st.reason
    # two identical uncoupled oscillators: a repeated, semisimple pair on the axis
    y1, y2 = jd.symbols("y1 y2")
    b1 = jd.Body("b1", "world", jd.Prismatic("s1", y1, "x"), mass=m, inertia=jd.point_mass())
    b2 = jd.Body("b2", "world", jd.Prismatic("s2", y2, "y"), mass=m, inertia=jd.point_mass())
    twin = jd.System([y1, y2], [b1, b2], [jd.RotationalSpringDamper("k1", y1, stiffness=4.0),
                                          jd.RotationalSpringDamper("k2", y2, stiffness=4.0)],
                     parameters={"m": 1.0})
    st = jd.stability(twin.linearize({"y1": 0, "y2": 0}))
    assert st.verdict == "marginally stable", st.reason


def test_time_variant_linearization_is_refused_by_state_space():
    al, ph = jd.symbols("alpha phi")
    disc = jd.Body("disc", "world", jd.Universal("pivot", (al, ph), ("x", "z")), mass=1.0,
                   com=(0, 0, 0.2), inertia=(0.01, 0.02, 0.03))
    lin = jd.System([al, ph], [disc], []).linearize({"alpha": 0, "phi": 5 * jd.t})
    with pytest.raises(jd.TimeVariantError, match="time-variant"):
        jd.modes(lin)
    ss = jd.state_space(lin, t=0.2, allow_time_variant=True)
    assert ss.A.shape == (4, 4)


def test_equilibria_which_one_is_meant():
    s = double_pendulum()
    hanging = jd.find_equilibrium(s, {"phi1": 0.4, "phi2": -0.3})
    np.testing.assert_allclose(hanging.y, [0.0, 0.0], atol=1e-9)
    upright = jd.find_equilibrium(s, {"phi1": 2.9, "phi2": 0.2})
    np.testing.assert_allclose(upright.y, [np.pi, 0.0], atol=1e-9)
    assert jd.stability(s.linearize(hanging)).verdict == "marginally stable"
    assert jd.stability(s.linearize(upright)).verdict == "unstable"
    found = jd.find_equilibria(s, [[0.1, 0.1], [3.0, 0.1], [0.1, 3.0], [3.0, 3.0], [0.0, 0.0]])
    assert len(found) == 4
    # method="stable" goes downhill in the potential: from near the upright position it ends
    # hanging (at a multiple of 2π)
    down = jd.find_equilibrium(s, {"phi1": 2.9, "phi2": 0.2}, method="stable")
    wrapped = np.angle(np.exp(1j * down.y))
    np.testing.assert_allclose(wrapped, [0.0, 0.0], atol=1e-9)
    assert jd.stability(s.linearize(down)).verdict == "marginally stable"
    # a pendulum pushed sideways by a constant force F: tan φ = F / (m g)
    phi, m, l, g, F = jd.symbols("phi m l g F")
    bob = jd.Body("bob", "world", jd.Revolute("pivot", phi, "z"), mass=m, com=(0, -l, 0),
                  inertia=jd.point_mass())
    s = jd.System([phi], [bob], [jd.Gravity((0, -g, 0)),
                                 jd.Force("push", "bob", (F, 0, 0), point=(0, -l, 0))],
                  parameters={"m": 2.0, "l": 0.5, "g": 9.81}, inputs=[F])
    eq = jd.find_equilibrium(s, {"phi": 0.1}, inputs={"F": 5.0})
    np.testing.assert_allclose(eq.y, [np.arctan(5.0 / (2.0 * 9.81))], rtol=1e-12)
    lin = s.linearize(eq)  # the equilibrium carries its input value
    np.testing.assert_allclose(lin.evaluate()["h"], [0.0], atol=1e-12)
    np.testing.assert_allclose(lin.evaluate()["K"],
                               [[0.5 * np.hypot(5.0, 2.0 * 9.81)]], rtol=1e-12)
    # no equilibrium: a constant torque larger than the largest gravity torque
    s2 = jd.System([phi], [bob], [jd.Gravity((0, -g, 0)),
                                  jd.GeneralizedForce("motor", phi, 20.0)],
                   parameters={"m": 2.0, "l": 0.5, "g": 9.81})
    with pytest.raises(jd.NoEquilibrium, match="no equilibrium"):
        jd.find_equilibrium(s2, {"phi": 0.0})
    with pytest.raises(jd.EvaluationError, match="unknown coordinate"):
        jd.find_equilibrium(s2, {"psi": 0.0})


def test_rotor_internal_damping_stability_threshold():
    """Jeffcott rotor (disc m on a shaft of stiffness k, whirl coordinates x, y) with external
    damping c_e and internal (rotating) damping c_i at spin Ω: the internal damping force
    −c_i·(ẋ + Ωy, ẏ − Ωx) is circulatory (N = ±c_i Ω). With z = x + iy:
    m z̈ + (c_e + c_i) ż + (k − i c_i Ω) z = 0; at the stability boundary λ = iω gives ω² = k/m
    and (c_e + c_i) ω = c_i Ω, so Ω_crit = √(k/m)·(1 + c_e/c_i)."""
    x, y, m, k, ce, ci, Om = jd.symbols("x y m k c_e c_i Omega")
    slide_x = jd.Body("carrier", "world", jd.Prismatic("sx", x, "x"), mass=0,
                      inertia=jd.point_mass())
    disc = jd.Body("disc", "carrier", jd.Prismatic("sy", y, "y"), mass=m,
                   inertia=jd.point_mass())
    xd, yd = jd.rate(x), jd.rate(y)
    forces = [jd.GeneralizedForce("shaft_x", x, -k * x - ce * xd - ci * (xd + Om * y)),
              jd.GeneralizedForce("shaft_y", y, -k * y - ce * yd - ci * (yd - Om * x))]
    s = jd.System([x, y], [slide_x, disc], forces,
                  parameters={"m": 2.0, "k": 800.0, "c_e": 1.5, "c_i": 4.0, "Omega": 0.0})
    lin = s.linearize({"x": 0, "y": 0})
    num = lin.evaluate(parameters={"Omega": 30.0})
    np.testing.assert_allclose(num["N"], [[0.0, 4.0 * 30.0], [-4.0 * 30.0, 0.0]], rtol=1e-14)
    np.testing.assert_allclose(num["D"], np.diag([5.5, 5.5]), rtol=1e-14)
    Om_crit = np.sqrt(800.0 / 2.0) * (1 + 1.5 / 4.0)
    assert jd.stability(lin, parameters={"Omega": 0.95 * Om_crit}).verdict == (
        "asymptotically stable")
    st = jd.stability(lin, parameters={"Omega": 1.05 * Om_crit})
    assert st.verdict == "unstable" and "flutter" in st.reason
    found = jd.stability_boundary(lin, "Omega", 0.0, 3 * Om_crit)
    assert abs(found - Om_crit) < 1e-10 * Om_crit


def test_equilibrium_with_a_fixed_cyclic_coordinate():
    """spatial_chain(3): the base turns about the vertical (a cyclic coordinate, any value is an
    equilibrium); held fixed at 0.7 it stays there while the rest settles hanging down."""
    from jourdain.models import spatial_chain

    s = spatial_chain(3)
    eq = jd.find_equilibrium(s, {"q0": 0.7, "q1": 3.0}, fixed=["q0"], method="stable")
    assert eq.y[0] == 0.7
    out = s.evaluate(eq.y, np.zeros(s.f))
    np.testing.assert_allclose(out["q"] - out["k"], 0.0, atol=1e-9)
    # hanging: the potential is at a minimum, K has no negative eigenvalue
    K = jd.linearize_numeric(s, eq).K
    assert np.linalg.eigvalsh(K).min() > -1e-9
