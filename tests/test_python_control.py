"""python-control bridge (jourdain.analysis.python_control): the named StateSpace against a
closed form, jourdain's other linearization path and a finite difference of the nonlinear
right-hand side; an LQR design on pendula on a cart whose loop, closed in a jourdain
simulation, follows the linear closed loop that python-control predicts."""

import sys
from pathlib import Path

import control
import numpy as np
import pytest

import jourdain as jd
from jourdain.analysis import MissingDependency, state_feedback, to_control
from jourdain.models import n_link_pendulum_on_cart
from tests.tolerance import EPS, eig_with_tol, norm, solve_scale, solve_tol

UPRIGHT1 = {"q0": 0, "q1": 0}
UPRIGHT2 = {"q0": 0, "q1": 0, "q2": 0}


def _rhs(system, x, u, parameters):
    """The nonlinear right-hand side ẋ = [ẏ; M⁻¹(q − k)] at x = [y; ẏ] and inputs u."""
    from jourdain.numeric import evaluate

    f = system.f
    out = evaluate(system, x[:f], x[f:], parameters=parameters, inputs=list(u))
    return np.concatenate([x[f:], np.linalg.solve(out["M"], out["q"] - out["k"]).ravel()])


def test_names_and_closed_form_single_pendulum():
    """Cart m0 on x, point mass m1 on a massless rod l0 at θ = q1 from the upward vertical,
    force F on the cart. Linearized upright: (m0 + m1)·ẍ − m1·l·θ̈ = F and l·θ̈ − ẍ − g·θ = 0,
    so ẍ = (F + m1·g·θ)/m0 and θ̈ = (F + (m0 + m1)·g·θ)/(m0·l)."""
    s = n_link_pendulum_on_cart(1)
    pars = {"m0": 2.0, "m1": 0.7, "l0": 0.8, "g": 9.81}
    lin = s.linearize(UPRIGHT1)
    sc = to_control(lin, parameters=pars, outputs=["q0", "q1"])
    assert isinstance(sc, control.StateSpace)
    assert sc.state_labels == ["q0", "q1", "q0_d", "q1_d"]
    assert sc.input_labels == ["F"]
    assert sc.output_labels == ["q0", "q1"]
    assert sc.name == "1-link pendulum on a cart"
    m0, m1, l, g = pars["m0"], pars["m1"], pars["l0"], pars["g"]
    A = np.array([[0, 0, 1, 0], [0, 0, 0, 1], [0, m1 * g / m0, 0, 0],
                  [0, (m0 + m1) * g / (m0 * l), 0, 0]])
    B = np.array([[0], [0], [1 / m0], [1 / (m0 * l)]])
    ss = jd.state_space(lin, parameters=pars)
    # one solve with M̃ on our side, the closed form evaluated directly
    np.testing.assert_allclose(sc.A, A, rtol=0, atol=solve_tol(ss.M_tilde, norm(A)))
    np.testing.assert_allclose(sc.B, B, rtol=0, atol=solve_tol(ss.M_tilde, norm(B)))
    np.testing.assert_array_equal(sc.C, [[1, 0, 0, 0], [0, 1, 0, 0]])
    np.testing.assert_array_equal(sc.D, np.zeros((2, 1)))
    # all states as outputs when none are chosen; the StateSpace method gives the same system
    full = ss.to_control()
    assert full.output_labels == full.state_labels == sc.state_labels
    np.testing.assert_array_equal(full.C, np.eye(4))
    np.testing.assert_array_equal(full.A, sc.A)


