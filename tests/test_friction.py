"""Coulomb friction from reaction forces (issue 38, item 4): ``jd.JointFriction`` and
``[forces.<name>] type = "joint_friction"``, against closed forms.

- a block on an incline: sliding down accelerates at g(sin α − μ cos α) with the normal
  reaction m·g·cos α; sliding up decelerates at g(sin α + μ cos α); a block that slides, stops
  and sticks follows the closed form, then creeps at the regularization's documented rate
  v_eps·atanh(tan α/μ) (against the scalar regularized equation, integrated by SciPy); from rest
  with tan α < μ it creeps at that rate and no faster;
- a box on horizontal ground pushed by F > μ·m·g: ẍ = F/m − μ·g (sympy's ``test_box_on_ground``
  model of ``sympy/physics/mechanics/tests/test_system_class.py``: M = m, forcing F − μN,
  auxiliary equation N − m·g = 0), in Python and from a model file;
- a wheel on a loaded axle: friction torque μ·r_pin·|F_radial| with F_radial = m·g + P, the
  spin-down φ̇ = ω0 − μ·r_pin·(m·g + P)/J·t;
- a pendulum whose pin friction changes the radial load it depends on (the coupled case):
  the friction torque from the quadratic equation τ² = (μ·r)²·|F(τ)|², and the refusal of
  Painlevé's paradox.

Tolerances: evaluations by tests/tolerance.py (solve rules over M and N̂), simulations by the
integrator's tolerances (rtol 1e-10).
"""

from __future__ import annotations

import numpy as np
import pytest

import jourdain as jd
from jourdain.io import ModelFileError, loads_model
from tests.tolerance import assert_close_solved, newton_euler_tol, solve_scale

G = 9.81
V_EPS = 1e-3  # the default regularization rate of JointFriction


def _close(ours, ref, out, c=10.0):
    """A friction-coupled result against a closed form: the solves with M and N̂ (twice: g_0
    and D), on the scale of the forces."""
    scale = solve_scale(out["N_hat"], out["g"], (out["k_hat"], out["q_hat"])) + np.abs(ref).max()
    assert_close_solved(ours, ref, [np.atleast_2d(out["M"]), out["N_hat"], out["N_hat"]],
                        scale=scale, c=c)


def _consistent(out):
    """The Newton–Euler equations hold with the friction in q̄^e and g."""
    r = (out["M_bar"] @ out["J_bar"] @ out["ydd"] + out["q_c"] - out["q_e"]
         - out["Q_bar"] @ out["g"])
    assert np.abs(r).max() <= newton_euler_tol(out, out["ydd"])


def incline(alpha: float, mu: float, **kw):
    """A block (mass m) on a slope falling at α: x along the slope, downhill; the slide's
    F_y is the normal force (the joint frame turned by −α about z)."""
    x, m, g, a, mu_ = jd.symbols("x m g alpha mu")
    return jd.System(
        [x], [jd.Body("block", "world", jd.Prismatic("slide", x, "x", orientation=[jd.Rot("z", -a)]),
                      mass=m, inertia=jd.box(m, 0.4, 0.2, 0.3))],
        [jd.Gravity((0, -g, 0)), jd.JointFriction("friction", "slide", mu_, "F_y", **kw)],
        parameters={"m": 2.0, "g": G, "alpha": alpha, "mu": mu})


def test_block_sliding_down_an_incline_at_the_closed_form():
    alpha, mu, m = 0.5, 0.3, 2.0
    s = incline(alpha, mu)
    out = s.evaluate([0.1], [1.0])
    g = dict(zip(out["g_names"], out["g"], strict=True))
    _close(out["ydd"], [G * (np.sin(alpha) - mu * np.cos(alpha))], out)
    _close([g["slide.F_y"]], [m * G * np.cos(alpha)], out)
    fr = out["friction"]["friction"]
    _close([fr["force"], fr["normal"]], [-mu * m * G * np.cos(alpha), m * G * np.cos(alpha)],
           out)
    _consistent(out)
    up = s.evaluate([0.1], [-1.0])  # sliding uphill: friction points downhill
    _close(up["ydd"], [G * (np.sin(alpha) + mu * np.cos(alpha))], up)

    v0, T = 1.0, 1.5
    res = s.simulate((0, T), [0.0], [v0], rtol=1e-10, atol=1e-12, t_eval=np.linspace(0, T, 7))
    a = G * (np.sin(alpha) - mu * np.cos(alpha))
    np.testing.assert_allclose(res.y[:, 0], v0 * res.t + a * res.t**2 / 2, rtol=1e-8, atol=1e-12)
    np.testing.assert_allclose(res.yd[:, 0], v0 + a * res.t, rtol=1e-8)
    # the normal force along the motion, the friction force as the results' input column
    k = res.g_names.index("slide.F_y")
    np.testing.assert_allclose(res.g[:, k], m * G * np.cos(alpha), rtol=1e-12)
    np.testing.assert_allclose(res.u[:, res.input_names.index("friction")],
                               -mu * m * G * np.cos(alpha), rtol=1e-12)
    assert res.energy_balance_error < 1e-8  # the friction's work is in W


