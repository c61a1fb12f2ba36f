"""The differential drive (two wheels rolling without slip on a common axle, Kane's two-wheeled
cart) and a skate on an incline against their closed forms (derived in the docstrings of
:mod:`jourdain.models.wheeled`).

Differential drive, axle midpoint A, heading ψ, speeds ``v`` (A's forward speed) and
``w = ψ̇``; chassis mass mc with its centre of mass b ahead of A, yaw inertia Ic; wheels of
mass mw, axial inertia Jw, diametral Iw, radius r, at ±d. The wheel centres move at
``v ∓ w·d = r·θ̇_{L,R}`` (no slip), A has no lateral velocity. Kinetic energy
``T = ½·m·v² + ½·I·w²`` with ``m = mc + 2mw + 2Jw/r²`` (each wheel: ½·mw·(v ∓ wd)² +
½·Jw·θ̇² + ½·Iw·w², the cross terms cancel between the wheels) and
``I = Ic + mc·b² + 2mw·d² + 2Iw + 2Jw·d²/r²``; the motors' power
``τ_L·θ̇_L + τ_R·θ̇_R`` gives the generalized forces ``(τ_L + τ_R)/r`` on v and
``d·(τ_R − τ_L)/r`` on w. The chassis' centre of mass, ``v·e_x + w·b·e_y``, accelerates by
``(v̇ − b·w²)·e_x + (v·w + b·ẇ)·e_y``; the wheels' centres, at ±d·e_y, by A's acceleration
``v̇·e_x + v·w·e_y`` plus ``∓(ẇ·d·e_x + w²·d·e_y)``, which cancel in the sum. With the
constraint forces doing no work on v and w (Chaplygin's sleigh's terms in b)::

    m·v̇ = mc·b·w² + (τ_L + τ_R)/r,     I·ẇ = −mc·b·v·w + d·(τ_R − τ_L)/r.

Equal torques τ from rest: ``ẍ = 2τ/(r·m)`` along the heading, no turning; opposite torques
``τ_R = −τ_L = τ`` from rest: ``ẇ = 2·d·τ/(r·I)``, no forward acceleration. The ground's force
on each wheel along the heading follows from its spin, ``Jw·θ̈_i = τ_i − r·F_i``; across
the heading the two wheels' rows coincide (a rigid axle), so only the sum is determined: the
chassis and wheels' lateral momentum, ``F_L + F_R = (mc + 2mw)·v·w + mc·b·ẇ``. In a steady
turn (free wheels, b = 0: ``v̇ = ẇ = 0``) that is the centripetal force ``m_0·v·w``
(``m_0 = mc + 2mw``) and A runs on a circle of radius ``v/w``. Linearized about straight
running at v, ``ẇ = −mc·b·v·w/I``: the heading is stable with the centre of mass ahead of the
axle and unstable behind it.

Tolerances (tests/tolerance.py): jourdain's ż comes from solves with W = [Y; A] (L and γ)
and M; the closed forms divide by m and I only. The bound is ``Σ c·n·cond·eps·scale`` over
those matrices with the scale from the summed terms; the forces add their least-squares
solve with the rows (rank-revealing: one row is redundant). Simulations are held to the
integrator's tolerance.
"""

from __future__ import annotations

import numpy as np
import pytest

from jourdain.models.wheeled import differential_drive, skate_on_incline
from jourdain.numeric import evaluate as tree_evaluate
from tests.tolerance import EPS, cond, norm, solve_scale, solve_tol, state_space_eig_tol

N_STATES = 10


@pytest.fixture(scope="module")
def body_speeds():
    return differential_drive("body")


@pytest.fixture(scope="module")
def wheel_speeds():
    return differential_drive("wheels")


def _closed_form(p: dict, v: float, w: float) -> tuple[float, float]:
    m = p["mc"] + 2 * p["mw"] + 2 * p["Jw"] / p["r"] ** 2
    inertia = (p["Ic"] + p["mc"] * p["b"] ** 2 + 2 * p["mw"] * p["d"] ** 2 + 2 * p["Iw"]
               + 2 * p["Jw"] * p["d"] ** 2 / p["r"] ** 2)
    vd = (p["mc"] * p["b"] * w * w + (p["tauL"] + p["tauR"]) / p["r"]) / m
    wd = (-p["mc"] * p["b"] * v * w + p["d"] * (p["tauR"] - p["tauL"]) / p["r"]) / inertia
    return vd, wd


