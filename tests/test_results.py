"""Results: energies and reaction forces along a motion against closed forms, files that other
tools read (HDF5 via h5py, CSV), plots with labelled axes."""

import csv
import math

import matplotlib
import numpy as np
import pytest

import jourdain as jd
from jourdain.models import double_pendulum, n_link_pendulum_on_cart
from tests.test_simulate import pendulum
from tests.tolerance import reactions_tol

matplotlib.use("Agg")


@pytest.fixture(scope="module")
def run():
    s = pendulum()
    return s, s.simulate((0, 2), [1.2], [0.5], rtol=1e-10, atol=1e-10,
                         t_eval=np.linspace(0, 2, 41))


def test_energies_and_positions_closed_form(run):
    s, res = run
    m, l, g = 1.5, 0.8, 9.81
    phi, w = res.y[:, 0], res.yd[:, 0]
    np.testing.assert_allclose(res.kinetic_energy, 0.5 * m * l**2 * w**2, rtol=1e-12)
    np.testing.assert_allclose(res.potential_energy, -m * g * l * np.cos(phi), rtol=1e-12)
    r = res.positions("bob", "com")
    np.testing.assert_allclose(r, np.c_[l * np.sin(phi), -l * np.cos(phi), 0 * phi], atol=1e-14)
    np.testing.assert_allclose(res.positions("bob"), 0.0, atol=1e-15)  # the pivot


def test_reaction_force_closed_form(run):
    """The pivot force on the bob is m(a − g) with a = l(φ̈ cos φ − φ̇² sin φ, φ̈ sin φ + φ̇² cos φ)."""
    _, res = run
    m, l, gr = 1.5, 0.8, 9.81
    phi, w, a = res.y[:, 0], res.yd[:, 0], res.ydd[:, 0]
    acc = l * np.c_[a * np.cos(phi) - w**2 * np.sin(phi), a * np.sin(phi) + w**2 * np.cos(phi)]
    F = m * (acc - np.array([0.0, -gr]))
    names = res.g_names
    Fx, Fy = res.g[:, names.index("pivot.F_x")], res.g[:, names.index("pivot.F_y")]
    # components in the joint frame; the magnitude does not depend on the frame
    np.testing.assert_allclose(np.hypot(Fx, Fy), np.hypot(F[:, 0], F[:, 1]), rtol=1e-9)


def test_kinetic_energy_matches_mass_matrix():
    """T from body velocities equals ½ ẏᵀ M ẏ (M from the projection) for a scleronomic model."""
    s = double_pendulum()
    res = s.simulate((0, 1), [0.5, -0.4], [1.0, 2.0], t_eval=np.linspace(0, 1, 5))
    for i in range(5):
        M = s.evaluate(res.y[i], res.yd[i])["M"]
        assert res.kinetic_energy[i] == pytest.approx(0.5 * res.yd[i] @ M @ res.yd[i], rel=1e-12)


def test_hdf5_round_trip_readable_by_h5py(run, tmp_path):
    import h5py

    _, res = run
    path = res.save(tmp_path / "pendulum.h5")
    with h5py.File(path) as h:  # what another tool sees
        assert h.attrs["format"] == "jourdain-results"
        np.testing.assert_array_equal(h["t"][()], res.t)
        assert h["y"].attrs["columns"] == '["phi"]'
        np.testing.assert_array_equal(h["T"][()], res.kinetic_energy)
    back = jd.Results.load(path)
    for k in ("t", "y", "yd", "ydd", "u", "W"):
        np.testing.assert_array_equal(getattr(back, k), getattr(res, k))
    np.testing.assert_array_equal(back.kinetic_energy, res.kinetic_energy)
    assert back.parameters == res.parameters and back.units["phi"] == "rad"
    with pytest.raises(jd.JourdainError, match="needs the system"):
        _ = back.g
    with_system = jd.Results.load(path, system=pendulum())
    np.testing.assert_allclose(with_system.g, res.g)