def _regularized_block(alpha, mu, v0, T, t_eval):
    """The block's own equation with the regularized law, N = m·g·cos α (SciPy)."""
    from scipy.integrate import solve_ivp

    def rhs(t, x):
        return [x[1], G * np.sin(alpha) - mu * G * np.cos(alpha) * np.tanh(x[1] / V_EPS)]

    sol = solve_ivp(rhs, (0, T), [0.0, v0], method="Radau", rtol=1e-11, atol=1e-13,
                    t_eval=t_eval)
    return sol.y


def test_block_slides_stops_and_sticks_on_an_incline():
    """tan α < μ: the block slides to a stop by the closed form, then sticks (creeps at
    v_eps·atanh(tan α/μ), the documented regularization)."""
    alpha, mu, v0, T = 0.2, 0.4, 0.5, 1.0
    s = incline(alpha, mu)
    a = G * (np.sin(alpha) - mu * np.cos(alpha))  # < 0
    t_stop = -v0 / a
    t_band = t_stop - 20 * V_EPS / -a  # until here |ẋ| > 20·v_eps: tanh = 1 to 1e-17
    te = np.concatenate([np.linspace(0, t_band, 6), np.linspace(t_stop + 0.2, T, 5)])
    res = s.simulate((0, T), [0.0], [v0], method="Radau", rtol=1e-10, atol=1e-12, t_eval=te)
    slide = res.t <= t_band
    np.testing.assert_allclose(res.y[slide, 0], v0 * res.t[slide] + a * res.t[slide] ** 2 / 2,
                               rtol=1e-8, atol=1e-12)
    v_creep = V_EPS * np.arctanh(np.tan(alpha) / mu)
    np.testing.assert_allclose(res.yd[~slide, 0], v_creep, rtol=1e-6)
    x_stop = -v0**2 / (2 * a)
    assert 0 < res.y[-1, 0] - x_stop < v_creep * (T - t_band) + 20 * V_EPS * (t_stop - t_band)
    ref = _regularized_block(alpha, mu, v0, T, res.t)
    np.testing.assert_allclose(res.y[:, 0], ref[0], rtol=1e-7, atol=1e-10)
    np.testing.assert_allclose(res.yd[:, 0], ref[1], rtol=1e-6, atol=1e-10)
    # sticking, the friction balances the weight's component along the slope
    out = s.evaluate(res.y[-1], res.yd[-1])
    np.testing.assert_allclose(out["friction"]["friction"]["force"],
                               -2.0 * G * np.sin(alpha), rtol=1e-8)


def test_block_at_rest_on_an_incline_below_the_friction_angle_sticks():
    alpha, mu, T = 0.2, 0.3, 0.5
    res = incline(alpha, mu).simulate((0, T), [0.0], [0.0], method="Radau", rtol=1e-10,
                                      atol=1e-12)
    v_creep = V_EPS * np.arctanh(np.tan(alpha) / mu)
    assert np.all(res.yd[:, 0] <= v_creep * (1 + 1e-6))
    assert 0 <= res.y[-1, 0] <= v_creep * T
    np.testing.assert_allclose(res.yd[-1, 0], v_creep, rtol=1e-6)
    # a smaller v_eps sticks better, in proportion
    res2 = incline(alpha, mu, v_eps=1e-5).simulate((0, T), [0.0], [0.0], method="Radau",
                                                    rtol=1e-10, atol=1e-14)
    np.testing.assert_allclose(res2.yd[-1, 0], 1e-2 * v_creep, rtol=1e-5)