def _rates(p: dict, psi: float, v: float, w: float) -> np.ndarray:
    """ẏ = (ẋ, ẏ, ψ̇, θ̇_L, θ̇_R) of the speeds v, w."""
    return np.array([v * np.cos(psi), v * np.sin(psi), w, (v - w * p["d"]) / p["r"],
                     (v + w * p["d"]) / p["r"]])


def _rows(out: dict) -> np.ndarray:
    """The rows' matrix A (``J̄_treeᵀ·Q̄_c = Aᵀ``)."""
    return (np.asarray(out["J_bar_tree"]).T @ np.asarray(out["Q_c"])).T


def _bounds(system, out: dict, p: dict, Y: np.ndarray) -> tuple[float, float]:
    """Tolerances of ż and of the contact forces at the state ``out``: ż from solves with
    W = [Y; A] (L, γ) and M, scale ``solve_scale(M, ż, (|L|ᵀ(|J̄|ᵀ|q̄^c| + |M_tree||γ|),
    |L|ᵀ|J̄|ᵀ|q̄^e|))``; the forces from the least-squares solve ``Aᵀλ = M_tree·ÿ + k − q``
    (rank-revealing condition number: one lateral row is redundant) plus ż's error mapped by
    ``‖A⁺‖·‖M_tree‖·‖L‖``."""
    tr = tree_evaluate(system.tree, out["y"], out["yd"], 0.0, p)
    J, aL = np.abs(tr["J_bar"]), np.abs(out["L"])
    Mt = np.asarray(tr["M"], dtype=float)
    k_terms = aL.T @ (J.T @ np.abs(np.ravel(tr["q_c"])) + np.abs(Mt) @ np.abs(out["gamma"]))
    q_terms = aL.T @ (J.T @ np.abs(np.ravel(tr["q_e"])))
    A = _rows(out)
    W = np.vstack([Y, A])
    s = solve_scale(out["M"], out["zd"], (k_terms, q_terms))
    tol_zd = solve_tol(out["M"], s) + 2 * solve_tol(W, s)
    sv = np.linalg.svd(A, compute_uv=False)
    sigma_r = sv[sv > 1e-8 * sv[0]][-1]
    f_terms = norm(Mt) * norm(out["ydd"]) + norm(tr["q_c"]) + norm(tr["q_e"])
    tol_f = solve_tol(A, norm(out["lambda"]) + f_terms / sv[0], rank_revealing=True)
    tol_f += norm(Mt) * norm(out["L"]) * tol_zd / sigma_r
    return tol_zd, tol_f


def _random(rng: np.random.Generator, base: dict) -> tuple[dict, np.ndarray, float, float]:
    p = dict(base)
    p.update(b=rng.uniform(-0.2, 0.2), tauL=rng.uniform(-2, 2), tauR=rng.uniform(-2, 2))
    return p, rng.uniform(-3, 3, 5), rng.uniform(-3, 3), rng.uniform(-3, 3)


def _wheel_forces(out: dict, psi: float) -> tuple[np.ndarray, float]:
    """Each wheel's ground force along the heading, and the sum across it."""
    f = out["contact_forces"]
    e, n = np.array([np.cos(psi), np.sin(psi)]), np.array([-np.sin(psi), np.cos(psi)])
    FL = np.array([f["left.T1"], f["left.T2"]])
    FR = np.array([f["right.T1"], f["right.T2"]])
    return np.array([FL @ e, FR @ e]), float((FL + FR) @ n)


