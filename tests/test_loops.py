"""Kinematic loops (jourdain.loops): closed forms, sympy's KanesMethod with dependent speeds,
an independent Lagrange-multiplier formulation, energy, singular positions, model files."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import symengine as se
from scipy.integrate import solve_ivp

import jourdain as jd
from jourdain.errors import ModelError
from jourdain.io.modelfile import ModelFileError, loads_model
from jourdain.loops import ClosingJoint, LoopEvaluator, evaluate
from jourdain.models.loops import four_bar, slider_crank
from tests.tolerance import EPS, cond, solve_tol

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
FB = {"a": 0.4, "b": 1.0, "c": 0.8, "d": 1.1, "m1": 1.0, "m2": 2.0, "m3": 1.5, "g": 9.81}


def _newton_tol(ev: LoopEvaluator, s: dict) -> float:
    """What the assembly leaves in z: the solve with Φ_d (rounding) plus Newton's stopping
    residual mapped by ‖Φ_d⁻¹‖."""
    rows, dep = list(ev.part.rows), list(ev.part.dependent)
    Pd = s["Phi_z"][np.ix_(rows, dep)]
    scale = 1.0 + float(np.max(np.abs(s["z"])))
    inv = float(np.linalg.norm(np.linalg.inv(Pd), 2))
    return solve_tol(Pd, scale) + 10 * inv * ev.newton_tol * scale


def _four_bar_closed_form(th1: float, th1_d: float, p: dict) -> tuple[float, float, float,
                                                                      float]:
    """Coupler and rocker absolute angles (and rates) of the four-bar for the crank angle th1,
    by intersecting the circle of radius b about the crank pin with the circle of radius c
    about the second ground pivot (the branch with the rocker above the line of the pins)."""
    a, b, c, d = p["a"], p["b"], p["c"], p["d"]
    A = np.array([a * math.cos(th1), a * math.sin(th1)])
    O2 = np.array([d, 0.0])
    e = O2 - A
    L = float(np.hypot(*e))
    x = (b * b - c * c + L * L) / (2 * L)  # along e from A
    h = math.sqrt(b * b - x * x)
    u = e / L
    P = A + x * u + h * np.array([-u[1], u[0]])
    phi2 = math.atan2(P[1] - A[1], P[0] - A[0])
    th3 = math.atan2(P[1] - O2[1], P[0] - O2[0])
    # rates: a ω1 e(th1)⊥ + b ω2 e(phi2)⊥ = c ω3 e(th3)⊥ (the loop's velocity closure)
    w2 = a * th1_d * math.sin(th1 - th3) / (b * math.sin(th3 - phi2))
    w3 = a * th1_d * math.sin(th1 - phi2) / (c * math.sin(th3 - phi2))
    return phi2, th3, w2, w3



def slider_tree():  # noqa: ANN201
    """The slider-crank's open tree: crank, rod and slider hinged in a row (the slider not yet
    guided), with gravity along −y."""
    from jourdain import System
    from jourdain.model import Body, Gravity, Revolute, rod, symbols

    phi, psi, chi = symbols("phi psi chi")
    r, l, m1, m2, m3, g = symbols("r l m1 m2 m3 g")
    bodies = [Body("crank", "world", Revolute("main", phi, "z"), mass=m1,
                   com=(r / 2, 0, 0), inertia=rod(m1, r, "x")),
              Body("rod", "crank", Revolute("pin", psi, "z", position=(r, 0, 0)), mass=m2,
                   com=(l / 2, 0, 0), inertia=rod(m2, l, "x")),
              Body("slider", "rod", Revolute("wrist", chi, "z", position=(l, 0, 0)),
                   mass=m3, inertia=(0.01, 0.01, 0.01))]
    return System([phi, psi, chi], bodies, [Gravity((0, -g, 0))],
                  parameters={"r": 0.3, "l": 1.0, "m1": 1.0, "m2": 1.5, "m3": 2.0, "g": 9.81})


@dataclass(frozen=True)
class FourBarAtRest:
    """Closed-form references at the equilibrium of examples/four_bar.toml: z, the potential
    V(θ1) along the manifold, its slope dV and curvature K by five-point differences of step
    h, and the reduced mass M from the kinetic energy along the manifold."""

    z: np.ndarray
    V: Callable[[float], float]
    h: float
    dV: float
    K: float
    M: float


def four_bar_at_rest(loop: Any, k_s: float = 20.0) -> FourBarAtRest:
    """The four-bar of examples/four_bar.toml (torsion spring k_s on the crank, rest angle 1)
    at its equilibrium near θ1 = 0.5."""
    from jourdain.loops.linearization import equilibrium

    g = FB["g"]
    a, b, c = FB["a"], FB["b"], FB["c"]

    def V(th1: float) -> float:
        phi2, th3, _, _ = _four_bar_closed_form(th1, 1.0, FB)
        return (0.5 * k_s * (th1 - 1.0) ** 2 + FB["m1"] * g * a / 2 * math.sin(th1)
                + FB["m2"] * g * (a * math.sin(th1) + b / 2 * math.sin(phi2))
                + FB["m3"] * g * c / 2 * math.sin(th3))

    z = equilibrium(loop, [0.5, 0.8, 1.9])
    th = float(z[0])
    hh = 1e-3
    dV = (V(th - 2 * hh) - 8 * V(th - hh) + 8 * V(th + hh) - V(th + 2 * hh)) / (12 * hh)
    K = (-V(th - 2 * hh) + 16 * V(th - hh) - 30 * V(th) + 16 * V(th + hh)
         - V(th + 2 * hh)) / (12 * hh * hh)
    phi2, th3, w2, w3 = _four_bar_closed_form(th, 1.0, FB)
    vc = a * np.array([-math.sin(th), math.cos(th)]) + b / 2 * w2 * np.array(
        [-math.sin(phi2), math.cos(phi2)])
    M = (FB["m1"] * a * a / 3 + FB["m2"] * vc @ vc + FB["m2"] * b * b / 12 * w2 ** 2
         + FB["m3"] * c * c / 3 * w3 ** 2)
    return FourBarAtRest(np.asarray(z), V, hh, dV, K, M)

def test_four_bar_kinematics_closed_form() -> None:
    loop = four_bar()
    ev = LoopEvaluator(loop, [0.5, 0.8, 1.9])
    z = np.array([0.5, 0.8, 1.9])
    # a full turn of the crank in steps of 0.1 rad, each assembly started from the last (the
    # continuation stays on one assembly branch)
    for th1 in 0.5 + 0.1 * np.arange(64):
        for th1_d in (1.0, -2.5):
            z[0] = th1
            asm = ev.assemble(z, [th1_d, 0, 0])
            s = ev.state(asm.z[[0]], asm.zd[[0]], 0.0)
            phi2, th3, w2, w3 = _four_bar_closed_form(th1, th1_d, FB)
            tol = _newton_tol(ev, s)
            assert abs(math.remainder(s["z"][0] + s["z"][1] - phi2, 2 * math.pi)) <= tol
            assert abs(math.remainder(s["z"][2] - th3, 2 * math.pi)) <= tol
            vtol = tol * (1 + abs(th1_d)) * cond(s["Phi_z"][:, 1:])
            assert abs(s["zd"][0] + s["zd"][1] - w2) <= vtol
            assert abs(s["zd"][2] - w3) <= vtol
            assert np.max(np.abs(s["Phi"])) <= 1e-13 * 2 * (1 + np.max(np.abs(s["z"])))
            z = s["z"].copy()


def test_slider_crank_kinematics_closed_form() -> None:
    loop = slider_crank(("phi",))
    p = {"r": 0.3, "l": 1.0}
    ev = LoopEvaluator(loop, [0.5, -0.6, 1.2])
    z = np.array([0.5, -0.6, 1.2])
    for phi in 0.5 + 0.1 * np.arange(64):
        phid = 2.0
        z[0] = phi
        asm = ev.assemble(z, [phid, 0, 0])
        s = ev.state(asm.z[[0]], asm.zd[[0]], 0.0)
        r, l = p["r"], p["l"]
        root = math.sqrt(l * l - (r * math.sin(phi)) ** 2)
        x = r * math.cos(phi) + root
        beta = -math.asin(r * math.sin(phi) / l)  # the rod's absolute angle
        xd = -r * phid * math.sin(phi) - r * r * phid * math.sin(phi) * math.cos(phi) / root
        betad = -r * phid * math.cos(phi) / (l * math.cos(beta))
        tol = _newton_tol(ev, s)
        assert abs(s["z"][2] - x) <= tol
        assert abs(math.remainder(s["z"][0] + s["z"][1] - beta, 2 * math.pi)) <= tol
        vtol = tol * (1 + phid) * cond(s["Phi_z"][:, 1:])
        assert abs(s["zd"][2] - xd) <= vtol
        assert abs(s["zd"][0] + s["zd"][1] - betad) <= vtol
        z = s["z"].copy()


def _kane_four_bar(full: bool = False):
    """sympy.physics.mechanics' four-bar with dependent speeds: its mass matrix and forcing in
    the independent speed (``full``: of all coordinates and speeds, for integration), lambdified
    in (q1..3, u1..3, a, b, c, d, m1, m2, m3, g)."""
    sm = pytest.importorskip("sympy")
    me = pytest.importorskip("sympy.physics.mechanics")
    q1, q2, q3 = me.dynamicsymbols("q1:4")
    u1, u2, u3 = me.dynamicsymbols("u1:4")
    a, b, c, d, m1, m2, m3, g = sm.symbols("a b c d m1 m2 m3 g")
    N = me.ReferenceFrame("N")
    A = N.orientnew("A", "Axis", (q1, N.z))
    B = A.orientnew("B", "Axis", (q2, A.z))
    C = N.orientnew("C", "Axis", (q3, N.z))
    A.set_ang_vel(N, u1 * N.z)
    B.set_ang_vel(A, u2 * A.z)
    C.set_ang_vel(N, u3 * N.z)
    O = me.Point("O")
    O.set_vel(N, 0)
    Pa = O.locatenew("Pa", a * A.x)
    Pa.v2pt_theory(O, N, A)
    Ca = O.locatenew("Ca", a / 2 * A.x)
    Ca.v2pt_theory(O, N, A)
    Cb = Pa.locatenew("Cb", b / 2 * B.x)
    Cb.v2pt_theory(Pa, N, B)
    Pb = Pa.locatenew("Pb", b * B.x)
    Pb.v2pt_theory(Pa, N, B)
    O2 = O.locatenew("O2", d * N.x)
    O2.set_vel(N, 0)
    Cc = O2.locatenew("Cc", c / 2 * C.x)
    Cc.v2pt_theory(O2, N, C)
    Pc = O2.locatenew("Pc", c * C.x)
    Pc.v2pt_theory(O2, N, C)
    gap = Pb.pos_from(O) - Pc.pos_from(O)
    dv = Pb.vel(N) - Pc.vel(N)
    bodies = [me.RigidBody("crank", Ca, A, m1, (me.inertia(A, 0, 0, m1 * a**2 / 12), Ca)),
              me.RigidBody("coupler", Cb, B, m2, (me.inertia(B, 0, 0, m2 * b**2 / 12), Cb)),
              me.RigidBody("rocker", Cc, C, m3, (me.inertia(C, 0, 0, m3 * c**2 / 12), Cc))]
    loads = [(Ca, -m1 * g * N.y), (Cb, -m2 * g * N.y), (Cc, -m3 * g * N.y)]
    kane = me.KanesMethod(N, q_ind=[q1], u_ind=[u1], q_dependent=[q2, q3],
                          u_dependent=[u2, u3],
                          kd_eqs=[q1.diff() - u1, q2.diff() - u2, q3.diff() - u3],
                          configuration_constraints=[gap.dot(N.x), gap.dot(N.y)],
                          velocity_constraints=[dv.dot(N.x), dv.dot(N.y)])
    kane.kanes_equations(bodies, loads)
    syms = [q1, q2, q3, u1, u2, u3, a, b, c, d, m1, m2, m3, g]
    if full:
        return (sm.lambdify(syms, kane.mass_matrix_full, "numpy"),
                sm.lambdify(syms, kane.forcing_full, "numpy"))
    return (sm.lambdify(syms, kane.mass_matrix, "numpy"),
            sm.lambdify(syms, kane.forcing, "numpy"))


def test_four_bar_M_and_forcing_equal_kanes_method_with_dependent_speeds() -> None:
    """sympy's KanesMethod (u2, u3 dependent through velocity constraints) gives the dynamic
    rows MM_d·u̇ = F_d and the constraint rows MM_c·u̇ = F_c; in the independent speed u1,
    M = MM_d[:, 0] + MM_d[:, 1:]·A and q − k = F_d − MM_d[:, 1:]·MM_c[:, 1:]⁻¹·F_c with
    A = −MM_c[:, 1:]⁻¹·MM_c[:, 0]."""
    MMf, Ff = _kane_four_bar()
    loop = four_bar()
    pars = [FB[k] for k in ("a", "b", "c", "d", "m1", "m2", "m3", "g")]
    for z0, zd0 in (([0.5, 0.8, 1.9], [1.0, 0, 0]), ([2.0, -1.0, 1.9], [-3.0, 0, 0]),
                    ([-0.8, 1.2, 1.5], [0.4, 0, 0])):
        s = evaluate(loop, z0, zd0)
        MM = np.asarray(MMf(*s["z"], *s["zd"], *pars), dtype=float)
        F = np.asarray(Ff(*s["z"], *s["zd"], *pars), dtype=float).reshape(-1)
        Mc = MM[1:, 1:]
        A = -np.linalg.solve(Mc, MM[1:, :1])
        M_ref = MM[:1, :1] + MM[:1, 1:] @ A
        f_ref = F[:1] - MM[:1, 1:] @ np.linalg.solve(Mc, F[1:])
        # both sides solve with a 2×2 constraint matrix: one solve_tol each
        Pd = s["Phi_z"][:, 1:]
        Jz = np.abs(s["J_z"])
        m_scale = float(np.max(Jz.T @ np.abs(s["M_tree"]) @ Jz))
        f_scale = float(np.max(Jz.T @ (np.abs(s["k_tree"]) + np.abs(s["q_tree"])
                                       + np.abs(s["M_tree"]) @ np.abs(s["gamma"]))))
        m_tol = solve_tol(Pd, m_scale) + solve_tol(Mc, m_scale)
        f_tol = solve_tol(Pd, f_scale) + solve_tol(Mc, f_scale)
        assert np.max(np.abs(s["M"] - M_ref)) <= m_tol
        assert np.max(np.abs((s["q"] - s["k"]) - f_ref)) <= f_tol
        # the closing joint's constraint forces do no work: Φ_z·J_z = 0
        assert s["orthogonality"] <= 10 * 3 * EPS * cond(Pd) * float(np.max(np.abs(
            s["Phi_z"]))) * float(np.max(np.abs(s["J_z"])))


def _lagrange_four_bar(t_end: float, alpha0: np.ndarray, alphad0: np.ndarray,
                       t_eval: np.ndarray) -> np.ndarray:
    """The four-bar in the absolute angles α1, α2, α3 of crank, coupler and rocker with the
    loop closure a·e(α1) + b·e(α2) − c·e(α3) − (d, 0) = 0 and Lagrange multipliers (index-1
    form [M −Gᵀ; G 0]·[α̈; λ] = [q − k; −ġα̇]), written here from the rods' centres."""
    a, b, c = FB["a"], FB["b"], FB["c"]  # d enters through the consistent initial state
    m = np.array([FB["m1"], FB["m2"], FB["m3"]])
    g = FB["g"]
    Iz = m * np.array([a, b, c]) ** 2 / 12

    def e(x: float) -> np.ndarray:
        return np.array([math.cos(x), math.sin(x)])

    def ep(x: float) -> np.ndarray:
        return np.array([-math.sin(x), math.cos(x)])

    def rhs(_t: float, x: np.ndarray) -> np.ndarray:
        al, ad = x[:3], x[3:]
        # centres: J (2×3) and bias (acceleration at α̈ = 0)
        J1 = np.zeros((2, 3))
        J1[:, 0] = a / 2 * ep(al[0])
        J2 = np.zeros((2, 3))
        J2[:, 0] = a * ep(al[0])
        J2[:, 1] = b / 2 * ep(al[1])
        J3 = np.zeros((2, 3))
        J3[:, 2] = c / 2 * ep(al[2])
        b1 = -a / 2 * e(al[0]) * ad[0] ** 2
        b2 = -a * e(al[0]) * ad[0] ** 2 - b / 2 * e(al[1]) * ad[1] ** 2
        b3 = -c / 2 * e(al[2]) * ad[2] ** 2
        M = np.diag(Iz).astype(float)
        k = np.zeros(3)
        q = np.zeros(3)
        for mi, J, bi in ((m[0], J1, b1), (m[1], J2, b2), (m[2], J3, b3)):
            M += mi * J.T @ J
            k += mi * J.T @ bi
            q += J.T @ np.array([0.0, -mi * g])
        G = np.column_stack([a * ep(al[0]), b * ep(al[1]), -c * ep(al[2])])
        gam = -a * e(al[0]) * ad[0] ** 2 - b * e(al[1]) * ad[1] ** 2 + c * e(al[2]) * ad[2] ** 2
        K = np.block([[M, -G.T], [G, np.zeros((2, 2))]])
        sol = np.linalg.solve(K, np.concatenate([q - k, -gam]))
        return np.concatenate([ad, sol[:3]])

    r = solve_ivp(rhs, (0.0, t_end), np.concatenate([alpha0, alphad0]), method="DOP853",
                  rtol=1e-12, atol=1e-13, t_eval=t_eval)
    return r.y[:3].T