def test_csv_round_trip_readable_by_csv_module(tmp_path):
    s = n_link_pendulum_on_cart(1)
    res = s.simulate((0, 1), [0.0, 3.0], [0, 0], inputs={"F": 1.0}, t_eval=[0, 0.5, 1])
    path = res.save(tmp_path / "cart.csv")
    rows = [r for r in csv.reader(line for line in path.open() if not line.startswith("#"))]
    assert rows[0][:6] == ["t", "q0", "q1", "q0_d", "q1_d", "q0_dd"]
    assert "F" in rows[0] and "T" in rows[0]
    assert float(rows[2][0]) == 0.5 and float(rows[2][2]) == res.y[1, 1]
    back = jd.Results.load(path)
    np.testing.assert_array_equal(back.y, res.y)
    np.testing.assert_array_equal(back.u, res.u)
    with pytest.raises(jd.EvaluationError, match="unknown results file type"):
        res.save(tmp_path / "cart.xlsx")


def test_plots_have_labelled_axes(run):
    _, res = run
    ax = res.plot()
    assert ax.get_xlabel() == "t / s" and ax.get_ylabel() == "phi / rad"
    assert ax.get_legend().get_texts()[0].get_text() == "phi / rad"
    ax = res.plot("yd")
    assert ax.get_ylabel() == "phi_d / (rad/s)"
    ax = res.plot("energy")
    assert ax.get_ylabel() == "energy / J"
    ax = res.plot_phase("phi")
    assert ax.get_xlabel() == "phi / rad" and ax.get_ylabel() == "phi_d / (rad/s)"
    with pytest.raises(jd.EvaluationError, match="unknown coordinate"):
        res.plot_phase("theta")
    ax = res.plot("g")
    assert [t.get_text() for t in ax.get_legend().get_texts()][:2] == ["pivot.F_x / N",
                                                                       "pivot.F_y / N"]
    ax = res.plot_path("bob", "xy", point="com")
    x, y = ax.get_lines()[0].get_data()
    np.testing.assert_allclose(np.hypot(x, y), 0.8, rtol=1e-12)  # on the circle of radius l
    assert ax.get_xlabel() == "x / m"


def test_conservative_run_reports_drift(run):
    _, res = run
    E = res.total_energy
    assert res.energy_drift == pytest.approx(np.abs(E - E[0]).max() / max(abs(E[0]),
                                             res.kinetic_energy.max()))
    assert res.energy_drift < 1e-9
    assert math.isfinite(res.wall_time) and res.nfev > 0
    text = res.summary()
    assert "finished" in text and f"relative energy drift {res.energy_drift:.3e}" in text


def test_spring_potentials_and_energy_conservation():
    """Elastic pendulum (a point mass on a linear spring hung from the origin, planar polar
    coordinates) with a torsion spring on the angle: V = ½ c (L − L0)² + ½ k φ² − m g·r."""
    phi, r, m, c, L0, k, g = jd.symbols("phi r m c L0 k g")
    arm = jd.Body("arm", "world", jd.Revolute("pivot", phi, "z"), mass=0,
                  inertia=jd.point_mass())
    bob = jd.Body("bob", "arm", jd.Prismatic("slide", r, "x"), mass=m, inertia=jd.point_mass())
    s = jd.System([phi, r], [arm, bob],
                  [jd.Gravity((0, -g, 0)), jd.SpringDamper("spring", "world", (0, 0, 0), "bob",
                                                           (0, 0, 0), stiffness=c,
                                                           rest_length=L0),
                   jd.RotationalSpringDamper("torsion", phi, stiffness=k)],
                  parameters={"m": 0.5, "c": 40.0, "L0": 1.0, "k": 2.0, "g": 9.81})
    res = s.simulate((0, 3), [-1.2, 1.3], [0.5, 0.0], rtol=1e-11, atol=1e-11)
    assert res.conservative
    ph, rr = res.y[:, 0], res.y[:, 1]
    V = 0.5 * 40 * (rr - 1.0) ** 2 + 0.5 * 2.0 * ph**2 + 0.5 * 9.81 * rr * np.sin(ph)
    np.testing.assert_allclose(res.potential_energy, V, rtol=1e-12, atol=1e-12)
    T = 0.5 * 0.5 * (res.yd[:, 1] ** 2 + rr**2 * res.yd[:, 0] ** 2)
    np.testing.assert_allclose(res.kinetic_energy, T, rtol=1e-12, atol=1e-12)
    assert res.energy_drift < 1e-9
    # a damper makes it non-conservative; the balance T + V − W_nc stays constant
    s2 = jd.System(s.coordinates, s.bodies,
                   [*s.forces[:2], jd.RotationalSpringDamper("torsion", phi, 2.0, 0.3)],
                   parameters=s.parameter_values)
    res2 = s2.simulate((0, 3), [-1.2, 1.3], [0.5, 0.0], rtol=1e-11, atol=1e-11)
    assert not res2.conservative and res2.energy_balance_error < 1e-9
    assert res2.work_nonconservative[-1] < -0.01