def test_body_speeds_equal_the_closed_form(body_speeds) -> None:
    """ż = (v̇, ẇ), each wheel's force along the heading and the lateral sum against the
    closed form at random states, torques and chassis offsets b."""
    s = body_speeds
    rng = np.random.default_rng(17)
    for _ in range(N_STATES):
        p, y, v, w = _random(rng, s.parameter_values)
        out = s.evaluate(y, _rates(p, y[2], v, w), parameters=p)
        assert out["speeds"] == ["v", "w"]
        assert not any(k.endswith(".N") for k in out["contact_forces"])  # planar chassis
        Y = np.zeros((2, 5))
        Y[0, :2] = np.cos(y[2]), np.sin(y[2])
        Y[1, 2] = 1.0
        tol_zd, tol_f = _bounds(s, out, p, Y)
        vd, wd = _closed_form(p, v, w)
        assert np.max(np.abs(out["zd"] - [vd, wd])) <= tol_zd, (out["zd"], [vd, wd], tol_zd)
        th_dd = np.array([vd - wd * p["d"], vd + wd * p["d"]]) / p["r"]
        longitudinal = (np.array([p["tauL"], p["tauR"]]) - p["Jw"] * th_dd) / p["r"]
        lateral = (p["mc"] + 2 * p["mw"]) * v * w + p["mc"] * p["b"] * wd
        ours_long, ours_lat = _wheel_forces(out, y[2])
        assert np.max(np.abs(ours_long - longitudinal)) <= 2 * tol_f, (ours_long, longitudinal)
        assert abs(ours_lat - lateral) <= 2 * tol_f, (ours_lat, lateral, tol_f)


def test_wheel_speeds_give_the_same_motion(wheel_speeds) -> None:
    """With the wheels' rates as speeds, ż = (θ̈_L, θ̈_R) = ((v̇ ∓ ẇ·d)/r) of the closed form."""
    s = wheel_speeds
    rng = np.random.default_rng(29)
    for _ in range(N_STATES):
        p, y, v, w = _random(rng, s.parameter_values)
        out = s.evaluate(y, _rates(p, y[2], v, w), parameters=p)
        assert out["speeds"] == ["thetaL_d", "thetaR_d"]
        Y = np.zeros((2, 5))
        Y[0, 3] = Y[1, 4] = 1.0
        tol_zd, _ = _bounds(s, out, p, Y)
        vd, wd = _closed_form(p, v, w)
        ref = np.array([vd - wd * p["d"], vd + wd * p["d"]]) / p["r"]
        assert np.max(np.abs(out["zd"] - ref)) <= tol_zd, (out["zd"], ref, tol_zd)


@pytest.mark.parametrize("psi", [0.0, 0.7, -2.0])
def test_equal_torques_drive_straight(body_speeds, psi: float) -> None:
    """From rest, equal torques τ: ẍ = 2τ/(r·(mc + 2mw + 2Jw/r²)) along the heading, ψ̈ = 0."""
    s = body_speeds
    p = dict(s.parameter_values, tauL=0.8, tauR=0.8)
    out = s.evaluate([0.3, -0.1, psi, 0.2, 1.0], np.zeros(5), parameters=p)
    m = p["mc"] + 2 * p["mw"] + 2 * p["Jw"] / p["r"] ** 2
    a = (p["tauL"] + p["tauR"]) / (p["r"] * m)
    ref = np.array([a * np.cos(psi), a * np.sin(psi), 0.0])
    tol_zd, _ = _bounds(s, out, p, np.array([[np.cos(psi), np.sin(psi), 0, 0, 0],
                                             [0, 0, 1.0, 0, 0]]))
    assert np.max(np.abs(out["ydd"][:3] - ref)) <= tol_zd, (out["ydd"], ref)


