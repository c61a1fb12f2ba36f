"""Equations of motion M·ÿ + k = q against closed forms derived by hand, and internal
cross-checks (M as the Hessian of the kinetic energy, the power balance of k and q)."""

import numpy as np
import pytest
import symengine as se
import sympy as sp

import jourdain as jd
from jourdain.models import double_pendulum, heavy_top, n_link_pendulum_on_cart, spatial_chain
from tests.kinematics_fd import compile_kinematics, fd_velocity
from tests.tolerance import assert_close_eval


def test_simple_pendulum():
    """m l² φ̈ = -m g l sin φ (point mass on a massless rod, φ from the downward vertical)."""
    phi, m, l, g = jd.symbols("phi m l g")
    bob = jd.Body("bob", "world", jd.Revolute("pivot", phi, "z"), mass=m, com=(0, -l, 0),
                  inertia=jd.point_mass())
    s = jd.System([phi], [bob], [jd.Gravity((0, -g, 0))],
                  parameters={"m": 2.0, "l": 0.5, "g": 9.81})
    out = s.evaluate([0.7], [1.3])
    np.testing.assert_allclose(out["M"], [[2.0 * 0.25]], rtol=1e-14)
    np.testing.assert_allclose(out["k"], [0.0], atol=1e-14)
    np.testing.assert_allclose(out["q"], [-2.0 * 9.81 * 0.5 * np.sin(0.7)], rtol=1e-14)


