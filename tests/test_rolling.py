"""Velocity constraints (METHOD.md §7): Chaplygin's sleigh (a knife edge, speeds given by
definition) and the rolling disc against their closed forms, and the errors of bad input."""

from __future__ import annotations

import numpy as np
import pytest

import jourdain as jd
from jourdain.errors import ModelError, SingularConfiguration
from jourdain.models.rolling import chaplygin_sleigh, rolling_disc

EPS = float(np.finfo(float).eps)


def _sleigh_state(rng: np.random.Generator, a: float) -> tuple[np.ndarray, np.ndarray, float,
                                                               float]:
    y = rng.uniform(-1.0, 1.0, 3)
    u, w = rng.uniform(-2.0, 2.0, 2)
    psi = y[2]
    ex = np.array([np.cos(psi), np.sin(psi)])
    ey = np.array([-np.sin(psi), np.cos(psi)])
    vc = u * ex - a * w * ey  # the centre of mass, a behind the edge
    return y, np.array([vc[0], vc[1], w]), u, w


def test_sleigh_equals_its_closed_form() -> None:
    s = chaplygin_sleigh()
    p = s.parameter_values
    m, I, a = p["m"], p["I"], p["a"]
    rng = np.random.default_rng(7)
    for _ in range(5):
        y, yd, u, w = _sleigh_state(rng, a)
        out = s.evaluate(y, yd)
        assert out["speeds"] == ["u", "w"]
        np.testing.assert_allclose(out["z"], [u, w], rtol=0, atol=10 * EPS * 4)
        ref = np.array([-a * w * w, m * a * u * w / (I + m * a * a)])
        scale = float(np.max(np.abs(ref))) + 1.0
        assert np.max(np.abs(out["zd"] - ref)) <= 100 * EPS * scale
        F = m * I * u * w / (I + m * a * a)
        assert abs(out["contact_forces"]["edge.T"] - F) <= 100 * EPS * (abs(F) + 1.0)


def test_sleigh_run_keeps_energy_and_the_edge() -> None:
    s = chaplygin_sleigh()
    p = s.parameter_values
    m, I, a = p["m"], p["I"], p["a"]
    y, yd, u, w = _sleigh_state(np.random.default_rng(2), a)
    res = s.simulate((0.0, 5.0), y, yd, rtol=1e-11, atol=1e-12)
    assert res.status == "finished"
    T = 0.5 * m * (res.yd[:, 0] ** 2 + res.yd[:, 1] ** 2) + 0.5 * I * res.yd[:, 2] ** 2
    assert np.max(np.abs(T - T[0])) <= 1e-8 * T[0]
    assert np.max(np.abs(res.constraints.Phi_dot)) <= 1e3 * EPS * (1 + np.abs(res.yd).max())


@pytest.mark.parametrize("Omega", [2.0, 3.0, 6.0])
def test_rolling_disc_lean_frequency_and_critical_spin(Omega: float) -> None:
    """Upright rolling at spin Ω (thin uniform disc, I_d = m r²/4, I_a = m r²/2): the lean
    obeys (I_d + m r²)·φ̈ + (I_a(I_a + m r²)Ω²/I_d − m g r)·φ = 0 once the heading rate is
    eliminated; stable (marginally) above Ω² = g/(3r)."""
    d = rolling_disc()
    p = d.parameter_values
    m, r, g = p["m"], p["r"], p["g"]
    Id, Ia = m * r * r / 4, m * r * r / 2
    lin = d.linearize({"zc": r, "theta_d": -Omega})
    assert lin.names == ("psi", "phi") and set(lin.cyclic) == {"x", "y", "theta"}
    w2 = (Ia * (Ia + m * r * r) * Omega ** 2 / Id - m * g * r) / (Id + m * r * r)
    nonzero = lin.eigenvalues[np.abs(lin.eigenvalues) > 1e-6]
    ref = np.sqrt(complex(-w2))
    assert np.allclose(np.sort_complex(nonzero), np.sort_complex([-ref, ref]),
                       rtol=1e-12, atol=1e-12)
    verdict = jd.stability(lin).verdict
    assert verdict == ("unstable" if Omega ** 2 < g / (3 * r) else "marginally stable")