def test_four_bar_trajectory_equals_lagrange_multiplier_formulation() -> None:
    loop = four_bar()
    t_end = 2.0
    res = loop.simulate((0.0, t_end), [0.5, 0.8, 1.9], [2.0, 0, 0], samples=41,
                        rtol=1e-12, atol=1e-12)
    assert res.status == "finished"
    z, zd = res.y[0], res.yd[0]
    alpha0 = np.array([z[0], z[0] + z[1], z[2]])
    alphad0 = np.array([zd[0], zd[0] + zd[1], zd[2]])
    ref = _lagrange_four_bar(t_end, alpha0, alphad0, res.t)
    ours = np.column_stack([res.y[:, 0], res.y[:, 0] + res.y[:, 1], res.y[:, 2]])
    assert np.max(np.abs(ours - ref)) <= 1e-8
    # on the manifold along the motion
    assert res.closure_residual[0] <= 1e-10 and res.closure_residual[1] <= 1e-10


def test_conservative_four_bar_energy_over_10_s() -> None:
    res = four_bar().simulate((0.0, 10.0), [0.5, 0.8, 1.9], [1.0, 0, 0], samples=201,
                        rtol=1e-10, atol=1e-12)
    assert res.status == "finished"
    E = res.total_energy
    assert np.max(np.abs(E - E[0])) <= 1e-9 * max(abs(E[0]), float(np.max(res.kinetic_energy)))
    assert res.closure_residual[0] <= 1e-10 and res.closure_residual[1] <= 1e-10
    # multipliers: the tree's equations hold with the closing force Φ_zᵀλ
    assert res.multipliers.shape == (201, 2) and np.all(np.isfinite(res.multipliers))


