"""Simulation: closed forms (pendulum period with the complete elliptic integral), energy
conservation, events, inputs of every kind, stiff methods, and clear errors."""

import math

import numpy as np
import pytest
import symengine as se
from scipy.special import ellipk

import jourdain as jd
from jourdain.models import n_link_pendulum_on_cart, spatial_chain
from jourdain.simulation.simulate import Event, IntegrationError
from tests.tolerance import assert_residual_small, eom_terms, norm


def pendulum(damping: float = 0.0) -> jd.System:
    """Point mass m on a massless rod of length l; phi from the downward vertical."""
    phi, m, l, g = jd.symbols("phi m l g")
    bob = jd.Body("bob", "world", jd.Revolute("pivot", phi, "z"), mass=m, com=(0, -l, 0),
                  inertia=jd.point_mass())
    forces: list = [jd.Gravity((0, -g, 0))]
    if damping:
        forces.append(jd.RotationalSpringDamper("friction", phi, damping=damping))
    return jd.System([phi], [bob], forces, parameters={"m": 1.5, "l": 0.8, "g": 9.81},
                     units={"phi": "rad", "m": "kg", "l": "m", "g": "m/s^2"}, name="pendulum")


def test_pendulum_period_from_90_degrees_elliptic_integral():
    """T = 4 sqrt(l/g) K(k²), k = sin(φ0/2) (exact large-amplitude period)."""
    s = pendulum()
    phi = s.y[0]
    l, g = 0.8, 9.81
    T_exact = 4 * math.sqrt(l / g) * ellipk(math.sin(math.pi / 4) ** 2)
    res = s.simulate((0, 3.5 * T_exact), [math.pi / 2], [0.0], rtol=1e-11, atol=1e-11,
                     events=[Event(phi, direction=+1, name="upward zero crossing")])
    times = res.events["upward zero crossing"]["t"]
    # released at rest at +90°: φ first crosses zero going down at T/4, upward at 3T/4
    assert len(times) == 3
    np.testing.assert_allclose(times[0], 0.75 * T_exact, rtol=1e-9)
    np.testing.assert_allclose(np.diff(times), T_exact, rtol=1e-9)
    # energy of a conservative model is conserved; the drift is reported
    assert res.conservative and res.energy_drift < 1e-9


def test_spatial_chain_6_energy_conservation():
    s = spatial_chain(6)
    rng = np.random.default_rng(3)
    y0, yd0 = rng.uniform(-1, 1, s.f), rng.uniform(-1, 1, s.f)
    res = s.simulate((0, 2.0), y0, yd0, rtol=1e-12, atol=1e-12)
    assert res.conservative
    assert res.energy_drift < 1e-8
    # the work of the applied forces (gravity) integrated with the motion is -ΔV
    np.testing.assert_allclose(res.W, -(res.potential_energy - res.potential_energy[0]),
                               atol=1e-8 * np.abs(res.potential_energy).max())
    # ÿ of the results solves M ÿ + k = q at every output point (backward error: M, q, k
    # evaluated again here, so the terms of q and k bound the right-hand side's rounding)
    i = len(res.t) // 2
    out = s.evaluate(res.y[i], res.yd[i], res.t[i])
    assert_residual_small(out["M"], res.ydd[i], out["q"] - out["k"],
                          b_scale=sum(norm(t) for t in eom_terms(out)))


def test_damped_pendulum_energy_balance():
    s = pendulum(damping=0.3)
    res = s.simulate((0, 5), [1.0], [0.0], rtol=1e-10, atol=1e-10, t_eval=np.linspace(0, 5, 501))
    assert not res.conservative and res.energy_drift is None
    # the friction torque -d·φ̇ does the work -∫ d φ̇² dt (trapezoid on the dense output)
    w_ref = -np.concatenate([[0], np.cumsum(np.diff(res.t) * 0.3 * 0.5 * (
        res.yd[1:, 0] ** 2 + res.yd[:-1, 0] ** 2))])
    np.testing.assert_allclose(res.work_nonconservative, w_ref, atol=2e-4)
    assert res.energy_balance_error < 1e-8