def test_opposite_torques_turn_on_the_spot(body_speeds) -> None:
    """From rest, ``τ_R = −τ_L = τ``: ψ̈ = 2·d·τ/(r·I), A does not move (b·w² = 0)."""
    s = body_speeds
    p = dict(s.parameter_values, tauL=-0.5, tauR=0.5)
    out = s.evaluate([0.0, 0.0, 0.4, 0.0, 0.0], np.zeros(5), parameters=p)
    inertia = (p["Ic"] + p["mc"] * p["b"] ** 2 + 2 * p["mw"] * p["d"] ** 2 + 2 * p["Iw"]
               + 2 * p["Jw"] * p["d"] ** 2 / p["r"] ** 2)
    ref = np.array([0.0, 0.0, 2 * p["d"] * p["tauR"] / (p["r"] * inertia)])
    tol_zd, _ = _bounds(s, out, p, np.array([[np.cos(0.4), np.sin(0.4), 0, 0, 0],
                                             [0, 0, 1.0, 0, 0]]))
    assert np.max(np.abs(out["ydd"][:3] - ref)) <= tol_zd, (out["ydd"], ref)


def test_steady_turn_centripetal_force_and_circle(body_speeds) -> None:
    """Free wheels, b = 0: v and w stay constant, the wheels' lateral forces add up to the
    centripetal ``(mc + 2mw)·v·w`` and none acts along the heading; over a run A stays on the
    circle of radius v/w about its centre (integrator tolerance) and the no-slip rows hold to
    rounding."""
    s = body_speeds
    p = dict(s.parameter_values, b=0.0)
    v, w, psi = 1.2, 0.8, 0.3
    y0 = np.array([0.5, -0.2, psi, 0.0, 0.0])
    out = s.evaluate(y0, _rates(p, psi, v, w), parameters=p)
    Y = np.array([[np.cos(psi), np.sin(psi), 0, 0, 0], [0, 0, 1.0, 0, 0]])
    tol_zd, tol_f = _bounds(s, out, p, Y)
    assert np.max(np.abs(out["zd"])) <= tol_zd
    longitudinal, lateral = _wheel_forces(out, psi)
    centripetal = (p["mc"] + 2 * p["mw"]) * v * w
    assert np.max(np.abs(longitudinal)) <= 2 * tol_f
    assert abs(lateral - centripetal) <= 2 * tol_f, (lateral, centripetal)
    res = s.simulate((0.0, 4.0), y0, _rates(p, psi, v, w), parameters=p, rtol=1e-10,
                     atol=1e-12, t_eval=np.linspace(0.0, 4.0, 41))
    assert res.status == "finished"
    R = v / w
    centre = y0[:2] + R * np.array([-np.sin(psi), np.cos(psi)])
    radius = np.hypot(res.y[:, 0] - centre[0], res.y[:, 1] - centre[1])
    assert np.max(np.abs(radius - R)) <= 1e-8 * R
    assert np.max(np.abs(res.y[:, 2] - (psi + w * res.t))) <= 1e-8
    assert np.max(np.abs(res.constraints.Phi_dot)) <= 1e3 * EPS * (1 + np.abs(res.yd).max())


def _skate_rates(psi: float, u: float, w: float) -> np.ndarray:
    return np.array([u * np.cos(psi), u * np.sin(psi), w])


def test_skate_on_incline_equals_its_closed_form() -> None:
    """``u̇ = g·sin α·cos ψ``, ``ẇ = 0`` and the blade's lateral force
    ``m·u·w + m·g·sin α·sin ψ`` at random states (skate_on_incline's docstring)."""
    s = skate_on_incline()
    p = s.parameter_values
    m, sa = p["m"], p["g"] * np.sin(p["alpha"])
    rng = np.random.default_rng(41)
    for _ in range(N_STATES):
        y = rng.uniform(-2, 2, 3)
        u, w = rng.uniform(-3, 3, 2)
        out = s.evaluate(y, _skate_rates(y[2], u, w))
        ref = np.array([sa * np.cos(y[2]), 0.0])
        Y = np.array([[np.cos(y[2]), np.sin(y[2]), 0.0], [0.0, 0.0, 1.0]])
        tol_zd, tol_f = _bounds(s, out, p, Y)
        assert np.max(np.abs(out["zd"] - ref)) <= tol_zd, (out["zd"], ref, tol_zd)
        F = m * u * w + m * sa * np.sin(y[2])
        assert abs(out["contact_forces"]["blade.T"] - F) <= tol_f, (out["contact_forces"], F)
        assert cond(Y) < 10