def test_multipliers_equal_redundant_form_and_are_the_pin_force() -> None:
    """λ from the projected equations equals the redundant (index-1) form's; for the
    rows p_A − p_B it is the force of the rocker on the coupler at the pin, which Newton's
    law for the rocker about its ground pivot checks: Iₒ·θ̈3 = moment of (−λ) + gravity."""
    loop = four_bar()
    s = evaluate(loop, [1.1, 0.3, 1.9], [1.5, 0, 0])
    ev = LoopEvaluator(loop, s["z"])
    zdd, lam = ev.redundant_accelerations(s["z"], s["zd"], 0.0)
    tol = solve_tol(np.block([[s["M_tree"], s["Phi_z"].T], [s["Phi_z"], np.zeros((2, 2))]]),
                    1 + float(np.max(np.abs(lam))))
    assert np.max(np.abs(lam - s["lambda"])) <= tol
    assert np.max(np.abs(zdd - s["zdd"])) <= tol
    c, m3, g = FB["c"], FB["m3"], FB["g"]
    th3 = s["z"][2]
    r = c * np.array([math.cos(th3), math.sin(th3)])
    F = -s["lambda"]  # on the rocker
    moment = r[0] * F[1] - r[1] * F[0] - m3 * g * c / 2 * math.cos(th3)
    I_O = m3 * c * c / 3
    assert abs(I_O * s["zdd"][2] - moment) <= tol * (1 + c) * (1 + I_O)