def test_batched_reactions_equal_single_state_evaluation():
    from jourdain.models import spatial_chain

    s = spatial_chain(3)
    res = s.simulate((0, 1), [0.2] * s.f, [0.1] * s.f, t_eval=np.linspace(0, 1, 4))
    for i in range(4):
        ref = s.evaluate(res.y[i], res.yd[i], res.t[i])  # two solves of N̂·g = k̂ − q̂
        np.testing.assert_allclose(res.g[i], ref["g"], rtol=0, atol=2 * reactions_tol(ref))
    assert res.g_names == ref["g_names"]


# --- sampling and the motion between the samples (issue 17, item 8) ---------------------------
#: a plot resolves about a thousandth of its height
PLOT_RESOLUTION = 1e-3


def test_default_run_plots_smooth_curves():
    """Without t_eval the results hold the integrator's steps (here about 0.2 s apart, a
    tenth of the period: straight lines between them miss the curve by 4 % of the amplitude).
    The plot draws the interpolated motion on PLOT_POINTS times plus the steps."""
    from jourdain.simulation.results import PLOT_POINTS

    s = pendulum()
    res = s.simulate((0, 10), [1.0], [0.0])
    period = 2 * np.pi * np.sqrt(0.8 / 9.81)  # small-amplitude period, slightly short at 1 rad
    assert np.diff(res.t).max() > period / 20  # the steps alone are coarse
    for what, col in (("y", "y"), ("yd", "yd")):
        x, y = res.plot(what).get_lines()[0].get_data()
        assert len(x) >= PLOT_POINTS and np.diff(x).max() <= 10.0 / (PLOT_POINTS - 1) * (1 + 1e-12)
        assert len(x) * period / 10.0 >= 100  # points per period
        assert set(res.t) <= set(x)
        ref = s.simulate((0, 10), [1.0], [0.0], rtol=1e-12, atol=1e-12, t_eval=x)
        dev = np.abs(y - getattr(ref, col)[:, 0]).max() / np.abs(getattr(ref, col)).max()
        assert dev < PLOT_RESOLUTION, what
    straight = np.interp(x, res.t, res.yd[:, 0])  # what the plot drew before
    assert np.abs(straight - ref.yd[:, 0]).max() / np.abs(ref.yd).max() > PLOT_RESOLUTION
    x, _ = res.plot_phase("phi").get_lines()[0].get_data()
    assert len(x) >= PLOT_POINTS
    x, _ = res.plot("energy").get_lines()[0].get_data()
    assert len(x) >= PLOT_POINTS
    x, _ = res.plot_path("bob", point="com").get_lines()[0].get_data()
    assert len(x) >= PLOT_POINTS


def test_interpolate_is_exact_at_the_samples_and_of_sixth_order_between():
    s = pendulum()
    res = s.simulate((0, 3), [1.0], [0.0], rtol=1e-10, atol=1e-12)
    at = res.interpolate(res.t)
    for k in ("y", "yd", "ydd"):
        np.testing.assert_allclose(at[k], getattr(res, k), rtol=1e-13, atol=1e-13)
    # halving the steps (t_eval on every step and midpoint gives them to the interpolation)
    # divides the error between samples by about 2⁶
    mid = 0.5 * (res.t[1:] + res.t[:-1])
    fine = s.simulate((0, 3), [1.0], [0.0], rtol=1e-10, atol=1e-12,
                      t_eval=np.sort(np.r_[res.t, mid]))
    quarter = 0.5 * (res.t[1:] + mid)
    ref = s.simulate((0, 3), [1.0], [0.0], rtol=1e-13, atol=1e-13, t_eval=quarter)
    coarse_err = np.abs(res.interpolate(quarter)["y"] - ref.y).max()
    fine_err = np.abs(fine.interpolate(quarter)["y"] - ref.y).max()
    assert fine_err < coarse_err / 16
    with pytest.raises(jd.EvaluationError, match="within the run"):
        res.interpolate([3.5])