def box_on_ground(F: float = 10.0, mu: float = 0.3):
    """sympy's test_box_on_ground: a particle on the ground pushed by F, friction μ·N."""
    x, m, g, f, mu_ = jd.symbols("x m g F mu")
    return jd.System(
        [x], [jd.Body("box", "world", jd.Prismatic("ground", x, "x"), mass=m,
                      inertia=jd.point_mass())],
        [jd.Gravity((0, -g, 0)), jd.Force("push", "box", (f, 0, 0)),
         jd.JointFriction("friction", "ground", mu_, "F_y")],
        parameters={"m": 2.0, "g": G, "F": F, "mu": mu})


BOX_TOML = """
[model]
name = "box on ground"
[coordinates]
x = "m"
[parameters]
m = 2.0
g = 9.81
F = 10.0
mu = 0.3
[bodies.box]
parent = "world"
mass = "m"
inertia = "point"
joint = { type = "prismatic", name = "ground", coordinate = "x", axis = "x" }
[forces.gravity]
type = "gravity"
vector = [0, "-g", 0]
[forces.push]
type = "force"
body = "box"
vector = ["F", 0, 0]
[forces.friction]
type = "joint_friction"
joint = "ground"
mu = "mu"
normal = "F_y"
"""


@pytest.mark.parametrize("source", ["python", "model file"])
def test_box_pushed_along_the_ground(source):
    m, F, mu = 2.0, 10.0, 0.3
    s = box_on_ground() if source == "python" else loads_model(BOX_TOML).system
    out = s.evaluate([0.0], [0.5])
    N = out["g"][out["g_names"].index("ground.F_y")]
    _close([N], [m * G], out)  # sympy's auxiliary equation N − m·g = 0
    _close(np.ravel(out["M"]), [m], out)  # sympy's mass matrix m
    _close(out["q"], [F - mu * m * G], out)  # sympy's forcing F − μ·N
    _close(out["ydd"], [F / m - mu * G], out)
    _consistent(out)
    T, v0 = 2.0, 0.5
    res = s.simulate((0, T), [0.0], [v0], rtol=1e-10, atol=1e-12, t_eval=[0, 1, 2])
    a = F / m - mu * G
    np.testing.assert_allclose(res.y[:, 0], v0 * res.t + a * res.t**2 / 2, rtol=1e-8)


def test_box_pushed_below_the_friction_limit_sticks():
    m, F, mu = 2.0, 3.0, 0.3  # F < μ·m·g = 5.9
    res = box_on_ground(F, mu).simulate((0, 0.5), [0.0], [0.0], method="Radau", rtol=1e-10,
                                        atol=1e-12)
    np.testing.assert_allclose(res.yd[-1, 0], V_EPS * np.arctanh(F / (mu * m * G)), rtol=1e-6)


def loaded_wheel():
    """A wheel (disc) on an axle along z, its centre on the axis, loaded by its weight and P."""
    phi, m, g, R, P, mu, r = jd.symbols("phi m g R P mu r_pin")
    return jd.System(
        [phi], [jd.Body("wheel", "world", jd.Revolute("axle", phi, "z"), mass=m,
                        inertia=jd.disc(m, R, "z"))],
        [jd.Gravity((0, -g, 0)), jd.Force("load", "wheel", (0, -P, 0)),
         jd.JointFriction("bearing", "axle", mu, ["F_x", "F_y"], radius=r)],
        parameters={"m": 3.0, "g": G, "R": 0.3, "P": 40.0, "mu": 0.1, "r_pin": 0.02})


def test_wheel_on_a_loaded_axle_spins_down_at_the_closed_form():
    m, R, P, mu, r = 3.0, 0.3, 40.0, 0.1, 0.02
    J = m * R**2 / 2
    torque = mu * r * (m * G + P)
    s = loaded_wheel()
    out = s.evaluate([0.7], [5.0])
    _close(out["ydd"], [-torque / J], out)
    fr = out["friction"]["bearing"]
    _close([fr["normal"], fr["force"]], [m * G + P, -torque], out)
    _consistent(out)
    w0, T = 20.0, 1.0  # stops at J·w0/torque = 2.1 s
    res = s.simulate((0, T), [0.0], [w0], rtol=1e-10, atol=1e-12, t_eval=[0, 0.5, 1.0])
    np.testing.assert_allclose(res.yd[:, 0], w0 - torque / J * res.t, rtol=1e-8)
    np.testing.assert_allclose(res.y[:, 0], w0 * res.t - torque / J * res.t**2 / 2, rtol=1e-8)