def test_dense_output_and_methods_agree():
    s = n_link_pendulum_on_cart(2)
    y0 = [0.1, math.pi + 0.2, math.pi - 0.2]
    te = np.linspace(0, 3, 31)
    ref = s.simulate((0, 3), y0, [0, 0, 0], inputs={"F": 0.0}, rtol=1e-12, atol=1e-12, t_eval=te)
    np.testing.assert_array_equal(ref.t, te)
    for method, tol in (("DOP853", 1e-6), ("RK45", 1e-5), ("Radau", 1e-6), ("BDF", 1e-3),
                        ("scipy:Radau", 1e-6)):
        r = s.simulate((0, 3), y0, [0, 0, 0], inputs={"F": 0.0}, method=method, rtol=1e-8,
                       atol=1e-8, t_eval=te)
        np.testing.assert_allclose(r.y, ref.y, atol=tol, err_msg=method)


def test_radau_in_c_on_a_stiff_oscillator():
    """Overdamped mass on a stiff spring-damper: x'' + 1e4 x' + 1e6 x = 0 has the eigenvalues
    s = -5e3 ± sqrt(25e6 - 1e6); the implicit method needs far fewer evaluations."""
    x, m = jd.symbols("x m")
    body = jd.Body("slider", "world", jd.Prismatic("rail", x, "x"), mass=m,
                   inertia=jd.point_mass())
    s = jd.System([x], [body], [jd.RotationalSpringDamper("mount", x, 1e6, 1e4)],
                  parameters={"m": 1.0})
    r1, r2 = -5e3 + math.sqrt(24e6), -5e3 - math.sqrt(24e6)
    A = -r2 / (r1 - r2)  # x(0) = 1, x'(0) = 0
    B = 1 - A
    te = np.concatenate([np.linspace(0.005, 0.1, 20), [2.0]])
    exact = A * np.exp(r1 * te) + B * np.exp(r2 * te)
    rad = s.simulate((0, 2), [1.0], [0.0], method="Radau", rtol=1e-8, atol=1e-10, t_eval=te)
    np.testing.assert_allclose(rad.y[:, 0], exact, rtol=1e-6, atol=1e-10)
    dop = s.simulate((0, 2), [1.0], [0.0], method="DOP853", rtol=1e-8, atol=1e-10, t_eval=te)
    np.testing.assert_allclose(dop.y[:, 0], exact, rtol=1e-6, atol=1e-10)
    # after the transient the explicit method is held to tiny steps by stability alone
    assert rad.nfev * 5 < dop.nfev


def test_bead_on_a_rod_turned_at_constant_rate():
    """Rheonomic: a rod driven by R_z(Ω t), a bead sliding on it: ẍ = Ω² x, so
    x = x0 cosh(Ω t) + v0/Ω sinh(Ω t)."""
    x, m, W = jd.symbols("x m Omega")
    rod = jd.Body("rod", "world", jd.General("drive", [jd.Rot("z", W * jd.t)], coordinates=[]),
                  mass=0, inertia=jd.point_mass())
    bead = jd.Body("bead", "rod", jd.Prismatic("slot", x, "x"), mass=m, inertia=jd.point_mass())
    s = jd.System([x], [rod, bead], [], parameters={"m": 0.3, "Omega": 2.0})
    te = np.linspace(0, 1.5, 16)
    for method in ("DOP853", "Radau"):
        r = s.simulate((0, 1.5), [0.1], [0.05], rtol=1e-11, atol=1e-12, t_eval=te,
                       method=method)
        exact = 0.1 * np.cosh(2 * te) + 0.05 / 2 * np.sinh(2 * te)
        np.testing.assert_allclose(r.y[:, 0], exact, rtol=1e-8, err_msg=method)
    # T includes the rheonomic terms: ½ m (ẋ² + Ω² x²)
    np.testing.assert_allclose(r.kinetic_energy, 0.15 * (r.yd[:, 0] ** 2 + 4 * r.y[:, 0] ** 2),
                               rtol=1e-12)
    assert not r.conservative and r.rheonomic
    assert r.energy_balance_error < 1e-7  # the drive's work is in the balance
    assert "rheonomic" in r.summary()