def test_double_pendulum_closed_form(rng):
    """Two uniform rods, relative angle φ2: M, k and q from Lagrange's equations by hand."""
    s = double_pendulum()
    p = s.parameter_values
    m1, m2, l1, l2, g = (p[n] for n in ("m1", "m2", "l1", "l2", "g"))
    I2 = m2 * l2**2 / 12
    for _ in range(5):
        (p1, p2), (w1, w2) = rng.uniform(-3, 3, 2), rng.uniform(-3, 3, 2)
        out = s.evaluate([p1, p2], [w1, w2])
        c, sn = np.cos(p2), np.sin(p2)
        M22 = m2 * l2**2 / 4 + I2
        M12 = M22 + m2 * l1 * l2 * c / 2
        M11 = m1 * l1**2 / 3 + m2 * l1**2 + M22 + m2 * l1 * l2 * c
        h = m2 * l1 * l2 / 2
        k = [-h * sn * (2 * w1 * w2 + w2**2), h * sn * w1**2]
        q = [-(m1 / 2 + m2) * g * l1 * np.sin(p1) - m2 * g * l2 / 2 * np.sin(p1 + p2),
             -m2 * g * l2 / 2 * np.sin(p1 + p2)]
        np.testing.assert_allclose(out["M"], [[M11, M12], [M12, M22]], rtol=1e-12)
        np.testing.assert_allclose(out["k"], k, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(out["q"], q, rtol=1e-12)


def test_heavy_symmetric_top_against_lagrange(rng):
    """T = ½A'(θ̇² + ψ̇² sin²θ) + ½C(φ̇ + ψ̇ cos θ)², V = m g L cos θ with A' = A + m L²;
    M, k = Ṁẏ - ∂T/∂y and q = -∂V/∂y from these by SymPy differentiation."""
    ts = sp.symbols("t")
    psi, th, ph = (sp.Function(n)(ts) for n in ("psi", "theta", "phi"))
    m, L, A, C, g = sp.symbols("m L A C g")
    Ap = A + m * L**2
    T = (Ap * (th.diff(ts) ** 2 + psi.diff(ts) ** 2 * sp.sin(th) ** 2)
         + C * (ph.diff(ts) + psi.diff(ts) * sp.cos(th)) ** 2) / 2
    V = m * g * L * sp.cos(th)
    qs = [psi, th, ph]
    qd = [x.diff(ts) for x in qs]
    lag = [sp.diff(T.diff(v), ts) - T.diff(x) + V.diff(x) for x, v in zip(qs, qd, strict=True)]
    qdd = [x.diff(ts, 2) for x in qs]
    M_ref = sp.Matrix([[e.diff(a) for a in qdd] for e in lag])
    rest = sp.Matrix([e.subs({a: 0 for a in qdd}) for e in lag])  # k - q
    Y = sp.symbols("y0:3")
    Yd = sp.symbols("yd0:3")
    sub = {**dict(zip(qd, Yd, strict=True)), **dict(zip(qs, Y, strict=True))}
    par = heavy_top().parameter_values
    fM = sp.lambdify([Y, Yd, m, L, A, C, g], M_ref.subs(sub))
    fr = sp.lambdify([Y, Yd, m, L, A, C, g], rest.subs(sub))
    s = heavy_top()
    for _ in range(5):
        y, yd = rng.uniform(-2, 2, 3), rng.uniform(-5, 5, 3)
        args = (y, yd, par["m"], par["L"], par["A"], par["C"], par["g"])
        out = s.evaluate(y, yd)
        # evaluated directly on both sides: rounding of 6p products, relative to the terms
        J, Mb = np.abs(out["J_bar"]), np.abs(out["M_bar"])
        n6 = J.shape[0]
        assert_close_eval(out["M"], np.array(fM(*args), float), n6, (J.T @ Mb @ J).max())
        terms = J.T @ (np.abs(out["q_c"]) + np.abs(out["q_e"]))
        assert_close_eval(out["k"] - out["q"], np.array(fr(*args), float).ravel(), n6,
                          terms.max())


def test_pendulum_on_shaken_support():
    """Support moved vertically by a·sin(ωt): m l² φ̈ + m l (g + ÿ_s) sin φ = 0, so
    k = -m l a ω² sin(ωt) sin φ and q = -m g l sin φ (closed form)."""
    phi, m, l, g, a, w = jd.symbols("phi m l g a w")
    support = jd.Body("support", "world", jd.General("shaker", [jd.Trans("y", a * jd.sin(w * jd.t))]),
                      mass=5.0, inertia=jd.point_mass())
    bob = jd.Body("bob", "support", jd.Revolute("pivot", phi, "z"), mass=m, com=(0, -l, 0),
                  inertia=jd.point_mass())
    s = jd.System([phi], [support, bob], [jd.Gravity((0, -g, 0))],
                  parameters={"m": 1.5, "l": 0.8, "g": 9.81, "a": 0.05, "w": 20.0})
    for t in (0.1, 0.37):
        out = s.evaluate([0.4], [2.0], t=t)
        np.testing.assert_allclose(out["M"], [[1.5 * 0.64]], rtol=1e-14)
        k = -1.5 * 0.8 * 0.05 * 400.0 * np.sin(20.0 * t) * np.sin(0.4)
        np.testing.assert_allclose(out["k"], [k], rtol=1e-12)
        np.testing.assert_allclose(out["q"], [-1.5 * 9.81 * 0.8 * np.sin(0.4)], rtol=1e-13)


def test_spring_damper_is_the_gradient_of_its_potential(rng):
    """q of a (nonlinear) spring between a pendulum bob and the world equals -∂V/∂y by finite
    differences; the damper force equals -d·L̇·∂L/∂y."""
    p1, p2 = jd.symbols("p1 p2")
    k3, d = jd.symbols("k3 d")
    e = jd.elongation
    bodies = [
        jd.Body("a", "world", jd.Revolute("h1", p1, "z"), mass=1.0, com=(0, -0.5, 0),
                inertia=jd.rod(1.0, 1.0, "y")),
        jd.Body("b", "a", jd.Revolute("h2", p2, "z", position=(0, -1, 0)), mass=1.0,
                com=(0, -0.5, 0), inertia=jd.rod(1.0, 1.0, "y")),
    ]
    spring = jd.SpringDamper("spring", "world", (1.0, -1.0, 0.0), "b", (0.0, -1.0, 0.0),
                             rest_length=0.5, law=k3 * e**3 + 20 * e + d * jd.elongation_d)
    s = jd.System([p1, p2], bodies, [spring], parameters={"k3": 40.0, "d": 0.0})

    def V(y):
        r = np.array([np.sin(y[0]) + 1.0 * np.sin(y[0] + y[1]),
                      -np.cos(y[0]) - 1.0 * np.cos(y[0] + y[1])])
        L = np.linalg.norm(r - np.array([1.0, -1.0]))
        x = L - 0.5
        return 40.0 * x**4 / 4 + 20 * x**2 / 2, L

    h = 1e-6
    for _ in range(4):
        y = rng.uniform(-1, 1, 2)
        grad = np.array([(V(y + h * e_)[0] - V(y - h * e_)[0]) / (2 * h) for e_ in np.eye(2)])
        np.testing.assert_allclose(s.evaluate(y, [0, 0])["q"], -grad, rtol=1e-7, atol=1e-7)
        yd = rng.uniform(-1, 1, 2)
        dL = np.array([(V(y + h * e_)[1] - V(y - h * e_)[1]) / (2 * h) for e_ in np.eye(2)])
        q_damped = s.evaluate(y, yd, parameters={"d": 3.0})["q"]
        q_plain = s.evaluate(y, yd)["q"]
        np.testing.assert_allclose(q_damped - q_plain, -3.0 * (dL @ yd) * dL, rtol=1e-6, atol=1e-8)


def test_rotational_spring_on_relative_joint_acts_on_its_coordinate_only():
    """A torque pair on joint 2 of a double pendulum is the generalized force (0, -k φ2 - d φ̇2)."""
    s0 = double_pendulum()
    phi1, phi2 = s0.coordinates
    kk, dd = jd.symbols("kk dd")
    s = jd.System(s0.coordinates, s0.bodies,
                  [*s0.forces, jd.RotationalSpringDamper("spring2", phi2, kk, dd, rest_angle=0.1)],
                  parameters={**s0.parameter_values, "kk": 7.0, "dd": 0.3})
    y, yd = [0.4, -0.5], [1.0, 2.0]
    dq = s.evaluate(y, yd)["q"] - s0.evaluate(y, yd)["q"]
    np.testing.assert_allclose(dq, [0.0, -7.0 * (-0.5 - 0.1) - 0.3 * 2.0], atol=1e-13)


def test_point_force_and_torque_by_virtual_work(rng):
    """q = J_Pᵀ F + J_Rᵀ T: the generalized force of a point force (given in a body frame) and
    a torque, with J_P from finite differences of the point's position."""
    s0 = spatial_chain(3)
    Fx, Tz = jd.symbols("Fx Tz")
    point = (0.1, -0.2, 0.3)
    forces = [jd.Force("push", "body2", (Fx, 0.5 * Fx, 0), point=point, frame="body1"),
              jd.Torque("twist", "body1", (0, 0, Tz), frame="world")]
    s = jd.System(s0.coordinates, s0.bodies, forces, inputs=[Fx, Tz],
                  parameters=s0.parameter_values)
    kin, fn = compile_kinematics(s)
    f = s.f
    y = rng.uniform(-1, 1, f)
    out = fn(y, np.zeros(f), 0.0)
    S1, S2 = out["body1.S"], out["body2.S"]
    F_world = S1 @ np.array([2.0, 1.0, 0.0])
    h = 1e-6

    def point_pos(yy):
        o = fn(yy, np.zeros(f), 0.0)
        c = np.array([s.parameter_values[f"c{a}2"] for a in "xyz"])
        return o["body2.r"].ravel() + o["body2.S"] @ (np.array(point) - c)

    J_P = np.column_stack([(point_pos(y + h * e) - point_pos(y - h * e)) / (2 * h)
                           for e in np.eye(f)])
    # J_R of body1 in its frame; the world torque expressed there
    J_R1 = out["body1.J_R"]
    q_ref = J_P.T @ F_world + J_R1.T @ (S1.T @ np.array([0, 0, 3.0]))
    q = s.evaluate(y, np.zeros(f), inputs={"Fx": 2.0, "Tz": 3.0})["q"]
    np.testing.assert_allclose(q, q_ref, rtol=1e-7, atol=1e-8)
    assert S2.shape == (3, 3)


@pytest.mark.parametrize("make", [double_pendulum, heavy_top, lambda: spatial_chain(4),
                                  lambda: n_link_pendulum_on_cart(3)],
                         ids=["double-pendulum", "heavy-top", "spatial-chain-4", "cart-3"])
def test_mass_matrix_is_hessian_of_kinetic_energy(make, rng):
    """T(ẏ) = Σ ½ m v·v + ½ ω·Iω with v, ω from finite differences of r(y), S(y) only; the
    polarization of this quadratic form gives M entry by entry."""
    s = make()
    kin, fn = compile_kinematics(s)
    f = s.f
    values = {se.Symbol(k): v for k, v in s.parameter_values.items()}
    masses = [float(b.mass.subs(values)) for b in s.bodies]
    inertias = [np.array([[float(x.subs(values)) for x in row] for row in b.inertia])
                for b in s.bodies]
    y = rng.uniform(-1, 1, f)

    def T(yd):
        total = 0.0
        for b, m, I in zip(kin.bodies, masses, inertias, strict=True):
            v, w = fd_velocity(fn, y, yd, 0.0, b.name)
            total += 0.5 * m * v @ v + 0.5 * w @ I @ w
        return total

    E = np.eye(f)
    H = np.array([[T(E[i] + E[j]) - T(E[i]) - T(E[j]) if i != j else 2 * T(E[i])
                   for j in range(f)] for i in range(f)])
    M = s.evaluate(y, np.zeros(f), inputs=[0.0] * len(s.inputs) or None)["M"]
    np.testing.assert_allclose(M, H, rtol=1e-6, atol=1e-7 * np.abs(M).max())
    np.testing.assert_array_equal(M, M.T)


@pytest.mark.parametrize("make", [heavy_top, lambda: spatial_chain(6),
                                  lambda: n_link_pendulum_on_cart(4)],
                         ids=["heavy-top", "spatial-chain-6", "cart-4"])
def test_gyroscopic_forces_do_no_work_and_energy_balance(make, rng):
    """Scleronomic models: ẏᵀk = ½ẏᵀṀẏ (Ṁ by central differences along ẏ), hence
    dT/dt = ẏᵀMÿ + ½ẏᵀṀẏ equals the power ẏᵀq of the applied forces."""
    s = make()
    f = s.f
    u = {n: 0.7 for n in s.input_names} or None
    for _ in range(3):
        y, yd = rng.uniform(-1, 1, f), rng.uniform(-2, 2, f)
        out = s.evaluate(y, yd, inputs=u)
        h = 1e-6
        Md = (s.evaluate(y + h * yd, yd, inputs=u)["M"]
              - s.evaluate(y - h * yd, yd, inputs=u)["M"]) / (2 * h)
        lhs, rhs = yd @ out["k"], 0.5 * yd @ Md @ yd
        assert abs(lhs - rhs) <= 1e-6 * max(1.0, abs(rhs))
        ydd = np.linalg.solve(out["M"], out["q"] - out["k"])
        Tdot = yd @ out["M"] @ ydd + 0.5 * yd @ Md @ yd
        assert abs(Tdot - yd @ out["q"]) <= 1e-6 * max(1.0, abs(yd @ out["q"]))
