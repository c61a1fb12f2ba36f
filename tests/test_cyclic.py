"""Cyclic coordinates: detection and the stability verdict in Routh's sense (issue 12, item 3).

References: the sleeping top's critical spin C²Ω² > 4·A₀·m·g·s (Klein–Sommerfeld; Magnus,
*Kreisel*), its nutation frequencies A₀ω² − CΩω + m·g·s = 0, and the conserved momentum of a
free cart."""

import json
from pathlib import Path

import numpy as np
import pytest

import jourdain as jd
from jourdain.analysis.cyclic import cyclic_coordinates
from jourdain.cli import main
from jourdain.errors import EvaluationError
from jourdain.io import capabilities, load_model
from jourdain.models import double_pendulum, heavy_top
from tests.tolerance import state_space_eig_tol

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _critical_spin(p):
    A0 = p["A"] + p["m"] * p["L"] ** 2
    return np.sqrt(4 * A0 * p["m"] * p["g"] * p["L"]) / p["C"], A0


@pytest.fixture(scope="module")
def top():
    return load_model(EXAMPLES / "heavy_top.toml")


@pytest.mark.parametrize("factor, verdict", [(1 + 1e-4, jd.analysis.MARGINALLY_STABLE),
                                             (1 - 1e-4, jd.analysis.UNSTABLE)])
def test_sleeping_top_critical_spin(top, factor, verdict):
    """heavy_top.toml: stable just above C²Ω² = 4·A₀·m·g·s, unstable just below, with the spin
    angle treated as cyclic; the nutation frequencies solve A₀ω² − CΩω + m·g·s = 0."""
    p = top.system.parameter_values
    crit, A0 = _critical_spin(p)
    omega = factor * crit
    res = capabilities.linear_analysis(top, "fast", {"Omega": omega})
    st = res["stability"]
    assert res["cyclic"] == ("gamma",) and st.cyclic == ("gamma",)
    assert st.verdict == verdict, st.reason
    assert "Routh" in st.reason and "gamma" in st.reason
    # the four non-zero eigenvalues against the closed form (complex roots below the spin)
    ss = jd.state_space(res["linearization"], parameters={"Omega": omega})
    lam, tol = state_space_eig_tol(ss)
    C, mgs = p["C"], p["m"] * p["g"] * p["L"]
    omegas = np.roots([A0, -C * omega, mgs]).astype(complex)  # λ = iω
    ref = np.concatenate([1j * omegas, np.conj(1j * omegas)])
    moving = np.abs(lam) > 1e-6 * np.abs(lam).max()
    assert moving.sum() == 4
    for r in ref:
        i = int(np.argmin(np.abs(lam - r)))
        # near the critical spin the pairs nearly coincide: a double root moves by √(error)
        assert abs(lam[i] - r) <= np.sqrt(tol[i] * np.abs(lam).max()) + tol[i]