def pendulum(mu: float = 0.3, r_pin: float = 0.05):
    """A rod hanging from a pin with friction: the radial load depends on the friction
    torque (through the tangential acceleration), which depends on the load."""
    phi, m, g, l, I, mu_, r = jd.symbols("phi m g l I mu r_pin")
    return jd.System(
        [phi], [jd.Body("rod", "world", jd.Revolute("pin", phi, "z"), mass=m, com=(0, -l, 0),
                        inertia=((I, 0, 0), (0, I, 0), (0, 0, I)))],
        [jd.Gravity((0, -g, 0)), jd.JointFriction("pin_friction", "pin", mu_, ["F_x", "F_y"],
                                                  radius=r)],
        parameters={"m": 1.5, "g": G, "l": 0.8, "I": 0.05, "mu": mu, "r_pin": r_pin})


def _pendulum_closed_form(phi, w, mu, r, m=1.5, l=0.8, I=0.05):
    """τ = −c·|F|, F the pin's force: tangential a + b·τ, radial F_n (Newton for the centre
    of mass), so τ²(1 − c²b²) − 2c²ab·τ − c²(a² + F_n²) = 0, the root of sign −sign(c)."""
    J = I + m * l**2
    c = mu * r * np.tanh(w / V_EPS)
    a, b = m * G * np.sin(phi) * I / J, m * l / J
    Fn = m * l * w**2 + m * G * np.cos(phi)
    roots = np.roots([1 - c**2 * b**2, -2 * c**2 * a * b, -c**2 * (a**2 + Fn**2)])
    tau = float(next(t.real for t in roots if np.sign(t.real) == -np.sign(c)))
    return tau, (-m * G * l * np.sin(phi) + tau) / J, np.hypot(a + b * tau, Fn)


@pytest.mark.parametrize("phi, w", [(0.6, 2.0), (-1.1, -3.0), (2.5, 0.4)])
def test_pin_friction_and_its_radial_load_solved_together(phi, w):
    mu, r = 0.4, 0.3  # μ·r·m·l/J = 0.14: the torque moves the load by 0.5 %
    out = pendulum(mu, r).evaluate([phi], [w])
    tau, ydd, F = _pendulum_closed_form(phi, w, mu, r)
    fr = out["friction"]["pin_friction"]
    _close([fr["force"], fr["normal"]], [tau, F], out)
    _close(out["ydd"], [ydd], out)
    _consistent(out)
    # the coupling matters: μ·r times the load without the friction torque is another torque
    F0 = _pendulum_closed_form(phi, w, 0.0, r)[2]
    assert abs(mu * r * F0 - abs(tau)) > 1e-3 * abs(tau)


def test_painleve_paradox_is_refused():
    """μ·r·m·l/J ≥ 1: no friction torque is consistent with the load it makes."""
    s = pendulum(mu=3.0, r_pin=0.8)
    with pytest.raises(jd.EvaluationError, match="Painlevé"):
        s.evaluate([1.0], [1.0])
    res = s.simulate((0, 1), [1.0], [0.0])  # stops where it starts to move, and says why
    assert res.status == "interrupted" and "Painlevé" in res.message and res.t[-1] < 1e-3


def test_friction_element_is_checked():
    x, m = jd.symbols("x m")
    body = jd.Body("b", "world", jd.Prismatic("slide", x, "x"), mass=m, inertia=jd.point_mass())
    with pytest.raises(jd.ModelError, match='unknown joint "slid"'):
        jd.System([x], [body], [jd.JointFriction("f", "slid", 0.3, "F_y")], {"m": 1.0})
    with pytest.raises(jd.ModelError, match="parameters only"):
        jd.System([x], [body], [jd.JointFriction("f", "slide", "x", "F_y")], {"m": 1.0})
    with pytest.raises(jd.ModelError, match="v_eps"):
        jd.System([x], [body], [jd.JointFriction("f", "slide", 0.3, "F_y", v_eps=0)],
                  {"m": 1.0})
    s = jd.System([x], [body], [jd.JointFriction("f", "slide", 0.3, "F_x")], {"m": 1.0})
    with pytest.raises(jd.ModelError, match="slide.F_x is not a reaction component"):
        s.evaluate([0], [1])
    with pytest.raises(jd.ModelError, match="not linearized"):
        incline(0.3, 0.2).linearize({"x": 0})


