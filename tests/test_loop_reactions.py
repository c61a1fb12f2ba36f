"""Reactions of the closing joints by name (jourdain.loops.reactions): the four-bar's pin
force against the Newton–Euler equations of the coupler and the rocker written out here."""

from __future__ import annotations

import math

import numpy as np

from jourdain.loops import evaluate
from jourdain.loops.models import four_bar
from jourdain.loops.reactions import closing_reactions
from jourdain.loops.simulate import simulate_loop
from tests.tolerance import solve_tol

FB = {"a": 0.4, "b": 1.0, "c": 0.8, "d": 1.1, "m1": 1.0, "m2": 2.0, "m3": 1.5, "g": 9.81}


def _pin_force(z: np.ndarray, zd: np.ndarray, zdd: np.ndarray) -> np.ndarray:
    """Force of the rocker on the coupler at the closure pin (inertial x, y) from two moment
    equations: the rocker about its ground pivot and the coupler about the knee (the knee's
    and the ground's pin forces drop out)."""
    a, b, c, m2, m3, g = FB["a"], FB["b"], FB["c"], FB["m2"], FB["m3"], FB["g"]
    th1, phi, th3 = z[0], z[0] + z[1], z[2]
    w1, wphi = zd[0], zd[0] + zd[1]
    al1, alphi, al3 = zdd[0], zdd[0] + zdd[1], zdd[2]

    def e(x: float) -> np.ndarray:
        return np.array([math.cos(x), math.sin(x)])

    def ep(x: float) -> np.ndarray:
        return np.array([-math.sin(x), math.cos(x)])
    a_knee = a * (al1 * ep(th1) - w1 ** 2 * e(th1))
    a_cm = a_knee + b / 2 * (alphi * ep(phi) - wphi ** 2 * e(phi))
    r_cm = b / 2 * e(phi)
    # coupler about the knee: b e(φ) × F + r_cm × (−m2 g ŷ) = I_cm φ̈ + r_cm × m2 a_cm
    rhs_c = (m2 * b * b / 12 * alphi + m2 * (r_cm[0] * a_cm[1] - r_cm[1] * a_cm[0])
             + m2 * g * r_cm[0])
    row_c = b * np.array([-math.sin(phi), math.cos(phi)])
    # rocker about its pivot: c e(θ3) × (−F) − m3 g (c/2) cos θ3 = (m3 c²/3) θ̈3
    rhs_r = m3 * c * c / 3 * al3 + m3 * g * c / 2 * math.cos(th3)
    row_r = -c * np.array([-math.sin(th3), math.cos(th3)])
    A = np.array([row_c, row_r])
    return np.linalg.solve(A, [rhs_c, rhs_r]), A


def test_four_bar_closing_force_equals_newton_euler_of_coupler_and_rocker() -> None:
    loop = four_bar()
    for z0, zd0 in (([1.1, 0.3, 1.9], [1.5, 0, 0]), ([0.5, 0.8, 1.9], [-2.0, 0, 0])):
        s = evaluate(loop, z0, zd0)
        F_ref, A = _pin_force(s["z"], s["zd"], s["zdd"])
        w = closing_reactions(loop, s["z"], s["lambda"])["closure"]
        F, T = w["F"][0], w["T"][0]
        phi = s["z"][0] + s["z"][1]
        # A's (the coupler's) axes to inertial: rotation by φ about z
        F_in = np.array([math.cos(phi) * F[0] - math.sin(phi) * F[1],
                         math.sin(phi) * F[0] + math.cos(phi) * F[1]])
        K = np.block([[s["M_tree"], s["Phi_z"].T], [s["Phi_z"], np.zeros((2, 2))]])
        scale = 1.0 + float(np.max(np.abs(F_ref)))
        assert np.max(np.abs(F_in - F_ref)) <= solve_tol(K, scale) + solve_tol(A, scale)
        # a revolute joint about z in a plane: no moment about z, nothing out of the plane
        assert F[2] == 0.0 and np.all(T == 0.0)


def test_simulation_results_name_the_closing_joint_wrench() -> None:
    res = simulate_loop(four_bar(), (0.0, 1.0), [0.5, 0.8, 1.9], [1.0, 0, 0], samples=11)
    w = res.closing_reactions()
    assert list(w) == ["closure"] and w["closure"]["F"].shape == (11, 3)
    for k in (0, 5, 10):
        F_ref, A = _pin_force(res.z[k], res.zd[k], res.zdd[k])
        phi = res.z[k, 0] + res.z[k, 1]
        F = w["closure"]["F"][k]
        F_in = np.array([math.cos(phi) * F[0] - math.sin(phi) * F[1],
                         math.sin(phi) * F[0] + math.cos(phi) * F[1]])
        assert np.max(np.abs(F_in - F_ref)) <= 1e3 * solve_tol(A, 1 + np.max(np.abs(F_ref)))
    assert "closing joint closure: max |F|" in res.summary()