def test_singular_position_reported_or_repartitioned() -> None:
    """With the rocker angle independent, the rocker's extreme positions (crank and coupler
    collinear) make Φ_d singular: without re-partitioning the run stops where its condition
    passes cond_limit, naming the time and state; with it, the run switches to a
    well-conditioned partition well before and goes on, on the manifold, conserving energy."""
    loop = four_bar(("theta3",))
    stop = loop.simulate((0.0, 3.0), [0.5, 0.8, 1.9], [0.0, 0.0, 1.5], samples=61,
                         rtol=1e-10, atol=1e-12, repartition=False, cond_limit=1e3)
    assert stop.status == "singular"
    singular = stop.constraints.singular
    assert singular is not None and 0 < singular.t < 3.0
    assert "singular configuration at t =" in stop.message and "theta3" in stop.message
    assert singular.suggestion and "theta3" not in singular.suggestion
    go = loop.simulate((0.0, 3.0), [0.5, 0.8, 1.9], [0.0, 0.0, 1.5], samples=61,
                       rtol=1e-10, atol=1e-12)
    assert go.status == "finished" and len(go.constraints.partitions) >= 2
    assert go.closure_residual[0] <= 1e-10 and go.closure_residual[1] <= 1e-10
    E = go.total_energy
    assert np.max(np.abs(E - E[0])) <= 1e-8 * max(abs(E[0]), float(np.max(go.kinetic_energy)))