def test_inputs_constant_expression_table_callable_agree():
    s = n_link_pendulum_on_cart(1)
    t = se.Symbol("t")
    y0, yd0 = [0.0, math.pi + 0.1], [0.0, 0.0]
    kw = {"rtol": 1e-10, "atol": 1e-10, "t_eval": np.linspace(0, 2, 21)}
    expr = s.simulate((0, 2), y0, yd0, inputs={"F": 2 * se.sin(3 * t)}, **kw)
    call = s.simulate((0, 2), y0, yd0, inputs={"F": lambda tt: 2 * math.sin(3 * tt)}, **kw)
    tt = np.linspace(0, 2, 4001)
    table = s.simulate((0, 2), y0, yd0, inputs={"F": (tt, 2 * np.sin(3 * tt))}, **kw)
    np.testing.assert_allclose(call.y, expr.y, atol=1e-9)
    np.testing.assert_allclose(table.y, expr.y, atol=1e-5)
    np.testing.assert_allclose(expr.u[:, 0], 2 * np.sin(3 * expr.t), atol=1e-15)
    const = s.simulate((0, 2), y0, yd0, inputs={"F": 0.0}, **kw)
    assert np.abs(const.y - expr.y).max() > 1e-3  # the force does act
    # state feedback compiled into the loop: a damper on the cart, F = -c·q0_d
    c = 4.0
    fb = s.simulate((0, 2), y0, [1.0, 0.0], inputs={"F": -c * s.yd[0]}, **kw)
    np.testing.assert_allclose(fb.u[:, 0], -c * fb.yd[:, 0], rtol=1e-12)
    # the same feedback as a Python function of the state
    py = s.simulate((0, 2), y0, [1.0, 0.0], inputs={"F": lambda t, y, yd: -c * yd[0]}, **kw)
    np.testing.assert_allclose(py.y, fb.y, atol=1e-9)
    np.testing.assert_allclose(py.u, fb.u, atol=1e-8)


@pytest.mark.parametrize("method", ["DOP853", "RK45", "Radau"])
def test_terminal_event_stops_the_run(method):
    s = pendulum()
    phi = s.y[0]
    res = s.simulate((0, 10), [1.0], [0.0], rtol=1e-10, atol=1e-10, method=method,
                     events=[Event(phi, direction=-1, terminal=True, name="bottom")])
    assert res.status == "event" and "bottom" in res.message
    t_hit = res.events["bottom"]["t"][0]
    assert res.t[-1] == t_hit and abs(res.y[-1, 0]) < 1e-9
    # quarter period of a 1 rad pendulum
    T = 4 * math.sqrt(0.8 / 9.81) * ellipk(math.sin(0.5) ** 2)
    np.testing.assert_allclose(t_hit, T / 4, rtol=1e-8)


def test_singular_mass_matrix_names_time_and_state():
    """A Cardan joint at gimbal lock (second angle ±90°) has a singular M."""
    a, b, c = jd.symbols("a b c")
    body = jd.Body("ball", "world", jd.Spherical("socket", [a, b, c], "xyz"), mass=1.0,
                   com=(0, 0, -0.5), inertia=jd.box(1.0, 0.1, 0.2, 0.3))
    s = jd.System([a, b, c], [body], [jd.Gravity((0, 0, -9.81))], name="ball")
    with pytest.raises(jd.SingularMassMatrix, match=r"t = 0.*b=1\.5708") as info:
        s.simulate((0, 1), [0.1, math.pi / 2, 0.2], [0, 0, 0])
    res = info.value.results  # the initial state; no acceleration there
    assert res.t.tolist() == [0.0] and np.isnan(res.ydd).all()