# --- energy balance for every model, events (issue 17, item 10) -------------------------------
def test_energy_balance_is_a_number_for_every_model(tmp_path):
    damped = pendulum(damping=0.3).simulate((0, 5), [1.0], [0.0], rtol=1e-10, atol=1e-10)
    assert damped.energy_drift is None  # the conservative special case only
    assert isinstance(damped.energy_balance_error, float) and damped.energy_balance_error < 1e-8
    assert "energy balance error" in damped.summary()
    back = jd.Results.load(damped.save(tmp_path / "damped.h5"))  # T, V from the file
    assert back.energy_balance_error == pytest.approx(damped.energy_balance_error, rel=1e-6)
    conservative = pendulum().simulate((0, 2), [1.2], [0.5], rtol=1e-10, atol=1e-10)
    assert conservative.energy_balance_error <= 2 * conservative.energy_drift + 1e-15
    np.testing.assert_array_equal(conservative.work_drive, 0.0)


def test_energy_balance_includes_the_work_of_a_prescribed_motion():
    """A bead on a rod turned at Ω: T = ½m(ẋ² + Ω²x²), ẍ = Ω²x, so the drive does
    W = mΩ²(x² − x0²). It used to be left out, and the 'balance error' was 0.5."""
    x, m, W = jd.symbols("x m Omega")
    rod = jd.Body("rod", "world", jd.General("drive", [jd.Rot("z", W * jd.t)], coordinates=[]),
                  mass=0, inertia=jd.point_mass())
    bead = jd.Body("bead", "rod", jd.Prismatic("slot", x, "x"), mass=m, inertia=jd.point_mass())
    s = jd.System([x], [rod, bead], [], parameters={"m": 0.3, "Omega": 2.0})
    r = s.simulate((0, 1.5), [0.1], [0.05], rtol=1e-11, atol=1e-12)
    assert r.rheonomic and not r.conservative and r.energy_drift is None
    exact = 0.3 * 4.0 * (r.y[:, 0] ** 2 - 0.1**2)
    # three-point Gauss along the interpolated motion: error of the interpolation's order
    np.testing.assert_allclose(r.work_drive, exact, rtol=1e-7, atol=1e-7 * exact.max())
    assert r.energy_balance_error < 1e-7
    assert "prescribed (rheonomic) motion's drive" in r.summary()
    labels = [ln.get_label() for ln in r.plot("energy").get_lines()]
    assert "W_drive (work of the prescribed motion)" in labels


def test_events_hold_every_event_even_without_crossings():
    s = pendulum()
    phi = s.y[0]
    res = s.simulate((0, 2), [1.0], [0.0], events=[
        jd.Event(phi, direction=-1, name="down"), jd.Event(phi - 5, name="never")])
    assert set(res.events) == {"down", "never"}
    assert res.events["never"]["t"].shape == (0,) and res.events["never"]["y"].shape == (0, 1)
    t_down = res.events["down"]["t"]
    assert len(t_down) >= 1 and np.all(np.abs(res.interpolate(t_down)["y"][:, 0]) < 1e-5)
    assert "events" in jd.Results.__doc__ and "terminal" in jd.Results.__doc__


def test_plotted_nonconservative_work_leaves_out_the_drives_work():
    """The pendulum on a vertically shaken pivot has only conservative forces, so W_nc = 0;
    its potential changes with t, and the plot's W_nc must subtract ∫∂V/∂t dt as
    work_nonconservative does (left out, the plot showed the drive's work: 1.18 J with
    T ≤ 15 J). Between samples the plot interpolates by cubic Hermite, whose error at this
    fast excitation is about 1e-5 of T; the bound is ten times that."""
    from pathlib import Path

    from jourdain.io.modelfile import load_model

    m = load_model(Path(__file__).parents[1] / "examples" / "parametric_pendulum.toml")
    res = m.system.simulate((0, 2), m.simulation.y0, m.simulation.yd0, rtol=1e-10,
                            atol=1e-12)
    _, T, _, W_nc, _ = res._energies_to_plot()
    assert np.abs(res.work_nonconservative).max() <= 1e-6 * np.abs(T).max()
    assert np.abs(W_nc).max() <= 1e-4 * np.abs(T).max()
