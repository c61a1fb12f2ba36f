"""The rolling disc of ``sympy.physics.mechanics`` (its own formulation, as in sympy's rolling
disc example and ``test_kane.py``), against jourdain's general path built from the disc's
geometry with the same generalized speeds.

sympy: frames Y (yaw q1 about N.z), L (lean q2 about Y.x), R (spin q3 about L.y); the contact
point C has zero velocity, the centre is ``Dmc = C + r·L.z``; the speeds are the components of
R's angular velocity in L, ``ω_R = u1·L.x + u2·L.y + u3·L.z``; KanesMethod gives
``M_s·u̇ = F_s``. Auxiliary speeds u4, u5, u6 of C along L.x, Y.z×L.x = Y.y, Y.z with the
forces f1, f2, f3 at C (on the disc) give the contact force.

jourdain: one body on ``General`` steps ``Trans(x, y, zc)``, ``Rot(z, psi)``, ``Rot(x, phi)``,
``Rot(y, theta)`` (so ``psi = q1``, ``phi = q2``, ``theta = q3``), a ``RollingDisc`` of radius r
about the body's y axis. With ``ω = ψ̇·Y.z + φ̇·L.x + θ̇·L.y`` and ``Y.z = sin φ·L.y + cos φ·L.z``
(L is Y turned by φ about x) the speeds are::

    u1 = φ̇,   u2 = θ̇ + sin φ·ψ̇,   u3 = cos φ·ψ̇

(sympy's kinematic equations ``q̇1 = u3/cos q2``, ``q̇2 = u1``, ``q̇3 = u2 − tan q2·u3``). The
contact point below the centre is ``C − r·(n − (n·a)·a)/|…| = C − r·L.z`` (a = L.y, n = N.z),
sympy's C. jourdain's contact forces are along world z (``ground.N``), x, y (``ground.T1``,
``ground.T2``): ``N = f3``, ``T1 = cos q1·f1 − sin q1·f2``, ``T2 = sin q1·f1 + cos q1·f2``.

Tolerances (tests/tolerance.py): each side solves (jourdain: W for L and γ, then M; sympy:
M_s, then the auxiliary equations' 3×3 matrix), so the differences are bounded by
``Σ c·n·cond·eps·scale`` over those matrices, the scale from the summed terms.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from sympy.physics.mechanics import (
    KanesMethod,
    Point,
    ReferenceFrame,
    RigidBody,
    cross,
    dot,
    dynamicsymbols,
    inertia,
)

import jourdain as jd
from jourdain.model import Body, General, Gravity, Rot, Trans, symbols
from jourdain.numeric import evaluate as tree_evaluate
from tests.tolerance import EPS, cond, norm, solve_scale, solve_tol

N_STATES = 12


@pytest.fixture(scope="module")
def sympy_disc() -> dict:
    """sympy's rolling disc, lambdified: M_s, F_s, the auxiliary equations' matrix (in f)
    and their rest (in u̇), and the kinematic equations."""
    q1, q2, q3, u1, u2, u3 = dynamicsymbols("q1 q2 q3 u1 u2 u3")
    u4, u5, u6, f1, f2, f3 = dynamicsymbols("u4 u5 u6 f1 f2 f3")
    r, m, g = sp.symbols("r m g")
    N = ReferenceFrame("N")
    Y = N.orientnew("Y", "Axis", [q1, N.z])
    L = Y.orientnew("L", "Axis", [q2, Y.x])
    R = L.orientnew("R", "Axis", [q3, L.y])
    w_qd = R.ang_vel_in(N)
    R.set_ang_vel(N, u1 * L.x + u2 * L.y + u3 * L.z)
    C = Point("C")
    C.set_vel(N, u4 * L.x + u5 * cross(Y.z, L.x) + u6 * Y.z)
    Dmc = C.locatenew("Dmc", r * L.z)
    Dmc.v2pt_theory(C, N, R)
    disc = RigidBody("disc", Dmc, R, m, (inertia(L, m * r**2 / 4, m * r**2 / 2, m * r**2 / 4),
                                         Dmc))
    kd = [dot(R.ang_vel_in(N) - w_qd, uv) for uv in L]
    loads = [(Dmc, -m * g * Y.z), (C, f1 * L.x + f2 * cross(Y.z, L.x) + f3 * Y.z)]
    km = KanesMethod(N, q_ind=[q1, q2, q3], u_ind=[u1, u2, u3], kd_eqs=kd,
                     u_auxiliary=[u4, u5, u6])
    km.kanes_equations([disc], loads)
    ud = sp.symbols("ud1:4")
    t = dynamicsymbols._t
    aux = km.auxiliary_eqs.subs({sp.diff(u, t): s for u, s in zip((u1, u2, u3), ud,
                                                                    strict=True)})
    forces = [f1, f2, f3]
    A_aux = aux.jacobian(forces)
    b_aux = aux.subs({f: 0 for f in forces})
    assert all(sp.diff(A_aux, f) == sp.zeros(3, 3) for f in forces)  # linear in the forces
    kdd = km.kindiffdict()
    qd = sp.Matrix([kdd[sp.diff(q, t)] for q in (q1, q2, q3)])
    args = [q1, q2, q3, u1, u2, u3, r, m, g]
    return {"M": sp.lambdify(args, km.mass_matrix), "F": sp.lambdify(args, km.forcing),
            "A_aux": sp.lambdify(args, A_aux), "b_aux": sp.lambdify([*args, *ud], b_aux),
            "qd": sp.lambdify(args, qd)}


@pytest.fixture(scope="module")
def disc() -> jd.System:
    """jourdain's disc with sympy's speeds u1, u2, u3 by definition (the mapping above)."""
    x, y, zc, psi, phi, theta = symbols("x y zc psi phi theta")
    psi_d, phi_d, theta_d = symbols("psi_d phi_d theta_d")
    m, r, g = symbols("m r g")
    body = Body("disc", "world",
                General("free", [Trans(vector=(x, y, zc)), Rot("z", psi), Rot("x", phi),
                                 Rot("y", theta)], coordinates=(x, y, zc, psi, phi, theta)),
                mass=m, inertia=(m * r**2 / 4, m * r**2 / 2, m * r**2 / 4))
    return jd.System([x, y, zc, psi, phi, theta], [body], [Gravity((0, 0, -g))],
                     parameters={"m": 1.0, "r": 0.5, "g": 9.81}, name="sympy's rolling disc",
                     contacts=[jd.RollingDisc("ground", "disc", r, "y")],
                     independent=["x", "y", "psi", "phi", "theta"],
                     speeds={"u1": phi_d,
                             "u2": theta_d + jd.sin(phi) * psi_d,
                             "u3": jd.cos(phi) * psi_d})


def _states(seed: int):
    """Random states: q (lean within ±1.2 rad), u, parameters (m, r, g), and jourdain's y, ẏ
    (ẏ from u by sympy's kinematic equations; x, y, zc and their rates are the solver's)."""
    rng = np.random.default_rng(seed)
    for _ in range(N_STATES):
        q = np.array([rng.uniform(-np.pi, np.pi), rng.uniform(-1.2, 1.2),
                      rng.uniform(-np.pi, np.pi)])
        u = rng.uniform(-4.0, 4.0, 3)
        par = {"m": rng.uniform(0.5, 3.0), "r": rng.uniform(0.2, 1.0), "g": rng.uniform(5, 12)}
        psi_d = u[2] / np.cos(q[1])
        y = np.array([*rng.uniform(-2, 2, 2), 0.9 * par["r"], *q])  # zc: a guess for Newton
        yd = np.array([0.0, 0.0, 0.0, psi_d, u[0], u[1] - np.sin(q[1]) * psi_d])
        yield q, u, par, y, yd


def _args(q, u, par) -> list[float]:
    return [*q, *u, par["r"], par["m"], par["g"]]


def _tree(disc: jd.System, out: dict, par: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """M_tree and the magnitudes of the terms that k and q of the speeds are summed from:
    ``|L|ᵀ(|J̄|ᵀ|q̄^c| + |M_tree||γ|)`` and ``|L|ᵀ|J̄|ᵀ|q̄^e|``."""
    tr = tree_evaluate(disc.tree, out["y"], out["yd"], 0.0, par)
    J, aL = np.abs(tr["J_bar"]), np.abs(out["L"])
    Mt = np.asarray(tr["M"], dtype=float)
    k_terms = aL.T @ (J.T @ np.abs(np.ravel(tr["q_c"])) + np.abs(Mt) @ np.abs(out["gamma"]))
    q_terms = aL.T @ (J.T @ np.abs(np.ravel(tr["q_e"])))
    return Mt, k_terms, q_terms


def test_speeds_and_kinematic_equations_are_sympys(disc: jd.System, sympy_disc: dict) -> None:
    """z from ẏ is sympy's u, and ẏ = L·z + l gives sympy's q̇ = f(q, u) for the angles; the
    contact point stays at rest (x, y follow from the rolling), the centre at r·cos q2."""
    for q, u, par, y, yd in _states(11):
        out = disc.evaluate(y, yd, parameters=par)
        assert out["speeds"] == ["u1", "u2", "u3"]
        np.testing.assert_allclose(out["z"], u, rtol=0, atol=10 * 3 * EPS * norm(u))
        ref = np.ravel(np.array(sympy_disc["qd"](*_args(q, u, par)), dtype=float))
        tol = solve_tol(_w(out), norm(out["L"]) * norm(u))
        tol += solve_tol(np.diag([1.0, np.cos(q[1])]), norm(ref))  # sympy's 1/cos q2
        assert np.max(np.abs(out["yd"][3:] - ref)) <= tol, (out["yd"][3:], ref, tol)
        assert abs(out["y"][2] - par["r"] * np.cos(q[1])) <= 10 * EPS * par["r"]


def test_right_hand_side_equals_sympys(disc: jd.System, sympy_disc: dict) -> None:
    """u̇ = M_s⁻¹·F_s of sympy against jourdain's ż at 12 random states and parameters, and
    M (= LᵀM_tree·L, formed with L from the solve with W) against M_s."""
    worst = 0.0
    for q, u, par, y, yd in _states(5):
        a = _args(q, u, par)
        M_s = np.array(sympy_disc["M"](*a), dtype=float)
        F_s = np.ravel(np.array(sympy_disc["F"](*a), dtype=float))
        ud_s = np.linalg.solve(M_s, F_s)
        out = disc.evaluate(y, yd, parameters=par)
        M = out["M"]
        _, k_terms, q_terms = _tree(disc, out, par)
        W = _w(out)
        tol_M = solve_tol(W, 2 * norm(M))  # L enters M twice
        assert np.max(np.abs(M - M_s)) <= tol_M, (M, M_s, tol_M)
        scale = solve_scale(M, out["zd"], (k_terms, q_terms))
        tol = sum(solve_tol(A, scale) for A in (M, M_s, W, W))
        d = float(np.max(np.abs(out["zd"] - ud_s)))
        assert d <= tol, (out["zd"], ud_s, d, tol, cond(M), cond(W))
        worst = max(worst, d / tol)
    assert worst < 1.0


def _w(out: dict) -> np.ndarray:
    """W = [Y; A] of the state: Y = ∂z/∂ẏ of the speeds' definitions (columns x, y, zc, psi,
    phi, theta), A the contact rows."""
    phi = out["y"][4]
    Y = np.zeros((3, 6))
    Y[0, 4] = 1.0
    Y[1, 5], Y[1, 3] = 1.0, np.sin(phi)
    Y[2, 3] = np.cos(phi)
    return np.vstack([Y, _contact_rows(out)])


def test_contact_forces_equal_sympys_auxiliary_speeds(disc: jd.System,
                                                     sympy_disc: dict) -> None:
    """The force of the ground on the disc at C from sympy's auxiliary speeds (u̇ from its
    right-hand side) against jourdain's multipliers of the rows ground.N, .T1, .T2 (in world
    axes, turned by q1), at 12 random states."""
    for q, u, par, y, yd in _states(23):
        a = _args(q, u, par)
        M_s = np.array(sympy_disc["M"](*a), dtype=float)
        ud_s = np.linalg.solve(M_s, np.ravel(np.array(sympy_disc["F"](*a), dtype=float)))
        A_aux = np.array(sympy_disc["A_aux"](*a), dtype=float)
        f = -np.linalg.solve(A_aux, np.ravel(np.array(sympy_disc["b_aux"](*a, *ud_s),
                                                       dtype=float)))
        c1, s1 = np.cos(q[0]), np.sin(q[0])
        ref = np.array([f[2], c1 * f[0] - s1 * f[1], s1 * f[0] + c1 * f[1]])
        out = disc.evaluate(y, yd, parameters=par)
        cf = out["contact_forces"]
        ours = np.array([cf["ground.N"], cf["ground.T1"], cf["ground.T2"]])
        Mt, k_terms, q_terms = _tree(disc, out, par)
        # λ solves Aᵀλ = M_tree·ÿ + k_tree − q_tree: its own solve, plus the error of ÿ
        # (that of ż through L, and of γ) mapped by M_tree and A's pseudo-inverse
        weight = par["m"] * par["g"]
        inertial = norm(Mt) * norm(out["ydd"])
        A_rows = _contact_rows(out)
        tol = solve_tol(A_rows, norm(ref) + (weight + inertial) / norm(A_rows))
        scale_zd = solve_scale(out["M"], out["zd"], (k_terms, q_terms))
        tol_zd = sum(solve_tol(A, scale_zd) for A in (out["M"], M_s, _w(out), _w(out)))
        tol += norm(Mt) * norm(out["L"]) * tol_zd / np.linalg.svd(A_rows, compute_uv=False)[-1]
        tol += solve_tol(A_aux, norm(ref) + weight)
        d = float(np.max(np.abs(ours - ref)))
        assert d <= tol, (ours, ref, d, tol)
        assert out["orthogonality"] <= 10 * 6 * EPS * norm(out["J_bar"]) * norm(out["Q_c"])


def _contact_rows(out: dict) -> np.ndarray:
    """The rows' matrix ``A`` (J̄_treeᵀ·Q̄_c = Aᵀ): λ is its least-squares solution."""
    return (np.asarray(out["J_bar_tree"]).T @ np.asarray(out["Q_c"])).T