def test_nan_and_bad_arguments_give_clear_errors():
    s = n_link_pendulum_on_cart(1)
    y0 = [0.0, 3.0]
    with pytest.raises(jd.EvaluationError, match="NaN"):
        s.simulate((0, 1), [0.0, np.nan], [0, 0], inputs={"F": 0.0})
    with pytest.raises(jd.EvaluationError, match="not finite"):
        s.simulate((0, 1), y0, [0, 0], inputs={"F": float("nan")})
    with pytest.raises(jd.EvaluationError, match="'F': 0.0"):
        s.simulate((0, 1), y0, [0, 0])
    with pytest.raises(jd.EvaluationError, match="unknown method"):
        s.simulate((0, 1), y0, [0, 0], inputs={"F": 0.0}, method="Euler")
    with pytest.raises(jd.EvaluationError, match="t1 > t0"):
        s.simulate((1, 0), y0, [0, 0], inputs={"F": 0.0})
    with pytest.raises(IntegrationError, match=r"NaN.*t = 0\.5"):
        s.simulate((0, 1), y0, [0, 0], inputs={"F": lambda t: np.nan if t >= 0.5 else 0.0})
    with pytest.raises(TypeError, match="tolerance"):  # misspelt options are not ignored
        s.simulate((0, 1), y0, [0, 0], inputs={"F": 0.0}, tolerance=1e-3)
    with pytest.raises(jd.EvaluationError, match="max_step must be positive"):
        s.simulate((0, 1), y0, [0, 0], inputs={"F": 0.0}, max_step=0)
    with pytest.raises(jd.EvaluationError, match=r"expected 1 values for \['F'\]"):
        s.simulate((0, 1), y0, [0, 0], inputs=[0.0, 1.0])
    with pytest.raises(jd.EvaluationError, match='unknown input'):
        s.simulate((0, 1), y0, [0, 0], inputs={"F": 0.0, "G": 1.0})
    with pytest.raises(jd.EvaluationError, match="table times must increase"):
        s.simulate((0, 1), y0, [0, 0], inputs={"F": ([0.0, 0.0, 1.0], [1.0, 2.0, 3.0])})
    with pytest.raises(jd.EvaluationError, match=r"input expressions may use"):
        s.simulate((0, 1), y0, [0, 0], inputs={"F": se.Symbol("w") * 2})
    with pytest.raises(jd.EvaluationError, match="unknown symbol"):
        s.simulate((0, 1), y0, [0, 0], inputs={"F": 0.0}, events=[Event(se.Symbol("zz"))])


def test_exception_in_input_function_keeps_results():
    s = n_link_pendulum_on_cart(1)

    def force(t: float) -> float:
        if t > 0.5:
            raise RuntimeError("sensor failed")
        return 1.0

    res = s.simulate((0, 2), [0.0, 3.0], [0, 0], inputs={"F": force}, max_step=0.05)
    assert res.interrupted and "sensor failed" in res.message
    assert 0.4 < res.t[-1] <= 0.5 and len(res.t) > 9
    np.testing.assert_array_equal(res.u[:, 0], 1.0)


def test_ctrl_c_keeps_results(tmp_path):
    s = n_link_pendulum_on_cart(1)

    def force(t: float) -> float:
        if t > 0.7:
            raise KeyboardInterrupt
        return 0.0

    out = tmp_path / "run.h5"
    res = s.simulate((0, 2), [0.0, 3.0], [0, 0], inputs={"F": force}, output=str(out))
    assert res.interrupted and "Ctrl-C" in res.message
    assert 0.5 < res.t[-1] <= 0.7
    back = jd.Results.load(out)
    assert back.status == "interrupted"
    np.testing.assert_array_equal(back.y, res.y)
    with pytest.raises(KeyboardInterrupt):
        s.simulate((0, 2), [0.0, 3.0], [0, 0], inputs={"F": force}, raise_on_interrupt=True)


def test_progress_and_chunked_output(tmp_path):
    s = n_link_pendulum_on_cart(1)
    seen = []
    kw = {"inputs": {"F": 0.0}, "rtol": 1e-9, "atol": 1e-9}
    # tiny steps: many chunks of the C loop, written to the file as they come
    res = s.simulate((0, 20), [0.0, 3.0], [0, 0], max_step=5e-4, output=str(tmp_path / "r.h5"),
                     progress=lambda t, t1: seen.append((t, t1)), **kw)
    assert res.status == "finished" and res.t[-1] == 20.0
    assert len(res.t) > 40000 and np.all(np.diff(res.t) > 0)
    assert len(seen) > 30 and all(b == 20.0 for _, b in seen)
    assert np.all(np.diff([a for a, _ in seen]) > 0)
    # chunking does not change the motion: one long run at the same step limit agrees
    whole = s.simulate((0, 20), [0.0, 3.0], [0, 0], max_step=5e-4, t_eval=[20.0], **kw)
    np.testing.assert_allclose(whole.y[-1], res.y[-1], atol=1e-9)
    back = jd.Results.load(tmp_path / "r.h5")
    np.testing.assert_array_equal(back.t, res.t)


def test_partial_file_of_a_killed_run_is_readable(tmp_path):
    """What a run killed by the system (no chance to finish the file) leaves behind."""
    from jourdain.simulation.results import append_incremental, open_incremental

    s = n_link_pendulum_on_cart(1)
    res = s.simulate((0, 1), [0.0, 3.0], [0, 0], inputs={"F": 0.0})
    h = open_incremental(tmp_path / "killed.h5", s)
    x = np.c_[res.y, res.yd, res.W]
    append_incremental(h, res.t[:10], x[:10])
    append_incremental(h, res.t[10:20], x[10:20])
    h.close()
    back = jd.Results.load(tmp_path / "killed.h5")
    assert back.status == "running" and "killed" in back.message
    np.testing.assert_array_equal(back.y, res.y[:20])
    np.testing.assert_array_equal(back.W, res.W[:20])