def test_partition_pivoting_and_grubler() -> None:
    loop = four_bar(None)
    ev = LoopEvaluator(loop, [0.5, 0.8, 1.9])
    assert ev.part.f == 1 and len(ev.part.rows) == 2
    assert ev.rank([0.5, 0.15, 1.5]) == 2
    assert loop.grubler() == -2  # spatial count: the planar four-bar is overconstrained
    with pytest.raises(ModelError, match="leave 1 degrees of freedom, but 2"):
        LoopEvaluator(loop.tree.closed_by(loop.closing, ("theta1", "theta2")),
            [0.5, 0.8, 1.9])
    # theta1 + theta2 = theta3: coupler parallel to the rocker, theta1 cannot be independent
    with pytest.raises(ModelError, match="theta1 do not determine the others here"):
        LoopEvaluator(four_bar(("theta1",)), [0.5, 1.0, 1.5])


def test_model_file_four_bar_and_errors() -> None:
    from jourdain.io.modelfile import load_model

    mf = load_model(EXAMPLES / "four_bar.toml")
    assert mf.system.closing and mf.system.independent == ("theta1",)
    assert [c.name for c in mf.system.closing] == ["closure"]
    s = evaluate(mf.system, mf.simulation.y0, mf.simulation.yd0)
    phi2, th3, _, _ = _four_bar_closed_form(0.5, 1.0, FB)
    assert abs(s["z"][2] - th3) <= 1e-12
    text = (EXAMPLES / "four_bar.toml").read_text()
    bad = text.replace('body_b = "rocker"', 'body_b = "roker"')
    with pytest.raises(ModelFileError, match=r'four_bar.toml:\d+: .*unknown body "roker".*rocker'):
        loads_model(bad, "four_bar.toml")
    bad = text.replace('type = "revolute"\nbody_a', 'type = "hinge"\nbody_a')
    with pytest.raises(ModelFileError, match='unknown closing joint type "hinge"'):
        loads_model(bad, "four_bar.toml")
    bad = text.replace('independent = ["theta1"]', 'independent = ["theta9"]')
    with pytest.raises(ModelFileError, match='"theta9" is not a declared coordinate'):
        loads_model(bad, "four_bar.toml")
    mf2 = load_model(EXAMPLES / "slider_crank.toml")
    assert mf2.system.closing and mf2.system.closing[0].name == "wrist"


