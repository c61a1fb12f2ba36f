"""Reactions of the closing joints by name (jourdain.loops.reactions): the four-bar's pin
force against the Newton–Euler equations of the coupler and the rocker written out here."""

from __future__ import annotations

import math

import numpy as np
import pytest

from jourdain.loops import evaluate
from jourdain.loops.reactions import closing_reactions
from jourdain.models.loops import four_bar
from tests.test_loops import slider_tree
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
    from jourdain.numeric import parameter_vector

    loop = four_bar()
    res = loop.simulate((0.0, 1.0), [0.5, 0.8, 1.9], [1.0, 0, 0], samples=11, rtol=1e-10,
                        atol=1e-12)
    w = closing_reactions(loop, res.y, res.multipliers, res.t,
                          parameter_vector(loop.tree, res.parameters))
    assert list(w) == ["closure"] and w["closure"]["F"].shape == (11, 3)
    for k in (0, 5, 10):
        F_ref, A = _pin_force(res.y[k], res.yd[k], res.ydd[k])
        phi = res.y[k, 0] + res.y[k, 1]
        F = w["closure"]["F"][k]
        F_in = np.array([math.cos(phi) * F[0] - math.sin(phi) * F[1],
                         math.sin(phi) * F[0] + math.cos(phi) * F[1]])
        assert np.max(np.abs(F_in - F_ref)) <= 1e3 * solve_tol(A, 1 + np.max(np.abs(F_ref)))
    # the closing joint's rows are named among the reactions of the one results
    assert set(res.constraint_labels) <= set(res.g_names)


def _loops() -> dict:
    from pathlib import Path

    from jourdain.io.modelfile import loads_model
    from jourdain.loops import ClosingJoint

    ex = Path(__file__).resolve().parents[1] / "examples" / "spatial_rssr.toml"
    mf = loads_model(ex.read_text(), "spatial_rssr.toml")
    tree = slider_tree()
    return {
        "revolute": (four_bar(), [1.1, 0.3, 1.9], [1.5, 0, 0]),
        "spherical": (mf.system, list(mf.simulation.y0), [1.0, 0, 0, 0.3, 0]),
        "prismatic": (tree.closed_by([ClosingJoint("guide", "prismatic", "world",
                                                           "slider", axis="x")], ("phi",)),
                      [0.5, -0.6, 0.1], [2.0, 0, 0]),
        "point_on_line": (tree.closed_by([ClosingJoint(
            "line", "point_on_line", "crank", "slider", point_a=(0, 0.2, 0), axis=(1, 0.5, 0))],
            ("phi", "chi")), [0.5, -0.6, 0.1], [2.0, 0, 0.7]),
    }


@pytest.mark.parametrize("kind", ["revolute", "spherical", "prismatic", "point_on_line"])
def test_closing_wrench_does_the_virtual_work_of_its_rows(kind: str) -> None:
    """Each row's unit wrench (force and torque on A at A's joint point, the opposite on B)
    does the power Φ̇_i = Φ_z,i·ż for any motion on the manifold: checked with the bodies'
    velocities from the tree's kinematics (independent of the row formulas), for every kind
    of closing joint with points, at rates off the manifold's tangent (Φ̇ ≠ 0) and at the
    motion's own, where the power vanishes: the orthogonality J̄ᵀQ̄ = 0 of the closing joints
    (Φ_z·J_z = 0)."""
    import symengine as se

    from jourdain.loops import constraints
    from jourdain.loops.reactions import closing_wrench_map
    from jourdain.model.forces import rate
    from jourdain.stages.kinematics import kinematics

    loop, z0, zd0 = _loops()[kind]
    s = evaluate(loop, z0, zd0)
    tree = loop.tree
    kin = kinematics(tree)
    con = constraints(loop)
    W = closing_wrench_map(loop).W_inertial
    by_name = {cj.name: cj for cj in loop.closing}
    n = loop.f
    # any rates (off the manifold's tangent: Φ̇ ≠ 0) and the motion's own (Φ̇ = 0)
    rng = np.random.default_rng(7)
    for yd in (rng.uniform(-1.5, 1.5, n), np.asarray(s["zd"])):
        values = {c: v for c, v in zip(tree.coordinates, s["z"], strict=True)}
        values.update({rate(c): v for c, v in zip(tree.coordinates, yd, strict=True)})
        values.update({se.Symbol(k): v for k, v in tree.parameters})
        values[tree.t] = 0.0

        def num(e: se.Basic, values: dict = values) -> float:
            return float(se.sympify(e).subs(values))

        def vec(m, num=num) -> np.ndarray:  # noqa: ANN001
            return np.array([num(r[0]) for r in m.rows])

        def motion(body: str, point: np.ndarray, num=num, vec=vec, yd=yd  # noqa: ANN001
                   ) -> tuple[np.ndarray, np.ndarray]:
            if body == "world":
                return np.zeros(3), np.zeros(3)
            bk = kin[body]
            S = np.array([[num(e) for e in row] for row in bk.S.rows])
            w = S @ vec(bk.omega)
            JT = np.array([[num(e) for e in row] for row in bk.J_T_O.rows])
            v_O = JT @ yd + vec(bk.v_bar_O)
            return v_O + np.cross(w, point - vec(bk.r_O)), w

        checked, largest = 0, 0.0
        for i, row in enumerate(con.rows):
            cj = by_name[row.joint]
            if cj.body_a == "world":
                pA = np.array([num(e) for e in cj.point_a])
            else:
                bk = kin[cj.body_a]
                S = np.array([[num(e) for e in r] for r in bk.S.rows])
                pA = vec(bk.r_O) + S @ np.array([num(e) for e in cj.point_a])
            vA, wA = motion(cj.body_a, pA)
            vB, wB = motion(cj.body_b, pA)
            unit = np.array([num(W.rows[k][i]) for k in range(6)])
            power = unit[:3] @ (vA - vB) + unit[3:] @ (wA - wB)
            Phi_dot = float(np.asarray(s["Phi_z"])[i] @ yd)
            scale = 1.0 + float(np.max(np.abs(yd))) * (1.0 + float(np.max(np.abs(s["z"]))))
            assert abs(power - Phi_dot) <= 1e3 * 2.2e-16 * scale, row.label
            largest = max(largest, abs(Phi_dot))
            checked += 1
        assert checked == len(con.rows) >= 1
        if yd is not s["zd"]:
            assert largest > 1e-2  # the check was not of zeros