def test_double_pendulum_against_numeric_path_and_finite_differences():
    """A and B of the symbolic linearization against the numeric path (linearize_numeric: other
    code, the same equations; both solve with M̃) and against central differences of the
    nonlinear right-hand side, whose error is truncation h²/6·|x'''| plus rounding
    eps·|ẋ|/h (both scaled by ‖[A, B]‖: the model's derivatives are all of that size)."""
    s = n_link_pendulum_on_cart(2)
    pars = {"m0": 1.5, "m1": 0.6, "m2": 0.4, "l0": 0.9, "l1": 0.5}
    sc = to_control(s.linearize(UPRIGHT2), parameters=pars)
    num = jd.state_space(jd.linearize_numeric(s, UPRIGHT2, parameters=pars))
    f = s.f
    for ours, ref, terms in ((sc.A[f:], num.A[f:], (num.Q, num.P)),
                             (sc.B[f:], num.B[f:], (num.B_u,))):
        tol = 2 * solve_tol(num.M_tilde, solve_scale(num.M_tilde, ref, terms))
        np.testing.assert_allclose(ours, ref, rtol=0, atol=tol)
    np.testing.assert_array_equal(sc.A[:f], num.A[:f])
    # finite differences about the upright equilibrium (x = 0, u = 0)
    h = 1e-5
    x0, u0 = np.zeros(2 * f), np.zeros(1)
    A_fd = np.column_stack([(_rhs(s, x0 + h * e, u0, pars) - _rhs(s, x0 - h * e, u0, pars))
                            / (2 * h) for e in np.eye(2 * f)])
    B_fd = ((_rhs(s, x0, u0 + h, pars) - _rhs(s, x0, u0 - h, pars)) / (2 * h))[:, None]
    scale = norm(np.hstack([sc.A, sc.B]))
    tol = 10 * (h**2 + EPS / h) * scale
    np.testing.assert_allclose(sc.A, A_fd, rtol=0, atol=tol)
    np.testing.assert_allclose(sc.B, B_fd, rtol=0, atol=tol)


def test_lqr_closed_loop_in_a_simulation_follows_the_linear_prediction():
    """LQR (control.lqr) on the double pendulum on a cart, upright. The law u = −K·x is given
    to jourdain's simulation as compiled input expressions (state_feedback). From a small
    initial deviation of size ε the nonlinear closed loop follows the linear one,
    x(t) = e^{(A − BK)t}·x0 (python-control's initial_response), to a relative deviation
    that vanishes like ε²: the model is odd in (x, θ, F), so the terms the linearization drops
    are cubic. Two amplitudes ε and 2ε show the order: their deviations relative to the
    motion differ by the factor 4, to the next term of the expansion, itself of the size of
    the deviation (bounded by 10 times it)."""
    s = n_link_pendulum_on_cart(2)
    lin = s.linearize(UPRIGHT2)
    sc = to_control(lin)
    assert np.linalg.eigvals(sc.A).real.max() > 1.0  # upright is unstable in open loop
    Qw, Rw = np.diag([1.0, 10.0, 10.0, 0.1, 0.1, 0.1]), np.eye(1)
    K, _, E = control.lqr(sc, Qw, Rw)
    # python-control's closed-loop eigenvalues are those of A − BK (to their conditioning)
    Acl = sc.A - sc.B @ K
    lam, tol = eig_with_tol(Acl, EPS * norm(sc.B) * norm(K) * 10)
    E = np.asarray(E)[np.lexsort((np.asarray(E).imag, np.asarray(E).real))]
    np.testing.assert_allclose(E, lam, rtol=0, atol=tol.max())
    assert E.real.max() < 0
    closed = control.ss(Acl, sc.B, np.eye(6), np.zeros((6, 1)))
    law = state_feedback(s, K, lin)
    assert set(law) == {"F"}
    t = np.linspace(0.0, 8.0, 401)
    dev = []
    i1 = int(np.searchsorted(t, 1.0))
    for eps in (5e-3, 1e-2):
        x0 = np.array([0.0, eps, -0.5 * eps, 0.0, 0.0, 0.0])
        res = s.simulate((0.0, 8.0), x0[:3], x0[3:], inputs=law, rtol=1e-11, atol=1e-14,
                         t_eval=t)
        assert res.status == "finished"
        ref = control.initial_response(closed, T=t, X0=x0).states.T
        sim = np.hstack([res.y, res.yd])
        dev.append(np.abs(sim - ref).max() / np.abs(ref).max())
        # the input the simulation recorded is the law at the simulated states
        np.testing.assert_allclose(res.u[:, 0], -(sim @ K[0]), rtol=0,
                                   atol=10 * EPS * np.abs(sim).max() * np.abs(K).sum())
        # each closed-loop mode of the simulation, z_k = w_kᴴ·x (w_k the left eigenvector),
        # decays as e^{λ_k t}: its rate over [0, t1] is λ_k to the deviation of x carried
        # through w_k and divided by |z_k| at either end
        lam_k, W = np.linalg.eig(Acl.T)
        z0, z1 = W.T @ sim[0], W.T @ sim[i1]
        rate = np.log(z1 / z0) / t[i1]  # real parts: any branch of the log
        dz = np.linalg.norm(W, axis=0) * dev[-1] * np.abs(ref).max()
        bound = dz * (1 / np.abs(z0) + 1 / np.abs(z1)) / t[i1]
        assert np.all(np.abs(rate.real - lam_k.real) <= bound), (rate, lam_k, bound)
    ratio = dev[1] / dev[0]
    assert abs(ratio / 4.0 - 1.0) <= 10 * dev[1], (dev, ratio)