def test_closing_joint_api_errors() -> None:
    loop = four_bar()
    with pytest.raises(ModelError, match='unknown body "nope"'):
        loop.tree.closed_by([ClosingJoint("x", "spherical", "coupler", "nope")])
    with pytest.raises(ModelError, match="unknown type"):
        ClosingJoint("x", "weld", "coupler", "rocker")
    with pytest.raises(ModelError, match="unknown name"):
        loop.tree.closed_by([ClosingJoint(
            "x", "constraint", expressions=[se.Symbol("theta1") - se.Symbol("zeta")])])


def test_linearization_about_equilibrium_equals_closed_form_four_bar() -> None:
    """The four-bar of examples/four_bar.toml (torsion spring k on the crank, rest angle 1):
    at its equilibrium the stiffness is V''(θ1) of the potential along the manifold and the
    mass T = ½·M·θ̇1², both in closed form from the circle intersection; the eigenvalues are
    ±i·√(K/M). Finite differences on both sides: fixed relative tolerances."""
    from jourdain.io.modelfile import load_model
    from jourdain.loops.linearization import linearize_loop

    mf = load_model(EXAMPLES / "four_bar.toml")
    ref = four_bar_at_rest(mf.system)
    z, K_ref, M_ref = ref.z, ref.K, ref.M
    assert abs(ref.dV) <= 1e-9 * K_ref
    lin = linearize_loop(mf.system, z)
    assert lin.names == ("theta1",)
    assert abs(lin.M_tilde[0, 0] - M_ref) <= 1e-12 * M_ref * 10
    assert abs(lin.K[0, 0] - K_ref) <= 1e-7 * K_ref
    assert np.max(np.abs(lin.P)) <= 1e-7 * K_ref and np.max(np.abs(lin.N)) == 0.0
    w = math.sqrt(K_ref / M_ref)
    assert np.allclose(lin.eigenvalues, [-1j * w, 1j * w], rtol=1e-7, atol=1e-7 * w)


def test_cli_check_and_run_on_the_four_bar(tmp_path: Path, capsys: pytest.CaptureFixture
                                           ) -> None:
    import json

    from jourdain.cli import main

    assert main(["check", str(EXAMPLES / "four_bar.toml")]) == 0
    text = capsys.readouterr().out
    assert "closure" in text and "1 by the rank 2 of Φ_y" in text and "1 (planar)" in text
    assert main(["check", "--json", str(EXAMPLES / "slider_crank.toml")]) == 0
    s = json.loads(capsys.readouterr().out)["loops"]
    assert s["degrees_of_freedom_rank"] == 1 and s["independent"] == ["phi"]
    assert s["assembly_residual"]["Phi"] <= 1e-12
    out = tmp_path / "rep"
    assert main(["run", str(EXAMPLES / "four_bar.toml"), "--out", str(out), "--t-end",
                 "0.5"]) == 0
    info = json.loads((out / "loops.json").read_text())
    assert info["status"] == "finished" and info["max_Phi"] <= 1e-10
    assert info["max_Phi_dot"] <= 1e-10 and len(info["eigenvalues"]) == 2
    # the one report of trees and closed systems (io.report; tests/test_closed_report.py)
    for f in ("report.html", "simulation.csv", "loops.csv", "wrench-closure.csv"):
        assert (out / f).stat().st_size > 0
    # jourdain simulate integrates the closed system, not its open tree
    csv = tmp_path / "fb.csv"
    assert main(["simulate", str(EXAMPLES / "four_bar.toml"), "--t-end", "0.5", "--out",
                 str(csv)]) == 0
    capsys.readouterr()
    mf = jd.load_model(EXAMPLES / "four_bar.toml")
    ref = mf.system.simulate((0.0, 0.5), list(mf.simulation.y0), list(mf.simulation.yd0),
                             t_eval=np.linspace(0.0, 0.5, mf.simulation.samples))
    kept = jd.Results.load(csv)
    assert np.allclose(kept.y[-1], ref.y[-1], rtol=1e-12, atol=1e-12)