def test_contact_forces_of_a_disc_at_rest() -> None:
    d = rolling_disc()
    p = d.parameter_values
    out = d.evaluate([0.3, -0.2, p["r"], 0.4, 0.0, 1.0], np.zeros(6))
    f = out["contact_forces"]
    weight = p["m"] * p["g"]
    assert abs(f["ground.N"] - weight) <= 10 * EPS * weight
    assert abs(f["ground.T1"]) <= 10 * EPS * weight and abs(f["ground.T2"]) <= 10 * EPS * weight


def test_bad_input_names_the_element() -> None:
    s = chaplygin_sleigh()
    with pytest.raises(ModelError, match="unknown body"):
        jd.System(s.coordinates, s.bodies, contacts=[jd.KnifeEdge("k", "nobody")],
                  parameters=dict(s.parameters))
    with pytest.raises(ModelError, match="not linear"):
        jd.System(s.coordinates, s.bodies, parameters=dict(s.parameters),
                  contacts=[jd.VelocityConstraint("v", [jd.symbols("x_d") ** 2])])
    with pytest.raises(ModelError, match="leave 2 generalized velocities"):
        jd.System(s.coordinates, s.bodies, parameters=dict(s.parameters),
                  contacts=s.contacts, speeds=["x"]).evaluate([0, 0, 0], [0, 0, 0])
    d = rolling_disc()
    with pytest.raises(SingularConfiguration, match="ground"):
        d.evaluate([0, 0, 0.0, 0, np.pi / 2, 0], np.zeros(6))
    with pytest.raises(jd.ClosedSystemError if hasattr(jd, "ClosedSystemError") else
                       ModelError, match="contact"):
        jd.kinematics(d)


def test_a_ball_rolls_as_a_torus_of_zero_radius() -> None:
    """A solid ball (radius ρ: ``RollingDisc(radius=0, tube_radius=ρ)``) pushed at its centre
    by F along x: ``a = F/(m + I/ρ²) = 5F/(7m)``, the ground's friction ``−2F/7`` on it, the
    normal force ``m·g``, the centre at height ρ whatever the orientation."""
    x, y, z, psi, phi, theta = jd.symbols("x y z psi phi theta")
    m, rho, g, F = jd.symbols("m rho g F")
    ball = jd.Body("ball", "world", jd.General(
        "free", [jd.Trans(vector=(x, y, z)), jd.Rot("z", psi), jd.Rot("x", phi),
                 jd.Rot("y", theta)], coordinates=(x, y, z, psi, phi, theta)),
        mass=m, inertia=(2 * m * rho**2 / 5,) * 3)
    s = jd.System([x, y, z, psi, phi, theta], [ball],
                  [jd.Gravity((0, 0, -g)), jd.Force("push", "ball", (F, 0, 0))],
                  parameters={"m": 2.0, "rho": 0.11, "g": 9.81, "F": 3.0},
                  contacts=[jd.RollingDisc("ground", "ball", 0, "y", tube_radius=rho)],
                  independent=["x", "y", "psi", "phi", "theta"],
                  speeds=["psi", "phi", "theta"])
    p = s.parameter_values
    out = s.evaluate([0.3, -0.1, 0.0, 0.2, 0.3, 0.4], np.zeros(6))
    assert abs(out["y"][2] - p["rho"]) <= 10 * EPS * p["rho"]
    a = np.asarray(out["ydd"])[:2]
    along = a[0] * 1.0  # the push is along the world's x
    ref = 5 * p["F"] / (7 * p["m"])
    assert abs(along - ref) <= 1e3 * EPS * ref and abs(a[1]) <= 1e3 * EPS * ref
    f = out["contact_forces"]
    assert abs(f["ground.T1"] + 2 * p["F"] / 7) <= 1e3 * EPS * p["F"]
    assert abs(f["ground.N"] - p["m"] * p["g"]) <= 1e3 * EPS * p["m"] * p["g"]