def test_nominal_inputs_and_steady_offsets_in_the_law():
    """u = u_s − K·(x − x_s): the law about a non-zero nominal point, in the model's symbols."""
    s = n_link_pendulum_on_cart(1)
    K = np.array([[1.0, -2.0, 3.0, -4.0]])
    law = state_feedback(s, K, {"q0": 0.5, "q1": 0}, inputs={"F": 0.25})["F"]
    vals = {"q0": 0.7, "q1": 0.1, "q0_d": -0.2, "q1_d": 0.3}
    expected = 0.25 - K[0] @ np.array([0.7 - 0.5, 0.1, -0.2, 0.3])
    got = float(law.subs({jd.symbols(k): v for k, v in vals.items()}))
    assert got == pytest.approx(expected, rel=1e-15, abs=1e-15)


def test_errors_name_what_is_wrong(monkeypatch):
    s = n_link_pendulum_on_cart(1)
    lin = jd.linearize_numeric(s, UPRIGHT1)
    with pytest.raises(jd.EvaluationError, match=r"unknown output\(s\) \['x'\].*q0, q1, q0_d"):
        to_control(lin, outputs=["x"])
    with pytest.raises(jd.EvaluationError, match="twice"):
        to_control(lin, outputs=["q0", "q0"])
    with pytest.raises(jd.EvaluationError, match="pass t and parameters to state_space"):
        to_control(jd.state_space(lin), parameters={"g": 1.0})
    with pytest.raises(jd.EvaluationError, match=r"K has shape \(1, 3\).*needs \(1, 4\)"):
        state_feedback(s, np.ones((1, 3)), UPRIGHT1)
    with pytest.raises(jd.EvaluationError, match="NaN or inf"):
        state_feedback(s, [np.nan, 0, 0, 0], UPRIGHT1)
    with pytest.raises(jd.ModelError, match="no value for coordinate"):
        state_feedback(s, np.ones(4), {"q0": 0})
    monkeypatch.setitem(sys.modules, "control", None)  # as if python-control were missing
    with pytest.raises(MissingDependency, match=r"jourdain\[control\]"):
        to_control(lin)