def test_spatial_rssr_with_a_spherical_closing_joint() -> None:
    """examples/spatial_rssr.toml: the ball joint keeps the ball centres b apart, so along the
    whole motion cos θ3 = (a² + d² + c² − b² − 2ad·cos θ1)/(2ac·sin θ1) (closed form of
    |A(θ1) − B(θ3)| = b), while the energy stays constant and the partition may change."""
    mf = loads_model((EXAMPLES / "spatial_rssr.toml").read_text(), "spatial_rssr.toml")
    loop = mf.system
    assert [r for r in loop.constraints().labels] == ["ball.Fx", "ball.Fy", "ball.Fz"]
    assert loop.grubler() == 2
    res = loop.simulate((0.0, 2.0), mf.simulation.y0, mf.simulation.yd0, samples=41,
                        rtol=1e-10, atol=1e-12)
    assert res.status == "finished"
    a, b, c, d = 0.3, 1.2, 0.6, 1.0
    th1, th3 = res.coordinate("theta1"), res.coordinate("theta3")
    cos3 = (a * a + d * d + c * c - b * b - 2 * a * d * np.cos(th1)) / (2 * a * c * np.sin(th1))
    tol = 10 * (2 * b * math.sqrt(3) * res.closure_residual[0]
                + 3 * EPS * (a + b + c + d) ** 2) / (2 * a * c * np.abs(np.sin(th1)))
    assert np.all(np.abs(np.cos(th3) - cos3) <= tol)
    assert res.closure_residual[0] <= 1e-10 and res.closure_residual[1] <= 1e-10
    E = res.total_energy
    assert np.max(np.abs(E - E[0])) <= 1e-9 * max(abs(E[0]), float(np.max(res.kinetic_energy)))


def test_general_constraint_and_prismatic_closing_joint_give_the_same_motion() -> None:
    """The four-bar closed by two constraint expressions (the loop closure in closed form)
    has the M, k, q of the revolute closing joint; the slider-crank with the slider hanging
    from the rod and a prismatic closing joint to the ground has the slider's closed-form
    position."""
    from jourdain.model import symbols

    fb = four_bar()
    th1, th2, th3, a, b, c, d = symbols("theta1 theta2 theta3 a b c d")
    closure = ClosingJoint("loop", "constraint", expressions=[
        a * se.cos(th1) + b * se.cos(th1 + th2) - d - c * se.cos(th3),
        a * se.sin(th1) + b * se.sin(th1 + th2) - c * se.sin(th3)])
    gen = fb.tree.closed_by([closure], ("theta1",))
    s1 = evaluate(fb, [1.1, 0.3, 1.9], [1.5, 0, 0])
    s2 = evaluate(gen, [1.1, 0.3, 1.9], [1.5, 0, 0])
    tol = solve_tol(s1["Phi_z"][:, 1:], 1 + float(np.max(np.abs(s1["q_tree"]))))
    for k in ("z", "zd", "M", "k", "q"):
        assert np.max(np.abs(s1[k] - s2[k])) <= tol * (1 + float(np.max(np.abs(s1[k]))))
    # λ of the closed-form rows: the same pin force (x, y components)
    assert np.max(np.abs(s1["lambda"] - s2["lambda"])) <= tol * 10 * (
        1 + float(np.max(np.abs(s1["lambda"]))))

    tree = slider_tree()
    guide = ClosingJoint("guide", "prismatic", "world", "slider", axis="x")
    loop = tree.closed_by([guide], ("phi",))
    assert [row for row in loop.constraints().labels] == ["guide.N2", "guide.Mz"]
    res = loop.simulate((0.0, 1.0), [0.5, -0.6, 0.1], [2.0, 0, 0], samples=11,
                        rtol=1e-10, atol=1e-12)
    ph = res.coordinate("phi")
    x = 0.3 * np.cos(ph) + np.sqrt(1.0 - (0.3 * np.sin(ph)) ** 2)
    x_ours = 0.3 * np.cos(ph) + np.cos(ph + res.coordinate("psi"))
    assert np.max(np.abs(x_ours - x)) <= 10 * (res.closure_residual[0] + 4 * EPS) * 10
    # the slider does not turn: phi + psi + chi = 0
    assert np.max(np.abs(ph + res.coordinate("psi") + res.coordinate("chi"))) <= 10 * (
        res.closure_residual[0] + 4 * EPS) * 10
    E = res.total_energy
    assert np.max(np.abs(E - E[0])) <= 1e-9 * max(abs(E[0]), float(np.max(res.kinetic_energy)))