def test_a_leaning_torus_touches_at_its_lowest_point() -> None:
    """A torus wheel (R, ρ) leaning by φ has its centre at R·cos φ + ρ and the normal force
    m·g at rest with the lean held (the centre of mass above the contact only when upright)."""
    x, y, z, psi, phi, theta = jd.symbols("x y z psi phi theta")
    m, R, rho, g = jd.symbols("m R rho g")
    wheel = jd.Body("wheel", "world", jd.General(
        "free", [jd.Trans(vector=(x, y, z)), jd.Rot("z", psi), jd.Rot("x", phi),
                 jd.Rot("y", theta)], coordinates=(x, y, z, psi, phi, theta)),
        mass=m, inertia=(m * R**2 / 4, m * R**2 / 2, m * R**2 / 4))
    s = jd.System([x, y, z, psi, phi, theta], [wheel], [jd.Gravity((0, 0, -g))],
                  parameters={"m": 1.5, "R": 0.3, "rho": 0.02, "g": 9.81},
                  contacts=[jd.RollingDisc("tyre", "wheel", R, "y", tube_radius=rho)],
                  independent=["x", "y", "psi", "phi", "theta"],
                  speeds=["psi", "phi", "theta"])
    p = s.parameter_values
    for lean in (0.0, 0.2, -0.5):
        out = s.evaluate([0.0, 0.0, 0.0, 0.1, lean, 0.3], np.zeros(6))
        ref = p["R"] * np.cos(lean) + p["rho"]
        assert abs(out["y"][2] - ref) <= 10 * EPS * ref
        assert np.max(np.abs(out["Phi"])) <= 10 * EPS * ref


def test_speeds_by_definition_linearize_in_quasi_coordinates() -> None:
    """The differential drive in its body speeds (v, w) about straight running at v: every
    coordinate is cyclic, so the linearization is in the speeds' quasi-coordinates; the yaw
    rate obeys I·δẇ + mc·b·v·δw = 0 (eigenvalue −mc·b·v/I), the speed is neutral."""
    from jourdain.models.wheeled import differential_drive

    s = differential_drive("body")
    p = s.parameter_values
    v = 1.5
    lin = s.linearize({"x_d": v, "thetaL_d": v / p["r"], "thetaR_d": v / p["r"]})
    assert lin.names == ("v", "w") and set(lin.cyclic) == {"x", "y", "psi", "thetaL", "thetaR"}
    I = (p["Ic"] + p["mc"] * p["b"] ** 2 + 2 * p["mw"] * p["d"] ** 2 + 2 * p["Iw"]
         + 2 * p["Jw"] * p["d"] ** 2 / p["r"] ** 2)
    ref = -p["mc"] * p["b"] * v / I
    lam = lin.eigenvalues
    assert np.min(np.abs(lam - ref)) <= 1e3 * EPS * abs(ref)
    assert np.sum(np.abs(lam) <= 1e3 * EPS * abs(ref)) == 3
    assert jd.stability(lin).verdict == "marginally stable"


