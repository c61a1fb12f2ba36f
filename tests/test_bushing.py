"""Bushings (6-D spring–dampers between body frames), generalized forces on expressions of the
coordinates, and kinematic quantities in force laws (issue 12, items 1, 2, 6).

References: the virtual work of the bushing's wrench on its deflection coordinates, built
independently with SymPy (``q = (∂x/∂y)ᵀ·w``); the closed-form stiffness and damping of a
rigid body on mounts (``Σ Tᵀ·K·T`` with ``T = [E, −p̃]`` plus the geometric stiffness of the
preloads); equivalent spring–damper elements; the Jeffcott rotor's stability threshold
``Ω = ω(1 + d_a/d_i)``; the slip decay of a wheel under a linear creep law.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import symengine as se
import sympy as sp

import jourdain as jd
from tests.tolerance import EPS, assert_close_eval, eval_tol

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


# --- the virtual work of a bushing, against an independent SymPy formulation ----------------
def _two_body_model():
    """A body on a free joint (Cardan xyz) with an arm on a hinge; a full 6×6 bushing to the
    ground (frame: the ground) and a bushing from the body to the arm (frame: the arm) with
    preload and a nonlinear law on its torsion."""
    x, y, z, a, b, c, phi = jd.symbols("x y z a b c phi")
    rng = np.random.default_rng(7)
    A = rng.normal(size=(6, 6))
    K1 = (A @ A.T + 6 * np.eye(6)).round(3)
    C1 = (rng.normal(size=(6, 6)) * 0.3).round(3)  # not symmetric: any 6×6 is allowed
    pre1 = rng.normal(size=6).round(3)
    car = jd.Body("car", "world", jd.Free("float", [x, y, z, a, b, c]), mass=2.0,
                  inertia=jd.box(2.0, 0.6, 0.4, 0.3), com=(0.1, 0.0, 0.05))
    arm = jd.Body("arm", "car", jd.Revolute("hinge", phi, "z", position=(0.5, 0.2, 0.0)),
                  mass=0.5, inertia=jd.rod(0.5, 0.6), com=(0.3, 0.0, 0.0))
    k3, c3 = jd.symbols("k3 c3")
    mount = jd.Bushing("mount", "world", "car", point_a=(0.2, -0.1, -0.5),
                       point_b=(0.3, 0.1, -0.4), stiffness=K1.tolist(), damping=C1.tolist(),
                       preload=pre1.tolist())
    K2 = [40.0, 50.0, 60.0, 7.0, 8.0, 0.0]
    C2 = [0.4, 0.5, 0.6, 0.07, 0.08, 0.0]
    pre2 = [1.0, -2.0, 0.5, 0.3, -0.2, 0.1]
    joint = jd.Bushing("coupling", "car", "arm", point_a=(0.6, 0.2, 0.1),
                       point_b=(0.2, 0.0, 0.1), stiffness=K2, damping=C2, preload=pre2,
                       frame="arm",
                       laws={"rz": k3 * jd.deflection**3 + 3 * jd.deflection
                             + c3 * jd.deflection_d})
    sys_ = jd.System([x, y, z, a, b, c, phi], [car, arm], [mount, joint],
                     parameters={"k3": 500.0, "c3": 0.2})
    data = dict(K1=K1, C1=C1, pre1=pre1, K2=np.diag(K2), C2=np.diag(C2), pre2=np.array(pre2))
    return sys_, data


def _sympy_reference(data):
    """q = Σ (∂x/∂y)ᵀ·w for both bushings, from rotation matrices written out in SymPy (x and
    its Jacobian symbolic, ẋ = (∂x/∂y)·ẏ and w in numbers)."""
    ys = sp.symbols("x y z a b c phi")
    x, y, z, a, b, c, phi = ys

    def Rx(q):
        return sp.Matrix([[1, 0, 0], [0, sp.cos(q), -sp.sin(q)], [0, sp.sin(q), sp.cos(q)]])

    def Ry(q):
        return sp.Matrix([[sp.cos(q), 0, sp.sin(q)], [0, 1, 0], [-sp.sin(q), 0, sp.cos(q)]])

    def Rz(q):
        return sp.Matrix([[sp.cos(q), -sp.sin(q), 0], [sp.sin(q), sp.cos(q), 0], [0, 0, 1]])

    def vee_skew(R):
        return sp.Rational(1, 2) * sp.Matrix([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0],
                                              R[1, 0] - R[0, 1]])

    S1 = Rx(a) * Ry(b) * Rz(c)
    r1 = sp.Matrix([x, y, z])
    S2 = S1 * Rz(phi)
    r2 = r1 + S1 * sp.Matrix([0.5, 0.2, 0])
    # mount: world point a, car point b, frame world
    x1 = (r1 + S1 * sp.Matrix([0.3, 0.1, -0.4]) - sp.Matrix([0.2, -0.1, -0.5])).col_join(
        vee_skew(S1))
    # coupling: car point a, arm point b, frame arm
    d2 = S2.T * (r2 + S2 * sp.Matrix([0.2, 0, 0.1]) - (r1 + S1 * sp.Matrix([0.6, 0.2, 0.1])))
    x2 = d2.col_join(vee_skew(S1.T * S2))
    Y = sp.Matrix(ys)
    parts = []
    for X in (x1, x2):
        parts.append((sp.lambdify([ys], X, "numpy"), sp.lambdify([ys], X.jacobian(Y), "numpy")))

    def q_of(y, yd):
        q = np.zeros(7)
        for (fx, fj), (K, C, pre), law in zip(
                parts, ((data["K1"], data["C1"], data["pre1"]),
                        (data["K2"], data["C2"], data["pre2"])), (False, True), strict=True):
            x = np.asarray(fx(y), dtype=float).ravel()
            J = np.asarray(fj(y), dtype=float)
            xd = J @ yd
            w = pre - K @ x - C @ xd
            if law:
                w[5] = pre[5] - (500.0 * x[5] ** 3 + 3 * x[5] + 0.2 * xd[5])
            q += J.T @ w
        return q

    return q_of


def test_bushing_generalized_forces_match_virtual_work():
    """q of two bushings (full 6×6 with preload in the ground frame; diagonal with a cubic
    torsion law in the frame of the second body) against (∂x/∂y)ᵀ·w from SymPy: the wrenches
    on the two bodies do the virtual work of the deflection coordinates."""
    sys_, data = _two_body_model()
    ref = _sympy_reference(data)
    rng = np.random.default_rng(3)
    for _ in range(4):
        y = rng.normal(size=7) * 0.3
        yd = rng.normal(size=7)
        out = sys_.evaluate(y, yd)
        q_ref = np.asarray(ref(y, yd), dtype=float).ravel()
        scale = np.abs(out["J_bar"]).T @ np.abs(out["q_e"])
        assert_close_eval(out["q"], q_ref, n_terms=12 * 6, scale=float(np.max(scale)) + 1.0)


def test_bushing_reactions_close_the_newton_euler_equations():
    """The bushing's wrenches enter q̄^e and the reactions: with ÿ from M·ÿ = q − k and g from
    N̂·g = k̂ − q̂, the Newton–Euler residual M̄J̄ÿ + q̄^c − q̄^e − Q̄g vanishes (the hinge of the
    arm carries the coupling's internal load)."""
    from tests.tolerance import newton_euler_tol, ydd_of

    sys_, _ = _two_body_model()
    rng = np.random.default_rng(11)
    y, yd = rng.normal(size=7) * 0.3, rng.normal(size=7)
    out = sys_.evaluate(y, yd)
    ydd = ydd_of(out)
    res = (out["M_bar"] @ out["J_bar"] @ ydd + out["q_c"] - out["q_e"]
           - out["Q_bar"] @ out["g"])
    assert np.max(np.abs(res)) <= newton_euler_tol(out, ydd)
    assert np.max(np.abs(out["g"])) > 1.0  # the hinge is loaded


# --- a rigid body on four mounts --------------------------------------------------------------
MOUNTS = [(1.0, 0.5, -0.25), (1.0, -0.5, -0.25), (-1.5, 0.5, -0.25), (-1.5, -0.5, -0.25)]
#: share of the weight on each mount: front and rear carry it in the ratio of the lever arms
SHARE = [0.3, 0.3, 0.2, 0.2]
KT = (2.0e4, 3.0e4, 1.0e5)
KR = (400.0, 500.0, 300.0)
CT = (300.0, 350.0, 900.0)
CR = (4.0, 5.0, 3.0)


def _vehicle(rotational: bool = True, gravity: bool = True):
    q = jd.symbols("x y z roll pitch yaw")
    m, g = 1000.0, 10.0
    body = jd.Body("body", "world", jd.Free("float", q), mass=m,
                   inertia=[[300.0, 0, 0], [0, 1100.0, 0], [0, 0, 1200.0]])
    forces = [jd.Gravity((0, 0, -g))] if gravity else []
    kr = KR if rotational else (0, 0, 0)
    cr = CR if rotational else (0, 0, 0)
    for i, p in enumerate(MOUNTS):
        forces.append(jd.Bushing(f"mount{i + 1}", "world", "body", point_a=p, point_b=p,
                                 stiffness=[*KT, *kr], damping=[*CT, *cr],
                                 preload=[0, 0, m * g * SHARE[i] if gravity else 0, 0, 0, 0]))
    return jd.System(q, [body], forces), m, g


def _skew(p):
    return np.array([[0, -p[2], p[1]], [p[2], 0, -p[0]], [-p[1], p[0], 0]])


def _mounts_closed_form(mounts, kt, kr, ct, cr, lifts):
    """K (with the preloads' geometric stiffness) and D of a body on mounts at the points
    ``mounts`` (body frame = ground frame at rest, Cardan xyz angles), each with diagonal
    translational/rotational stiffness and damping and the upward preload ``lifts[i]``."""
    E = np.eye(3)
    K = np.zeros((6, 6))
    D = np.zeros((6, 6))
    gens = [_skew(e) for e in E]  # ∂R/∂θ_i at θ = 0, in the order of the Cardan sequence
    for p, lift in zip(mounts, lifts, strict=True):
        T = np.hstack([E, -_skew(p)])
        K += T.T @ np.diag(kt) @ T
        D += T.T @ np.diag(ct) @ T
        f = np.array([0, 0, lift])
        for i in range(3):
            for j in range(i, 3):
                K[3 + i, 3 + j] -= f @ (gens[i] @ gens[j] @ np.array(p))
                if j != i:
                    K[3 + j, 3 + i] -= f @ (gens[i] @ gens[j] @ np.array(p))
        K[3:, 3:] += np.diag(kr)
        D[3:, 3:] += np.diag(cr)
    return K, D


def test_vehicle_on_four_bushings_closed_form():
    """K and D of a body on four mounts at its equilibrium: Σ Tᵀ·K_m·T with T = [E, −p̃] (the
    deflection of a mount at p for a small displacement u and rotation θ is u + θ × p, and the
    rotation measure is θ), plus the geometric stiffness of the preloads (constant upward
    forces at points below the centre of mass: −Σ f·∂²(S p)/∂θ_i∂θ_j for Cardan xyz angles)."""
    sys_, m, g = _vehicle()
    lin = sys_.linearize({n: 0 for n in sys_.coordinate_names})
    num = lin.evaluate()
    np.testing.assert_allclose(num["h"], 0.0, atol=eval_tol(8, m * g))
    K, D = _mounts_closed_form(MOUNTS, KT, KR, CT, CR, [m * g * s for s in SHARE])
    scale = np.max(np.abs(K))
    assert_close_eval(num["K"], K, n_terms=48, scale=scale)
    assert_close_eval(num["N"], np.zeros((6, 6)), n_terms=48, scale=scale)
    assert_close_eval(num["D"], D, n_terms=48, scale=np.max(np.abs(D)))
    assert_close_eval(num["G"], np.zeros((6, 6)), n_terms=48, scale=np.max(np.abs(D)))


def test_vehicle_example_closed_form_and_modes():
    """examples/vehicle_on_bushings.toml: at rest h = 0, K and D are the closed forms above
    with the file's parameters, and the twelve eigenvalues are those of the closed-form
    M, D, K (M = diag(m, m, m, I_x, I_y, I_z) at rest)."""
    mf = jd.load_model(EXAMPLES / "vehicle_on_bushings.toml")
    p = mf.system.parameter_values
    af, ar, bh, h, m, g = p["a_f"], p["a_r"], p["b_h"], p["h"], p["m"], p["g"]
    mounts = [(af, bh, -h), (af, -bh, -h), (-ar, bh, -h), (-ar, -bh, -h)]
    lifts = [m * g / 2 * ar / (af + ar)] * 2 + [m * g / 2 * af / (af + ar)] * 2
    kt = (p["k_x"], p["k_y"], p["k_z"])
    kr = (p["k_r"],) * 3
    beta = p["beta"]
    K, D = _mounts_closed_form(mounts, kt, kr, [beta * k for k in kt], [beta * k for k in kr],
                               lifts)
    lin = mf.system.linearize({n: 0 for n in mf.system.coordinate_names})
    num = lin.evaluate()
    np.testing.assert_allclose(num["h"], 0.0, atol=eval_tol(8, m * g))
    assert_close_eval(num["K"], K, n_terms=48, scale=np.max(np.abs(K)))
    assert_close_eval(num["D"], D, n_terms=48, scale=np.max(np.abs(D)))
    M = np.diag([m, m, m, p["I_x"], p["I_y"], p["I_z"]])
    A = np.block([[np.zeros((6, 6)), np.eye(6)],
                  [-np.linalg.solve(M, K), -np.linalg.solve(M, D)]])
    ref = np.sort_complex(np.linalg.eigvals(A))
    ours = np.sort_complex(jd.modes(lin).eigenvalues)
    np.testing.assert_allclose(ours, ref, rtol=1e-9)


def test_bushing_with_diagonal_stiffness_equals_springs():
    """Without preload, a bushing with diagonal translational stiffness and damping and none in
    rotation has the linearization of three spring–dampers along its axes (anchored one rest
    length away, so they are unloaded and carry no transverse stiffness)."""
    sys_b, _, _ = _vehicle(rotational=False, gravity=False)
    q = sys_b.coordinates
    body = sys_b.bodies[0]
    springs = []
    for i, p in enumerate(MOUNTS):
        for a, e in enumerate(np.eye(3)):
            anchor = tuple(float(v) for v in np.array(p) + 2.0 * e)
            springs.append(jd.SpringDamper(f"s{i}{a}", "body", p, "world", anchor,
                                           stiffness=KT[a], damping=CT[a], rest_length=2.0))
    sys_s = jd.System(q, [body], springs)
    nb = sys_b.linearize({n: 0 for n in q}).evaluate()
    ns = sys_s.linearize({n: 0 for n in q}).evaluate()
    for key in ("K", "D", "N", "G"):
        scale = np.max(np.abs(ns["K" if key in "KN" else "D"]))
        assert_close_eval(nb[key], ns[key], n_terms=96, scale=scale)


def test_bushing_energy_is_conserved_without_damping():
    """A linear undamped bushing with symmetric stiffness and preload has the potential
    ½xᵀKx − w₀ᵀx: T + V stays constant along a large motion (to the integrator's tolerance)."""
    q = jd.symbols("x y z roll pitch yaw")
    body = jd.Body("body", "world", jd.Free("float", q), mass=3.0,
                   inertia=[[0.3, 0, 0], [0, 0.4, 0], [0, 0, 0.5]])
    K = np.diag([300.0, 400.0, 500.0, 20.0, 30.0, 40.0])
    K[0, 4] = K[4, 0] = 15.0
    mount = jd.Bushing("mount", "world", "body", point_a=(0.1, 0.2, -0.2),
                       point_b=(0.1, 0.2, -0.2), stiffness=K.tolist(),
                       preload=[1.0, 0, 30.0, 0.5, 0, 0])
    s = jd.System(q, [body], [jd.Gravity((0, 0, -9.81)), mount])
    assert jd.energy(s.kinematics()).conservative
    res = s.simulate((0.0, 2.0), [0.02, -0.01, 0.03, 0.2, -0.15, 0.1],
                     [0.1, 0.0, -0.2, 1.0, 0.5, -0.3], rtol=1e-10, atol=1e-12)
    E = res.kinetic_energy + res.potential_energy
    assert np.ptp(E) < 1e-7 * np.max(res.kinetic_energy)


# --- rotating internal damping --------------------------------------------------------------
def _rotor_from_example():
    return jd.load_model(EXAMPLES / "rotor_internal_damping.toml").system


def test_rotor_internal_damping_bushing_gives_circulatory_matrix_and_threshold():
    """Jeffcott rotor: the shaft is a bushing between the hub (turning at Ω) and the disc, its
    damping d_i acts on the deflection rate seen from the turning hub; the air damping d_a is a
    bushing to the ground. N = ±d_i·Ω (circulatory), D = (d_a + d_i)·E, K = k·E; with
    z = x + iy, m z̈ + (d_a + d_i) ż + (k − i d_i Ω) z = 0 is at its stability boundary when
    λ = iω: ω² = k/m and (d_a + d_i)ω = d_i Ω, so Ω_crit = √(k/m)·(1 + d_a/d_i)."""
    s = _rotor_from_example()
    p = s.parameter_values
    m, k, da, di = p["m"], p["k"], p["d_a"], p["d_i"]
    lin = s.linearize({"x": 0, "y": 0})
    for Om in (0.0, 7.0, 30.0):
        num = lin.evaluate(parameters={"Omega": Om})
        np.testing.assert_allclose(num["N"], [[0, di * Om], [-di * Om, 0]],
                                   atol=eval_tol(8, k + di * Om))
        np.testing.assert_allclose(num["D"], np.diag([da + di] * 2), atol=eval_tol(8, da + di))
        np.testing.assert_allclose(num["K"], np.diag([k] * 2), atol=eval_tol(8, k + di * Om))
        np.testing.assert_allclose(num["G"], 0.0, atol=eval_tol(8, da + di))
    Om_crit = np.sqrt(k / m) * (1 + da / di)
    assert jd.stability(lin, parameters={"Omega": 0.95 * Om_crit}).verdict == (
        "asymptotically stable")
    st = jd.stability(lin, parameters={"Omega": 1.05 * Om_crit})
    assert st.verdict == "unstable" and "flutter" in st.reason
    found = jd.stability_boundary(lin, "Omega", 0.0, 3 * Om_crit)
    assert abs(found - Om_crit) < 1e-9 * Om_crit


# --- generalized forces on expressions ------------------------------------------------------
def test_rotational_spring_damper_on_a_relative_angle():
    """A torsion spring–damper on the relative angle e = φ2 − φ1 of two links hinged at the
    ground, in absolute angles: by virtual work Q·δe = Q·(δφ2 − δφ1) with
    Q = −k(e − e0) − d·ė, so q = (−Q, Q); K and D of the linearization are k and d times
    [[1, −1], [−1, 1]]; without damping its potential is ½k(e − e0)² (up to a constant)."""
    p1, p2 = jd.symbols("phi1 phi2")
    b1 = jd.Body("l1", "world", jd.Revolute("h1", p1), mass=1.0, inertia=jd.rod(1.0, 1.0),
                 com=(0.5, 0, 0))
    b2 = jd.Body("l2", "world", jd.General("h2", [jd.Rot("z", p2)], coordinates=[p2],
                                           position=(0, 0, 0.1)),
                 mass=1.0, inertia=jd.rod(1.0, 1.0), com=(0.5, 0, 0))
    k, d, e0 = 3.0, 0.4, 0.2
    s = jd.System([p1, p2], [b1, b2],
                  [jd.RotationalSpringDamper("torsion", p2 - p1, k, d, e0)])
    y, yd = np.array([0.3, 1.1]), np.array([-0.7, 0.4])
    e, ed = y[1] - y[0], yd[1] - yd[0]
    Q = -k * (e - e0) - d * ed
    out = s.evaluate(y, yd)
    np.testing.assert_allclose(out["q"], [-Q, Q], rtol=10 * EPS * 8)
    lin = s.linearize({"phi1": 0.0, "phi2": e0}).evaluate()
    np.testing.assert_allclose(lin["K"], [[k, -k], [-k, k]], rtol=1e-14)
    np.testing.assert_allclose(lin["D"], [[d, -d], [-d, d]], rtol=1e-14)
    en = jd.energy(s.kinematics())
    assert en.nonconservative == ("torsion",)  # damped
    s0 = jd.System([p1, p2], [b1, b2], [jd.RotationalSpringDamper("torsion", p2 - p1, k, 0, e0)])
    en0 = jd.energy(s0.kinematics())
    assert en0.conservative
    rest = se.expand(en0.V - k / 2 * (p2 - p1 - e0) ** 2)
    assert not rest.free_symbols and abs(float(rest) + k * e0**2 / 2) < 1e-12


def test_generalized_force_on_a_distance_equals_a_spring_damper():
    """A GeneralizedForce on the distance of two points (a kinematic quantity) with the value
    −c·(deflection − L0) − d·deflection_d is the spring–damper between them: same q."""
    x, phi = jd.symbols("x phi")
    cart = jd.Body("cart", "world", jd.Prismatic("rail", x, "x"), mass=2.0,
                   inertia=jd.point_mass())
    pend = jd.Body("pend", "cart", jd.Revolute("pivot", phi), mass=0.5,
                   inertia=jd.rod(0.5, 0.8, "y"), com=(0, -0.4, 0))
    L = jd.distance("L", "world", (1.0, 0.5, 0.0), "pend", (0.0, -0.8, 0.0))
    c, d, L0 = 120.0, 1.5, 0.7
    s_q = jd.System([x, phi], [cart, pend], [jd.GeneralizedForce(
        "spring", L, -c * (jd.deflection - L0) - d * jd.deflection_d)])
    s_s = jd.System([x, phi], [cart, pend], [jd.SpringDamper(
        "spring", "world", (1.0, 0.5, 0.0), "pend", (0.0, -0.8, 0.0), c, d, L0)])
    assert [q.name for q in s_q.quantities] == ["L"]
    rng = np.random.default_rng(5)
    for _ in range(3):
        y, yd = rng.normal(size=2), rng.normal(size=2)
        a, b = s_q.evaluate(y, yd)["q"], s_s.evaluate(y, yd)["q"]
        assert_close_eval(a, b, n_terms=12, scale=float(np.max(np.abs(b))) + c)


# --- kinematic quantities -------------------------------------------------------------------
def _wheel(creep: float = 40.0):
    """A wheel of radius r on the ground: the hub translates (x), the wheel turns (phi); the
    creep force −c·v_s at the contact, v_s the velocity of the wheel's material point at the
    contact (a kinematic quantity), and its moment about the centre."""
    x, phi = jd.symbols("x phi")
    m, I, r, c = 3.0, 0.06, 0.25, creep
    hub = jd.Body("hub", "world", jd.Prismatic("road", x, "x", position=(0, r, 0)), mass=0,
                  inertia=jd.point_mass())
    wheel = jd.Body("wheel", "hub", jd.Revolute("axle", phi, "z"), mass=m,
                    inertia=[[I / 2, 0, 0], [0, I / 2, 0], [0, 0, I]])
    vs = jd.velocity("v_s", "wheel", (0, -r, 0), frame="world", point_frame="hub")
    F = -c * vs[0]
    forces = [jd.Force("creep", "wheel", (F, 0, 0)),
              jd.Torque("creep_moment", "wheel", (0, 0, r * F))]
    return jd.System([x, phi], [hub, wheel], forces), (m, I, r, c)


def test_wheel_example_slip_decays_and_rolls():
    """examples/wheel_creep.toml: started sliding at 2 m/s, the slip decays as
    exp(−c(1/m + r²/I)·t) and the hub ends at the rolling speed 2/(1 + I/(m r²)) (momentum
    about the contact point is conserved)."""
    mf = jd.load_model(EXAMPLES / "wheel_creep.toml")
    s = mf.system
    p = s.parameter_values
    m, I, r, c = p["m"], p["I"], p["r"], p["c"]
    assert [q.name for q in s.quantities] == ["slip", "v"]
    res = s.simulate((0.0, 0.5), [0.0, 0.0], [2.0, 0.0], rtol=1e-10, atol=1e-12)
    vs = res.yd[:, 0] + r * res.yd[:, 1]
    np.testing.assert_allclose(vs, 2.0 * np.exp(-c * (1 / m + r * r / I) * res.t), atol=1e-7)
    np.testing.assert_allclose(res.yd[-1, 0], 2.0 / (1 + I / (m * r * r)), rtol=1e-6)


def test_wheel_creep_force_from_the_contact_point_velocity():
    """The slip velocity v_s = ẋ + r·φ̇ of the contact point decays as
    exp(−c(1/m + r²/I)·t) (m ẍ = F, I φ̈ = rF, F = −c·v_s); the linearization has
    P = c·[[1, r], [r, r²]] exactly (∂q/∂ẏ of the quantity, no numeric differentiation)."""
    s, (m, I, r, c) = _wheel()
    lin = s.linearize({"x": 0, "phi": 0}).evaluate()
    np.testing.assert_allclose(lin["P"], c * np.array([[1, r], [r, r * r]]), rtol=1e-14)
    np.testing.assert_allclose(lin["Q"], 0.0, atol=0.0)
    res = s.simulate((0.0, 0.5), [0.0, 0.0], [2.0, 0.0], rtol=1e-10, atol=1e-12)
    vs = res.yd[:, 0] + r * res.yd[:, 1]
    ref = 2.0 * np.exp(-c * (1 / m + r * r / I) * res.t)
    np.testing.assert_allclose(vs, ref, atol=1e-7)


def test_kinematic_quantities_against_closed_forms():
    """Position, velocity, angular velocity, relative quantities, distance and its rate of a
    pendulum point, and the acceleration of a point on a prescribed rotor, each used as a force
    and read back from q̄^e against the closed forms."""
    phi = jd.symbols("phi")
    l, Om = 0.8, 3.0
    pend = jd.Body("pend", "world", jd.Revolute("pivot", phi), mass=1.0,
                   inertia=jd.rod(1.0, l, "y"), com=(0, -l / 2, 0))
    rotor = jd.Body("rotor", "world", jd.General("drive", [jd.Rot("z", Om * jd.t)],
                                                 position=(2.0, 0, 0)),
                    mass=1.0, inertia=jd.disc(1.0, 0.1))
    tip = (0, -l, 0)
    qs = {
        "pos": jd.position("p", "pend", tip),
        "vel": jd.velocity("v", "pend", tip),
        "omega": jd.angular_velocity("w", "pend", frame="world"),
        "rel": jd.relative_position("d", "rotor", (0.5, 0, 0), "pend", tip, frame="rotor"),
        "relv": jd.relative_velocity("dv", "rotor", (0.5, 0, 0), "pend", tip),
        "acc": jd.point_acceleration("a", "rotor", (0.5, 0, 0)),
    }
    dist = jd.distance("L", "world", (0, 1, 0), "pend", tip)
    rate = jd.distance_rate("L_d", "world", (0, 1, 0), "pend", tip)
    forces = [jd.Force(f"f_{k}", "rotor", v) for k, v in qs.items()]
    forces.append(jd.Force("f_dist", "rotor", (dist, rate, 0)))
    s = jd.System([phi], [pend, rotor], forces)
    ph, phd, t = 0.4, -1.3, 0.7
    ne = s.evaluate([ph], [phd], t=t)
    q_e = ne["q_e"]
    p = np.array([l * np.sin(ph), -l * np.cos(ph), 0])
    v = np.array([l * np.cos(ph), l * np.sin(ph), 0]) * phd
    th = Om * t
    Sr = np.array([[np.cos(th), -np.sin(th), 0], [np.sin(th), np.cos(th), 0], [0, 0, 1]])
    pr = np.array([2.0, 0, 0]) + Sr @ [0.5, 0, 0]
    vr = Sr @ [0, 0.5 * Om, 0]
    ar = Sr @ [-0.5 * Om**2, 0, 0]
    L = np.linalg.norm(p - [0, 1, 0])
    expect = {"pos": p, "vel": v, "omega": [0, 0, phd], "rel": Sr.T @ (p - pr),
              "relv": v - vr, "acc": ar}
    rotor_rows = slice(3, 6)
    for k, e in expect.items():
        F = applied(s, f"f_{k}", [ph], [phd], t)
        np.testing.assert_allclose(F, e, atol=eval_tol(12, 10.0))
    F = applied(s, "f_dist", [ph], [phd], t)
    np.testing.assert_allclose(F, [L, (p - [0, 1, 0]) @ v / L, 0], atol=eval_tol(12, 10.0))
    assert q_e[rotor_rows].shape == (3,)


def applied(system, name, y, yd, t):
    """The inertial force of one element on the rotor, evaluated from q̄^e of that element."""
    from jourdain.stages.newton_euler import applied_forces

    fe = next(f for f in system.forces if f.name == name)
    bf = applied_forces(system.kinematics(), [fe])[1]
    subs = {se.Symbol("phi"): y[0], se.Symbol("phi_d"): yd[0], jd.t: t}
    return [float(se.sympify(c).subs(subs)) for c in bf.f]


def test_acceleration_that_depends_on_ydd_is_refused():
    phi = jd.symbols("phi")
    pend = jd.Body("pend", "world", jd.Revolute("pivot", phi), mass=1.0,
                   inertia=jd.rod(1.0, 1.0, "y"), com=(0, -0.5, 0))
    a = jd.point_acceleration("a", "pend", (0, -1, 0))
    s = jd.System([phi], [pend], [jd.Force("inertia", "pend", (-a[0], 0, 0))])
    with pytest.raises(jd.ModelError, match=r"acceleration .* depends on the accelerations of "
                                            r"\['phi'\].*implicit"):
        s.equations_of_motion()


def test_quantity_errors_name_what_and_where():
    phi = jd.symbols("phi")
    pend = jd.Body("pend", "world", jd.Revolute("pivot", phi), mass=1.0,
                   inertia=jd.rod(1.0, 1.0, "y"))
    v = jd.velocity("v", "wheel", (0, 0, 0))
    with pytest.raises(jd.ModelError, match=r'quantity "v" \(velocity\): unknown body or frame '
                                            r'"wheel"'):
        jd.System([phi], [pend], [jd.Force("f", "pend", (v[0], 0, 0))])
    v1 = jd.velocity("v", "pend", (0, 0, 0))
    v2 = jd.velocity("v", "pend", (0, 1, 0))
    with pytest.raises(jd.ModelError, match='two different quantities are named "v"'):
        jd.System([phi], [pend], [jd.Force("f", "pend", (v1[0], v2[1], 0))])
    clash = jd.distance("phi_d", "world", (0, 0, 0), "pend", (0, 1, 0))
    with pytest.raises(jd.ModelError, match='its symbol "phi_d" is already declared'):
        jd.System([phi], [pend], [jd.Force("f", "pend", (clash, 0, 0))])
    with pytest.raises(jd.ModelError, match="depends on the rates"):
        jd.System([phi], [pend], [jd.GeneralizedForce("g", v1[0], 1.0)])
    with pytest.raises(jd.ModelError, match='component "rz" has a law and also nonzero'):
        jd.Bushing("b", "world", "pend", stiffness=[1] * 6, laws={"rz": jd.deflection})
    with pytest.raises(jd.ModelError, match='unknown component "theta"'):
        jd.Bushing("b", "world", "pend", laws={"theta": jd.deflection})
    with pytest.raises(jd.ModelError, match='frame "x" must be one of its bodies'):
        jd.Bushing("b", "world", "pend", frame="x")
    with pytest.raises(jd.ModelError, match="expected 6 entries"):
        jd.Bushing("b", "world", "pend", stiffness=[1, 2, 3])


# --- model files ----------------------------------------------------------------------------
_FILE = """
[coordinates]
phi1 = "rad"
phi2 = "rad"

[parameters]
c_t = 3.0
d_t = 0.4
k = 50.0
c3 = 200.0

[bodies.l1]
parent = "world"
mass = 1.0
com = [0.5, 0, 0]
inertia = { rod = { length = 1.0, axis = "x" } }
joint = { type = "revolute", coordinate = "phi1" }

[bodies.l2]
parent = "world"
mass = 1.0
com = [0.5, 0, 0]
inertia = { rod = { length = 1.0, axis = "x" } }
joint = { type = "revolute", coordinate = "phi2", position = [0, 0, 0.1] }

[quantities.tip]
type = "velocity"
body = "l2"
point = [1, 0, 0]

[quantities.gap]
type = "distance"
body_a = "l1"
point_a = [1, 0, 0]
body_b = "l2"
point_b = [1, 0, 0]

[forces.torsion]
type = "rotational_spring_damper"
coordinate = "phi2 - phi1"
stiffness = "c_t"
damping = "d_t"

[forces.mount]
type = "bushing"
body_a = "l1"
point_a = [1, 0, 0]
body_b = "l2"
point_b = [1, 0, 0]
frame = "l2"
stiffness = ["k", "k", "k", 0, 0, 0]
laws = { rz = "c3*deflection^3 + 0.1*deflection_d" }

[forces.drag]
type = "force"
body = "l2"
point = [1, 0, 0]
vector = ["-0.3*tip_x", "-0.3*tip_y", 0]

[forces.tether]
type = "generalized"
coordinate = "gap"
value = "-k*deflection^2 - deflection_d"
"""


def test_model_file_bushing_quantities_and_expressions_equal_python():
    """The model file's bushing, quantities and generalized forces on expressions give the q of
    the same elements built in Python."""
    from jourdain.io.modelfile import loads_model

    mf = loads_model(_FILE, "m.toml")
    s_file = mf.system
    p1, p2 = jd.symbols("phi1 phi2")
    b1, b2 = s_file.bodies
    tip = jd.velocity("tip", "l2", (1, 0, 0))
    gap = jd.distance("gap", "l1", (1, 0, 0), "l2", (1, 0, 0))
    k, c3 = 50.0, 200.0
    forces = [
        jd.RotationalSpringDamper("torsion", p2 - p1, 3.0, 0.4),
        jd.Bushing("mount", "l1", "l2", (1, 0, 0), (1, 0, 0), stiffness=[k, k, k, 0, 0, 0],
                   frame="l2", laws={"rz": c3 * jd.deflection**3 + 0.1 * jd.deflection_d}),
        jd.Force("drag", "l2", (-0.3 * tip[0], -0.3 * tip[1], 0), point=(1, 0, 0)),
        jd.GeneralizedForce("tether", gap, -k * jd.deflection**2 - jd.deflection_d),
    ]
    s_py = jd.System([p1, p2], [b1, b2], forces)
    assert [q.name for q in s_file.quantities] == ["gap", "tip"]
    rng = np.random.default_rng(2)
    for _ in range(3):
        y, yd = rng.normal(size=2), rng.normal(size=2)
        a = s_file.evaluate(y, yd)["q"]
        b = s_py.evaluate(y, yd)["q"]
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("change, message", [
    ('laws = { rz = "c3*deflection^3 + 0.1*deflection_d" }',
     'laws = { theta = "c3*deflection" }'),
    ('stiffness = ["k", "k", "k", 0, 0, 0]', 'stiffness = ["k", "k", "k"]'),
    ('type = "distance"', 'type = "distanse"'),
    ('coordinate = "phi2 - phi1"', 'coordinate = "phi2_d - phi1"'),
    ('frame = "l2"', 'frame = "world"'),
    ('vector = ["-0.3*tip_x", "-0.3*tip_y", 0]', 'vector = ["-0.3*tip_w", 0, 0]'),
    ('[quantities.gap]', '[quantities.phi1]'),
], ids=["law component", "stiffness size", "quantity type", "rate in coordinate",
        "bushing frame", "unknown symbol", "name clash"])
def test_model_file_errors_name_line_and_key(change, message):
    from jourdain.io.modelfile import ModelFileError, loads_model

    text = _FILE.replace(change, message)
    assert text != _FILE
    with pytest.raises(ModelFileError) as err:
        loads_model(text, "m.toml")
    line = text[:text.index(message)].count("\n") + 1
    msg = str(err.value)
    assert msg.startswith("m.toml:"), msg
    assert err.value.line == line, (msg, line)


def test_quantities_in_space_against_sympy_mechanics():
    """A body on a spherical joint (Cardan xyz) with a viscous drag −c·v_P at a body point P, a
    drag −c₂·v_Q at P whose law uses the velocity of the material point at a place Q fixed in
    the ground (point_frame = "world"), and a spin drag torque −c_r·ω (body axes): q against the
    generalized forces Σ (∂v/∂q̇)·F + (∂ω/∂q̇)·T of sympy.physics.mechanics (v2pt_theory,
    ang_vel_in)."""
    import sympy.physics.mechanics as me

    a, b, c = jd.symbols("a b c")
    P, Q = (0.3, -0.2, 0.5), (0.1, 0.4, -0.3)
    cd, c2, cr = 0.7, 1.3, 0.2
    body = jd.Body("body", "world", jd.Spherical("ball", [a, b, c], "xyz"), mass=1.0,
                   inertia=jd.box(1.0, 0.3, 0.4, 0.5))
    vP = jd.velocity("vP", "body", P)
    vQ = jd.velocity("vQ", "body", Q, point_frame="world")
    w = jd.angular_velocity("w", "body")
    s = jd.System([a, b, c], [body], [
        jd.Force("drag", "body", tuple(-cd * v for v in vP), point=P),
        jd.Force("drag_q", "body", tuple(-c2 * v for v in vQ), point=P),
        jd.Torque("spin", "body", tuple(-cr * x for x in w), frame="body")])

    qs = me.dynamicsymbols("a b c")
    qds = [me.dynamicsymbols(f"{n}", 1) for n in "abc"]
    N = me.ReferenceFrame("N")
    B = N.orientnew("B", "Body", qs, "123")
    O = me.Point("O")
    O.set_vel(N, 0)
    Pp = O.locatenew("P", P[0] * B.x + P[1] * B.y + P[2] * B.z)
    Qp = O.locatenew("Q", Q[0] * N.x + Q[1] * N.y + Q[2] * N.z)
    v_P = Pp.v2pt_theory(O, N, B)
    omega = B.ang_vel_in(N)
    v_Q = omega.cross(Qp.pos_from(O))  # the body's material point at Q
    F = -cd * v_P - c2 * v_Q
    T = -cr * omega
    gen = [sp.simplify(0) + v_P.diff(qd, N).dot(F) + omega.diff(qd, N).dot(T) for qd in qds]
    subs_syms = sp.symbols("a b c a_d b_d c_d")
    rep = dict(zip([*qds, *qs], [*subs_syms[3:], *subs_syms[:3]], strict=True))
    ref = sp.lambdify(subs_syms, [g.subs(rep) for g in gen], "numpy")
    rng = np.random.default_rng(9)
    for _ in range(3):
        y, yd = rng.normal(size=3), rng.normal(size=3)
        out = s.evaluate(y, yd)
        q_ref = np.array(ref(*y, *yd), dtype=float)
        scale = float(np.max(np.abs(out["J_bar"]).T @ np.abs(out["q_e"])))
        assert_close_eval(out["q"], q_ref, n_terms=24, scale=scale)


def test_check_lists_bushings_and_quantities(capsys):
    """jourdain check names the bushings and the kinematic quantities with their symbols."""
    from jourdain.cli import main

    assert main(["check", str(EXAMPLES / "wheel_creep.toml")]) == 0
    out = capsys.readouterr().out
    assert ('kinematic quantities: velocity "slip" of wheel [0, -r, 0] (point in hub\'s axes), '
            "components in world (slip_x, slip_y, slip_z)") in out
    assert main(["check", str(EXAMPLES / "rotor_internal_damping.toml")]) == 0
    assert "shaft (Bushing), air (Bushing)" in capsys.readouterr().out


def test_inclined_bushing_axes_equal_the_turned_matrices():
    """Mount axes turned by a constant rotation R0 (axes_a = axes_b = R0) with diagonal
    stiffness and damping k_d, c_d are a mount in the body axes with the full matrices
    T·k_d·Tᵀ, T = diag(R0, R0): the deflection in the turned axes is Tᵀ·x (s too, being the
    axial vector of R0ᵀ·R·R0), so q agrees at any state, not only near rest."""
    q = jd.symbols("x y z roll pitch yaw")
    body = jd.Body("body", "world", jd.Free("float", q), mass=2.0,
                   inertia=jd.box(2.0, 0.5, 0.4, 0.3))
    turn = [jd.Rot("z", se.pi / 6), jd.Rot("x", -se.pi / 5)]
    c, s5 = np.cos(np.pi / 6), np.sin(np.pi / 6)
    Rz = np.array([[c, -s5, 0], [s5, c, 0], [0, 0, 1]])
    a = -np.pi / 5
    Rx = np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])
    R0 = Rz @ Rx
    T = np.kron(np.eye(2), R0)
    kd = np.array([300.0, 500.0, 900.0, 20.0, 30.0, 40.0])
    cd = kd * 0.01
    pre = [0.0, 0.0, 5.0, 0.0, 0.3, 0.0]
    p = (0.2, -0.1, -0.3)
    inclined = jd.Bushing("m", "world", "body", p, p, stiffness=kd.tolist(),
                          damping=cd.tolist(), preload=pre, axes_a=turn, axes_b=turn)
    full = jd.Bushing("m", "world", "body", p, p, stiffness=(T @ np.diag(kd) @ T.T).tolist(),
                      damping=(T @ np.diag(cd) @ T.T).tolist(), preload=(T @ pre).tolist())
    s1 = jd.System(q, [body], [inclined])
    s2 = jd.System(q, [body], [full])
    rng = np.random.default_rng(4)
    for _ in range(3):
        y, yd = rng.normal(size=6) * 0.4, rng.normal(size=6)
        q1, q2 = s1.evaluate(y, yd)["q"], s2.evaluate(y, yd)["q"]
        assert_close_eval(q1, q2, n_terms=72, scale=float(np.max(np.abs(q2))) + 1000.0)
    with pytest.raises(jd.ModelError, match=r'bushing "m" axes_a: the matrix .* is not a '
                                            "rotation matrix"):
        jd.Bushing("m", "world", "body", axes_a=[[1, 0, 0], [0, 1, 0], [0, 0, 2]])


def test_model_file_bushing_axes():
    """axes_a/axes_b in a model file: rotations about axes (as joint orientations) are the
    Python API's; a matrix that is no rotation is refused at its line."""
    from jourdain.io.modelfile import ModelFileError, loads_model

    text = _FILE.replace('frame = "l2"\n', 'frame = "l2"\naxes_a = [{ rot = "z", angle = "pi/6" }]\n'
                         'axes_b = [{ rot = "z", angle = "pi/6" }]\n')
    b = next(f for f in loads_model(text, "m.toml").system.forces if f.name == "mount")
    ref = jd.Bushing("x", "world", "l1", axes_a=[jd.Rot("z", se.pi / 6)])
    assert b.axes_a == ref.axes_a == b.axes_b
    bad = _FILE.replace('frame = "l2"\n', 'frame = "l2"\naxes_b = [[1, 0, 0], [0, 1, 0], '
                        '[0, 0, 2]]\n')
    with pytest.raises(ModelFileError, match="axes_b: the axes .* is not a rotation matrix") as e:
        loads_model(bad, "m.toml")
    assert e.value.line == bad[:bad.index("axes_b")].count("\n") + 1