def test_lqr_holds_a_urdf_arm_in_a_pose_against_gravity():
    """The same loop on a robot read from URDF (tests/data/urdf/two_link_arm.urdf: joint
    torques tau_<joint> as inputs): about a pose held by the gravity torques u_s (the nominal
    check's holding inputs), u = u_s − K·(x − x_s). No symmetry here, so the deviation from the
    linear closed loop, relative to the motion, is O(ε): doubling ε doubles it, to the next
    term of the expansion (bounded by 10 times the deviation)."""
    pytest.importorskip("yourdfpy", reason="URDF import needs yourdfpy (jourdain[urdf])")
    import warnings

    from jourdain.io.urdf import load_urdf

    s = load_urdf(Path(__file__).parent / "data" / "urdf" / "two_link_arm.urdf").system
    pose = {"shoulder": 0.3, "elbow": 0.5, "wrist": -0.2}
    with warnings.catch_warnings():  # without its holding torques the pose is no equilibrium
        warnings.simplefilter("ignore", jd.NominalMotionWarning)
        hold = jd.linearize_numeric(s, pose).nominal_check.holding_inputs
    lin = s.linearize(pose, inputs=hold)
    assert lin.check_nominal().is_solution
    plant = to_control(lin)
    assert plant.input_labels == ["tau_shoulder", "tau_elbow", "tau_wrist"]
    K, _, E = control.lqr(plant, np.eye(6), np.eye(3))
    assert np.real(E).max() < 0
    closed = control.ss(plant.A - plant.B @ K, plant.B, np.eye(6), np.zeros((6, 3)))
    law = state_feedback(s, K, lin)
    y_s = np.array(list(pose.values()))
    t = np.linspace(0.0, 5.0, 251)
    dev = []
    for eps in (1e-3, 2e-3):
        dx = np.array([eps, -eps, 0.5 * eps, 0.0, 0.0, 0.0])
        res = s.simulate((0.0, 5.0), y_s + dx[:3], dx[3:], inputs=law, rtol=1e-11, atol=1e-13,
                         t_eval=t)
        ref = control.initial_response(closed, T=t, X0=dx).states.T
        sim = np.hstack([res.y - y_s, res.yd])
        dev.append(np.abs(sim - ref).max() / np.abs(ref).max())
    assert abs(dev[1] / dev[0] / 2.0 - 1.0) <= 10 * dev[1], dev


def test_lqr_holds_ur5_from_example_robot_data():
    """Issue 15's robot end to end: UR5 of example-robot-data read from URDF, linearized about
    a pose held by its gravity torques, an LQR design by python-control, the loop closed in a
    jourdain simulation. Its deviation from python-control's linear closed loop, relative to
    the motion, is O(ε) (no symmetry): doubling ε doubles it, to the next order."""
    pytest.importorskip("yourdfpy", reason="URDF import needs yourdfpy (jourdain[urdf])")
    import warnings

    from jourdain.io.urdf import load_urdf
    from tests.reference.test_urdf_pinocchio import robots_dir

    s = load_urdf(robots_dir() / "ur_description" / "urdf" / "ur5_robot.urdf").system
    f = s.f
    pose = dict(zip(s.coordinate_names, [0.2, -1.0, 1.2, -0.5, 0.4, 0.1], strict=True))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", jd.NominalMotionWarning)
        hold = jd.linearize_numeric(s, pose).nominal_check.holding_inputs
    lin = s.linearize(pose, inputs=hold)
    assert lin.check_nominal().is_solution
    plant = to_control(lin)
    K, _, E = control.lqr(plant, np.eye(2 * f), np.eye(f))
    assert np.real(E).max() < 0
    closed = control.ss(plant.A - plant.B @ K, plant.B, np.eye(2 * f), np.zeros((2 * f, f)))
    law = state_feedback(s, K, lin)
    y_s = np.array(list(pose.values()))
    t = np.linspace(0.0, 5.0, 251)
    dev = []
    for eps in (1e-3, 2e-3):
        dx = np.concatenate([eps * np.array([1.0, -1.0, 0.5, 0.3, -0.2, 0.1]), np.zeros(f)])
        res = s.simulate((0.0, 5.0), y_s + dx[:f], dx[f:], inputs=law, rtol=1e-11, atol=1e-13,
                         t_eval=t)
        ref = control.initial_response(closed, T=t, X0=dx).states.T
        sim = np.hstack([res.y - y_s, res.yd])
        dev.append(np.abs(sim - ref).max() / np.abs(ref).max())
    assert abs(dev[1] / dev[0] / 2.0 - 1.0) <= 10 * dev[1], dev