def test_the_c_kernel_runs_the_motion_of_the_numpy_path() -> None:
    """The benchmark bicycle leaning at 5 m/s, 2 s: jourdain's C integrator with the compiled
    kernel (DOP853) and SciPy's stepper on the NumPy evaluator (scipy:DOP853) reach the same
    motion to their tolerance, and both keep every row at rounding; the contact forces agree."""
    from jourdain.models.rolling import benchmark_bicycle

    s = benchmark_bicycle()
    names = s.coordinate_names
    y0 = np.zeros(9)
    y0[names.index("zc")] = -0.3
    y0[names.index("phi")] = 0.05
    yd0 = np.zeros(9)
    yd0[names.index("thetaR")] = -5 / 0.3
    te = np.linspace(0.0, 2.0, 41)
    runs = [s.simulate((0.0, 2.0), y0, yd0, method=m, rtol=1e-10, atol=1e-12, t_eval=te)
            for m in ("DOP853", "scipy:DOP853")]
    for r in runs:
        assert r.status == "finished" and len(r.t) == te.size
        assert np.max(np.abs(r.constraints.Phi)) <= 1e-13
        assert np.max(np.abs(r.constraints.Phi_dot)) <= 1e-13
    scale = float(np.max(np.abs(runs[1].y)))
    assert np.max(np.abs(runs[0].y - runs[1].y)) <= 1e-7 * scale
    lam = runs[1].constraints.multipliers
    assert np.max(np.abs(runs[0].constraints.multipliers - lam)) <= 1e-6 * np.max(np.abs(lam))


def test_the_rolling_disc_example_finds_the_critical_spin(tmp_path) -> None:
    """examples/rolling_disc.toml: `jourdain run` gives the stable spin range from
    Ω = √(g/(3r)) (the boundary by stability_boundary) to the sweep's end."""
    from pathlib import Path

    from jourdain.cli import main

    path = Path(__file__).resolve().parents[1] / "examples" / "rolling_disc.toml"
    assert main(["run", str(path), "--out", str(tmp_path / "r"), "--t-end", "0.5"]) == 0
    html = (tmp_path / "r" / "report.html").read_text(encoding="utf-8")
    bounds = [float(x) for x in html.split("(boundaries ")[1].split(" by")[0].split(", ")]
    ref = np.sqrt(9.81 / (3 * 0.5))
    # the stable side is only marginally stable (purely imaginary eigenvalues), so the boundary
    # is where the verdict changes, read off eigenvalues that split from a multiple root there:
    # rounding of the matrices (ε ≈ 2e-16) moves them by about √ε, and the boundary by as much
    # relative (measured 3e-8 with the complex step of jourdain.graph.complex_step)
    assert len(bounds) == 1 and abs(bounds[0] - ref) <= 10 * np.sqrt(np.finfo(float).eps) * ref


def test_a_top_in_body_fixed_angular_velocities() -> None:
    """Speeds by definition on a tree (no contact): the heavy top's body-fixed angular
    velocity components ω = J_R·ψ̇ (its kinematics' ``omega``) as z. Then M is the inertia
    about the pivot in the body's principal axes, diag(A + m·L², A + m·L², C), and the motion
    in z is the motion in Euler angles of the tree."""
    from jourdain.models.classic import heavy_top

    top = heavy_top()
    omega = jd.kinematics(top)["top"].omega
    speeds = {f"w{i + 1}": omega.rows[i][0] for i in range(3)}
    gen = jd.System(top.coordinates, top.bodies, top.forces, dict(top.parameters),
                    name="top in body speeds", speeds=speeds)
    p = top.parameter_values
    y0, yd0 = [0.2, 0.6, 0.1], [0.5, 0.3, 40.0]
    out = gen.evaluate(y0, yd0)
    T = p["A"] + p["m"] * p["L"] ** 2
    ref = np.diag([T, T, p["C"]])
    assert np.max(np.abs(out["M"] - ref)) <= 100 * EPS * T
    a = gen.simulate((0.0, 0.5), y0, yd0, rtol=1e-11, atol=1e-12, t_eval=[0.25, 0.5])
    b = top.simulate((0.0, 0.5), y0, yd0, rtol=1e-11, atol=1e-12, t_eval=[0.25, 0.5])
    assert a.status == "finished" and np.max(np.abs(a.y - b.y)) <= 1e-8
    assert np.max(np.abs(a.yd - b.yd)) <= 1e-6