def test_redundant_form_side_by_side() -> None:
    """The Lagrange-multiplier form in all tree coordinates (index 1, with and without
    Baumgarte's terms) follows the partitioned motion to the integration tolerance; its Φ
    drifts with the integration error, where the partitioned run stays at rounding level."""
    loop = four_bar()
    ref = loop.simulate((0.0, 2.0), [0.5, 0.8, 1.9], [2.0, 0, 0], samples=21,
                        rtol=1e-12, atol=1e-12)
    for ab in (0.0, 10.0):
        red = loop.simulate((0.0, 2.0), [0.5, 0.8, 1.9], [2.0, 0, 0], samples=21,
                            rtol=1e-12, atol=1e-12, formulation="redundant", alpha=ab,
                            beta=ab)
        assert red.status == "finished"
        assert np.max(np.abs(red.y - ref.y)) <= 1e-8
        lam_scale = 1 + float(np.max(np.abs(ref.multipliers)))
        assert np.max(np.abs(red.multipliers - ref.multipliers)) <= 1e-7 * lam_scale
        assert red.closure_residual[0] <= 1e-8
    assert ref.closure_residual[0] <= 1e-12 * 10


def test_n_four_bar_through_its_singular_flat_positions() -> None:
    """The N four-bar (N = 3) passes its flat positions, where Φ_z loses rank, in the
    augmented-Lagrangian form; the crank angle follows the exact one-degree-of-freedom motion
    of the parallelogram chain (benchmarks/n_four_bar.py runs N = 5, 10, 40 over 20 s)."""
    from benchmarks.n_four_bar import initial_state, reference
    from jourdain.models.loops import n_four_bar

    n = 3
    loop = n_four_bar(n)
    z, zd = initial_state(n)
    ev = LoopEvaluator(loop, z)
    assert ev.rank([0.0, 0.0] * n + [0.0]) < 2 * n  # flat: rank lost
    res = loop.simulate((0.0, 4.0), z, zd, samples=41, rtol=1e-10, atol=1e-12,
                        formulation="penalty")
    assert res.status == "finished"
    th0 = res.coordinate("th0")
    assert th0[-1] - th0[0] > math.pi  # it went through the horizontal positions
    assert np.max(np.abs(th0 - reference(n, res.t))) <= 1e-5
    assert res.closure_residual[0] <= 1e-6


def test_formulation_is_an_option_of_the_one_simulate() -> None:
    """``formulation`` picks the method of a closed system's run; every one returns the one
    Results with the closing rows; unknown formulations and another formulation's options are
    refused naming them, and a tree takes no formulation."""
    loop = four_bar()
    for f in ("redundant", "penalty"):
        res = loop.simulate((0.0, 0.2), [0.5, 0.8, 1.9], [1.0, 0, 0], samples=5,
                            formulation=f)
        assert isinstance(res, jd.Results) and res.status == "finished"
        assert res.constraint_labels == list(loop.constraints().labels)
        assert res.Phi.shape == res.Phi_dot.shape == res.multipliers.shape == (5, 2)
        assert res.constraints.partitions == ((0.0, ()),)
    with pytest.raises(jd.errors.EvaluationError, match="formulation must be one of"):
        loop.simulate((0.0, 0.2), [0.5, 0.8, 1.9], [1.0, 0, 0], formulation="index3")
    with pytest.raises(jd.errors.EvaluationError, match="omega=.*not of 'redundant'"):
        loop.simulate((0.0, 0.2), [0.5, 0.8, 1.9], [1.0, 0, 0], formulation="redundant",
                      omega=3.0)
    with pytest.raises(jd.errors.EvaluationError, match="beta=.*not of 'partitioned'"):
        loop.simulate((0.0, 0.2), [0.5, 0.8, 1.9], [1.0, 0, 0], beta=3.0)
    with pytest.raises(jd.errors.EvaluationError, match="no closing joints"):
        loop.tree.simulate((0.0, 0.2), [0.5, 0.8, 1.9], [1.0, 0, 0], formulation="redundant")