def test_sleeping_top_example_verdicts(top, capsys):
    """The report's nominal motions: the fast top stable, the slow one unstable; the text of
    `jourdain linearize` and `jourdain check` name the cyclic coordinate."""
    p = top.system.parameter_values
    crit, _ = _critical_spin(p)
    assert p["Omega"] > crit > p["Omega_slow"]
    assert capabilities.linear_analysis(top, "fast")["stability"].is_stable
    assert not capabilities.linear_analysis(top, "slow")["stability"].is_stable
    assert main(["linearize", str(EXAMPLES / "heavy_top.toml"), "--about", "slow"]) == 0
    out = capsys.readouterr().out
    assert "cyclic coordinates: gamma" in out and "stability: unstable" in out
    assert main(["check", str(EXAMPLES / "heavy_top.toml"), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["cyclic_coordinates"] == ["gamma"]
    assert main(["linearize", str(EXAMPLES / "heavy_top.toml"), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["cyclic_coordinates"] == ["gamma"]
    assert data["stability"]["cyclic"] == ["gamma"]
    assert data["stability"]["verdict"] == "marginally stable"


def test_precessing_top_is_stable_in_routh_sense():
    """The regular precession (z-x-z Euler angles): psi and phi are cyclic; the full system has
    the drift of both angles (a defective zero eigenvalue: the old verdict "unstable"), the
    reduced one is stable. phi occurs in M, k only in terms that cancel (sin² + cos²)."""
    model = load_model(EXAMPLES / "precessing_top.toml")
    res = capabilities.linear_analysis(model, None)
    assert res["cyclic"] == ("psi", "phi")
    assert res["stability"].verdict == jd.analysis.MARGINALLY_STABLE, res["stability"].reason
    full = jd.stability(res["linearization"], cyclic=())
    assert full.verdict == jd.analysis.UNSTABLE and "linearly" in full.reason
    assert jd.stability(res["linearization"]).cyclic == ("psi", "phi")


def test_detection():
    """Python models: the heavy top's precession and spin angles are cyclic, its nutation is
    not; a double pendulum has none."""
    assert cyclic_coordinates(heavy_top()) == ("psi", "phi")
    assert cyclic_coordinates(double_pendulum()) == ()
    x, phi, m = jd.symbols("x phi m")
    cart = jd.Body("cart", "world", jd.Prismatic("slider", x, "x"), mass=m,
                   inertia=jd.point_mass())
    bob = jd.Body("bob", "cart", jd.Revolute("pivot", phi, "z"), mass=m, com=(0, -1, 0),
                  inertia=jd.point_mass())
    s = jd.System([x, phi], [cart, bob], [jd.Gravity((0, -9.81, 0))], parameters={"m": 1.0})
    assert cyclic_coordinates(s) == ("x",)
    # a spring on the cart makes x appear in q: no longer cyclic
    sprung = jd.System([x, phi], [cart, bob], [jd.Gravity((0, -9.81, 0)),
                                               jd.RotationalSpringDamper("k", x, stiffness=5.0)],
                       parameters={"m": 1.0})
    assert cyclic_coordinates(sprung) == ()
    # a force with no real value at many random states (sqrt(1 − x²)): those states are
    # skipped, and x, which occurs, is not cyclic
    root = jd.System([x], [cart], [jd.GeneralizedForce("f", x, -jd.sqrt(1 - x**2))],
                     parameters={"m": 1.0})
    assert cyclic_coordinates(root) == ()
    # the pendulum on a free cart: the hanging position is stable with x cyclic
    st = jd.stability(s.linearize({"x": 0, "phi": 0}))
    assert st.verdict == jd.analysis.MARGINALLY_STABLE and st.cyclic == ("x",)


def test_cyclic_argument_is_checked():
    lin = double_pendulum().linearize({"phi1": 0, "phi2": 0})
    with pytest.raises(EvaluationError, match="not cyclic"):
        jd.stability(lin, cyclic=("phi1",))
    with pytest.raises(EvaluationError, match="not a coordinate"):
        jd.stability(lin, cyclic=("psi",))


def test_stability_boundary_is_the_critical_spin(top):
    """jd.stability_boundary on the spin (verdicts in Routh's sense) finds C²Ω² = 4·A₀·m·g·s.
    The bisection stops at 1e-10 relative; the verdict's tolerance on a zero real part moves a
    double root's boundary by about (1e3·√eps)² relative (the pair is judged as one cluster)."""
    lin = top.system.linearize({"alpha": 0, "beta": 0, "gamma": jd.symbols("Omega") * jd.t})
    crit, _ = _critical_spin(top.system.parameter_values)
    found = jd.stability_boundary(lin, "Omega", 30.0, 80.0)
    assert abs(found / crit - 1) <= 1e-10 + (1e3 * np.sqrt(np.finfo(float).eps)) ** 2


def test_numeric_linearization_keeps_its_equations():
    """linearize_numeric (the fast path) gives the same Routh verdict without deriving the
    equations again: the regular precession of the Python heavy top."""
    s = heavy_top()
    p = s.parameter_values
    th, Op = 0.5, 2.0
    A0 = p["A"] + p["m"] * p["L"] ** 2
    spin = (p["m"] * p["g"] * p["L"] + A0 * Op**2 * np.cos(th)) / (p["C"] * Op) - Op * np.cos(th)
    nominal = {"psi": Op * jd.t, "theta": th, "phi": spin * jd.t}
    num = jd.linearize_numeric(s, nominal)
    assert num.equations_of_motion is not None
    st = jd.stability(num)
    assert st.cyclic == ("psi", "phi") and st.verdict == jd.analysis.MARGINALLY_STABLE, st.reason


@pytest.mark.parametrize("name", ["precessing_top", "heavy_top", "wheel_creep", "robot_arm",
                                  "double_pendulum"])
def test_compiled_screen_agrees_with_exact_derivatives(name, monkeypatch):
    """The compiled shift test (the fast path) and the exact derivatives of the expression
    graph (forward mode) find the same cyclic coordinates."""
    from jourdain.analysis import cyclic

    system = load_model(Path(__file__).parents[1] / "examples" / f"{name}.toml").system
    fast = cyclic_coordinates(system)
    assert cyclic._screen_compiled(system, list(range(system.f))) is not None
    monkeypatch.setattr(cyclic, "_screen_compiled", lambda *a: None)
    assert cyclic_coordinates(system) == fast