def test_model_file_errors_are_located():
    bad = BOX_TOML.replace('joint = "ground"', 'joint = "grund"')
    with pytest.raises(ModelFileError, match='unknown joint "grund"') as e:
        loads_model(bad)
    assert e.value.line == BOX_TOML.splitlines().index('joint = "ground"') + 1
    with pytest.raises(ModelFileError, match="parameters only"):
        loads_model(BOX_TOML.replace('mu = "mu"', 'mu = "x"'))


@pytest.mark.parametrize("push", [10.0, "10 + 0*t", ((0.0, 5.0), (10.0, 10.0)),
                                  lambda t: 10.0, lambda t, y, yd: 10.0])
def test_inputs_reach_the_friction_forces(push):
    """The push as an input (number, expression, table, callable, state feedback): the normal
    force, and so the friction, are solved with it at every evaluation."""
    x, m, g, f, mu = jd.symbols("x m g F mu")
    s = jd.System(
        [x], [jd.Body("box", "world", jd.Prismatic("ground", x, "x"), mass=m,
                      inertia=jd.point_mass())],
        [jd.Gravity((0, -g, 0)), jd.Force("push", "box", (f, -f, 0)),
         jd.JointFriction("friction", "ground", mu, "F_y")],
        parameters={"m": 2.0, "g": G, "mu": 0.3}, inputs=[f])
    a = 10.0 / 2.0 - 0.3 * (2.0 * G + 10.0) / 2.0  # pushed down too: N = m·g + F
    out = s.evaluate([0.0], [0.5], inputs={"F": 10.0})
    _close(out["ydd"], [a], out)
    res = s.simulate((0, 1), [0.0], [0.5], inputs={"F": push}, rtol=1e-10, atol=1e-12,
                     t_eval=[0, 0.5, 1])
    np.testing.assert_allclose(res.y[:, 0], 0.5 * res.t + a * res.t**2 / 2, rtol=1e-8)


def test_a_study_runs_the_friction_per_case(tmp_path):
    """A study of μ: each case is System.simulate with the friction (the ensemble driver's
    compiled equations have none), the final positions at the closed form."""
    pytest.importorskip("xarray")
    pytest.importorskip("h5netcdf")
    from jourdain.study import StudyError, loads_study, run_study

    (tmp_path / "box.toml").write_text(BOX_TOML + "[simulation]\nyd0 = { x = 0.5 }\n")
    study = ('[study]\nmodel = "box.toml"\ndesign = "grid"\n[vary.mu]\n'
             "range = { start = 0.1, stop = 0.4, num = 4 }\n")
    ds = run_study(loads_study(study + "[compute.simulate]\nt_end = 1.0\nsamples = 3\n"
                               "rtol = 1e-10\natol = 1e-12\nfinal = true\n", base=tmp_path),
                   workers=1)
    mu = np.linspace(0.1, 0.4, 4)
    np.testing.assert_allclose(ds.final.values[:, 0], 0.5 + (10.0 / 2.0 - mu * G) / 2, rtol=1e-8)
    with pytest.raises(StudyError, match="joint friction"):
        run_study(loads_study(study + "[compute.evaluate]\n", base=tmp_path), workers=1)


def test_commands_on_a_model_file_with_friction(tmp_path, capsys):
    """jourdain check lists the element, eval --json has q and g with the friction and says
    why there is no linearization, simulate writes the friction force as a column."""
    import json

    from jourdain.cli import main

    path = tmp_path / "box.toml"
    path.write_text(BOX_TOML + "[simulation]\nt_end = 1.0\nyd0 = { x = 0.5 }\n")
    assert main(["check", str(path)]) == 0
    assert "friction (JointFriction)" in capsys.readouterr().out
    assert main(["eval", str(path), "--at", "x_d=0.5", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    np.testing.assert_allclose(out["values"]["q"], [10.0 - 0.3 * 2.0 * G], rtol=1e-14)
    np.testing.assert_allclose(out["values"]["g"][0], 2.0 * G, rtol=1e-14)
    assert "joint friction" in out["not_available"]["K"]
    csv = tmp_path / "run.csv"
    assert main(["simulate", str(path), "--out", str(csv)]) == 0
    header = next(line for line in csv.read_text().splitlines() if not line.startswith("#"))
    assert "friction" in header.split(",")