def test_failure_keeps_the_motion_up_to_it():
    """A point mass in polar coordinates (angle a, radius x) pulled to the centre by an
    overdamped spring: M = diag(m x², m) loses positive definiteness as x -> 0. The error names
    the time and state; the motion before it is on the exception."""
    a, x, m = jd.symbols("a x m")
    arm = jd.Body("arm", "world", jd.Revolute("pivot", a, "z"), mass=0, inertia=jd.point_mass())
    bead = jd.Body("bead", "arm", jd.Prismatic("slot", x, "x"), mass=m, inertia=jd.point_mass())
    s = jd.System([a, x], [arm, bead], [jd.RotationalSpringDamper("pull", x, 100.0, 25.0)],
                  parameters={"m": 1.0}, name="polar bead")
    # x'' + 25 x' + 100 x = 0 from x = 1, x' = 5: x(t) = exp(-5 t), which reaches
    # sqrt(1e-13) (the relative pivot limit of the Cholesky factorization) at t ≈ 3.0
    with pytest.raises(jd.SingularMassMatrix, match=r"polar bead.*t = 2\.9") as info:
        s.simulate((0, 10), [0.0, 1.0], [0.0, -5.0], rtol=1e-10, atol=1e-12)
    res = info.value.results
    assert res.status == "failed" and "not positive definite" in res.message
    assert 2.5 < res.t[-1] < 3.0
    np.testing.assert_allclose(res.y[:, 1], np.exp(-5 * res.t), rtol=1e-6, atol=1e-12)


def test_ctrl_c_during_the_c_loop_stops_between_chunks():
    """SIGINT while the C loop runs (raised here from an input function, synchronously): the
    run stops after the current chunk and keeps the motion."""
    import signal

    s = n_link_pendulum_on_cart(1)
    sent = []

    def force(t: float) -> float:
        if t > 0.7 and not sent:
            sent.append(t)
            signal.raise_signal(signal.SIGINT)
        return 0.0

    before = signal.getsignal(signal.SIGINT)
    res = s.simulate((0, 100), [0.0, 3.0], [0, 0], inputs={"F": force}, max_step=1e-3)
    assert sent and res.interrupted and "Ctrl-C" in res.message
    assert 0.7 < res.t[-1] < 3.0 and np.all(np.diff(res.t) > 0)
    assert signal.getsignal(signal.SIGINT) is before  # the handler is restored


class _Counting:
    """The integrator library with its jd_integrate calls counted."""

    def __init__(self, lib, calls: list) -> None:
        self._lib, self._calls = lib, calls

    def jd_integrate(self, *args):
        self._calls.append(1)
        return self._lib.jd_integrate(*args)


@pytest.mark.parametrize("method", ["DOP853", "RK45"])
def test_steps_do_not_depend_on_how_the_run_is_split(method, monkeypatch):
    """The C loop runs in calls of a few thousand steps (for Ctrl-C and progress); a run split
    into calls of 7 steps takes the very same steps as one in large calls, bit for bit (the
    step size, the FSAL stage and the rejection state are carried across calls). The number of
    steps per call never depends on the wall clock (issue 17: a chain under load once failed
    with a collapsed step)."""
    import importlib

    runs = importlib.import_module("jourdain.simulation.runs")  # where the C loop is called
    s = spatial_chain(3)
    rng = np.random.default_rng(3)
    y0, yd0 = rng.uniform(-1, 1, s.f), rng.uniform(-1, 1, s.f)
    big = s.simulate((0, 1.0), y0, yd0, method=method, rtol=1e-10, atol=1e-10)
    monkeypatch.setattr(runs, "steps_per_call", lambda f: 7)
    calls = []
    real = runs.integrator_library()
    monkeypatch.setattr(runs, "integrator_library", lambda: _Counting(real, calls))
    small = s.simulate((0, 1.0), y0, yd0, method=method, rtol=1e-10, atol=1e-10)
    assert len(calls) > big.n_accepted // 7  # the run did go in calls of 7 steps
    assert np.array_equal(big.t, small.t) and np.array_equal(big.y, small.y)
