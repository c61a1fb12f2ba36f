"""A vibration mode as a motion (jourdain.analysis.mode_motion): a rod pendulum's mode against
its closed form, the double pendulum's and a flexible pendulum's modes against the linearized
equations (residual), the 3-D view of an elastic body's mode, and bad arguments named."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import symengine as se

import jourdain as jd
from jourdain.errors import EvaluationError
from jourdain.models import double_pendulum

EPS = np.finfo(float).eps


def _residual(r: jd.Results, lin, y_s) -> float:  # type: ignore[no-untyped-def]
    """Largest |M̃·η̈ + P·η̇ + Q·η| relative to the size of its terms (η = y − y_s about an
    equilibrium y_s)."""
    ss = jd.state_space(lin)
    terms = [r.ydd @ ss.M_tilde.T, r.yd @ ss.P.T, (r.y - y_s) @ ss.Q.T]
    scale = max(np.abs(x).max() for x in terms)
    return float(np.abs(sum(terms)).max() / scale)


def test_rod_pendulum_mode_is_the_closed_form() -> None:
    """A uniform rod on a hinge, linearized hanging: ω² = 3g/(2l); the mode's motion is
    φ = A·cos ωt over two periods."""
    phi = se.Symbol("phi")
    m, l, g = 2.0, 0.8, 9.81
    rod = jd.Body("rod", "world", jd.Revolute("hinge", phi, "z"), mass=m, com=(0, -l / 2, 0),
                  inertia=jd.rod(m, l, "y"))
    system = jd.System([phi], [rod], [jd.Gravity((0, -g, 0))])
    lin = system.linearize({"phi": 0})
    r = jd.mode_motion(lin, 1, amplitude=0.05, periods=2, samples=81)
    w = np.sqrt(3 * g / (2 * l))
    assert r.t[-1] == pytest.approx(2 * 2 * np.pi / w, rel=1e-12)
    ref = 0.05 * np.cos(w * r.t)
    assert np.abs(r.y[:, 0] - ref).max() <= 100 * EPS
    assert np.abs(r.yd[:, 0] + 0.05 * w * np.sin(w * r.t)).max() <= 100 * EPS * w
    assert "mode 1" in r.message


@pytest.mark.parametrize("mode", [1, 2])
def test_double_pendulum_modes_solve_the_linear_equations(mode: int) -> None:
    system = double_pendulum()
    lin = system.linearize({"phi1": 0, "phi2": 0})
    r = jd.mode_motion(lin, mode, amplitude=0.02)
    assert np.abs(r.y).max() == pytest.approx(0.02, rel=1e-12)
    assert _residual(r, lin, 0.0) <= 1e3 * EPS


def test_an_elastic_mode_in_the_3d_view() -> None:
    """The flexible pendulum hanging (its equilibrium): its second mode, the first bending
    one, solves the linear equations to the accuracy of the eigenvectors (eps·cond(M̃) times
    the spread of the frequencies), and the 3-D view draws the beam's line through its
    nodes."""
    model = jd.load_model(Path(__file__).parent.parent / "examples" / "flexible_pendulum.toml")
    system = model.system
    eq = jd.find_equilibrium(system, {"phi": -np.pi / 2})
    lin = system.linearize(dict(zip(system.coordinate_names, eq.y, strict=True)))
    r = jd.mode_motion(lin, 2, amplitude=1e-3, samples=31)
    ss = jd.state_space(lin)
    w = np.sort(np.abs(np.linalg.eigvals(ss.A)))
    tol = 100 * EPS * np.linalg.cond(ss.M_tilde) * (w[-1] / w[2]) ** 2
    assert _residual(r, lin, np.asarray(eq.y)) <= tol
    sc = jd.view(r).scene
    assert sc["n_frames"] > 1 and sc["elastic"][0]["name"] == "arm"
    assert len(sc["elastic"][0]["nodes"]) == 9  # the beam's line through its nine nodes


def test_bad_arguments_are_named() -> None:
    lin = double_pendulum().linearize({"phi1": 0, "phi2": 0})
    with pytest.raises(EvaluationError, match=r"mode 3 asked, the linearization has 2"):
        jd.mode_motion(lin, 3)
    with pytest.raises(EvaluationError, match="amplitude must be a positive number"):
        jd.mode_motion(lin, 1, amplitude=-1.0)
    with pytest.raises(EvaluationError, match="samples must be an integer"):
        jd.mode_motion(lin, 1, samples=1)