def test_skate_drifts_across_the_slope() -> None:
    """From rest on the blade, turning at w: x oscillates, y drifts at s/(2w) on average
    (s = g·sin α), against the closed-form trajectory (integrator tolerance)."""
    s = skate_on_incline()
    p = s.parameter_values
    sa, w = p["g"] * np.sin(p["alpha"]), 1.5
    res = s.simulate((0.0, 6.0), [0.0, 0.0, 0.0], [0.0, 0.0, w], rtol=1e-11, atol=1e-12,
                     t_eval=np.linspace(0.0, 6.0, 61))
    assert res.status == "finished"
    t = res.t
    x = sa / (4 * w * w) * (1 - np.cos(2 * w * t))
    y = sa / (2 * w) * (t - np.sin(2 * w * t) / (2 * w))
    scale = sa / (2 * w) * t[-1]
    assert np.max(np.abs(res.y[:, 0] - x)) <= 1e-8 * scale
    assert np.max(np.abs(res.y[:, 1] - y)) <= 1e-8 * scale
    assert np.max(np.abs(res.y[:, 2] - w * t)) <= 1e-8


@pytest.mark.parametrize("b", [0.1, -0.1])
def test_straight_running_linearized(wheel_speeds, b: float) -> None:
    """Straight running at speed v (wheel speeds; x, y, ψ cyclic): from the closed form,
    ``ẇ = −mc·b·v·w/I`` to first order and ``v̇ = 0``, so with ``w = r·(θ̇_R − θ̇_L)/(2d)``
    ``θ̈_L = −θ̈_R = mc·b·v/(2I)·(θ̇_R − θ̇_L)``: eigenvalues 0, 0, 0 and ``−mc·b·v/I``, the
    centre of mass ahead of the axle (b > 0) keeps the cart on its heading, behind it (b < 0)
    it turns away."""
    s = wheel_speeds
    p = dict(s.parameter_values, b=b)
    v = 1.5
    lin = s.linearize({"x_d": v, "thetaL_d": v / p["r"], "thetaR_d": v / p["r"]}).at({"b": b})
    assert lin.names == ("thetaL", "thetaR") and set(lin.cyclic) == {"x", "y", "psi"}
    inertia = (p["Ic"] + p["mc"] * b ** 2 + 2 * p["mw"] * p["d"] ** 2 + 2 * p["Iw"]
               + 2 * p["Jw"] * p["d"] ** 2 / p["r"] ** 2)
    c = p["mc"] * b * v / (2 * inertia)
    ref = np.zeros((4, 4))
    ref[0, 2] = ref[1, 3] = 1.0
    ref[2:, 2:] = [[-c, c], [c, -c]]
    # P = ∂k/∂z sums Coriolis-like terms of the size of M̃'s terms times the rates: the
    # scale of the summed terms is max(|L|ᵀ|M_tree||L|)·‖z‖ at the nominal state; A's lower
    # block −M̃⁻¹·P comes from solves with M̃ and W (L, γ)
    y0 = np.zeros(5)
    out = s.evaluate(y0, [v, 0.0, 0.0, v / p["r"], v / p["r"]], parameters=p)
    Mt = np.asarray(tree_evaluate(s.tree, out["y"], out["yd"], 0.0, p)["M"], dtype=float)
    aL = np.abs(out["L"])
    terms = float(np.max(aL.T @ np.abs(Mt) @ aL)) * norm(out["z"])
    M_t = np.atleast_2d(lin.M_tilde)
    W = np.vstack([np.eye(5)[3:], _rows(out)])
    scale = solve_scale(M_t, lin.A[2:], (lin.P, [terms]))
    tol = solve_tol(M_t, scale) + 2 * solve_tol(W, scale)
    assert np.max(np.abs(lin.A - ref)) <= tol, (lin.A, ref, tol)
    lam, tol_lam = state_space_eig_tol(lin)
    ref_lam = np.sort(np.array([-2 * c, 0.0, 0.0, 0.0]))
    assert np.all(np.abs(np.sort(lam.real) - ref_lam) <= tol_lam + tol), (lam, ref_lam)
    assert np.all(lam.imag == 0.0)
