"""Linearization of force laws with the piecewise functions of the expression language
(``max``, ``min``, ``abs``, ``sign``; issue 38, item 2): differentiated on the branch active at
the nominal state, in every linearization (System.linearize, its compiled form, the general
form, the numeric one, ``jourdain linearize``, ``jourdain run``), and refused with a clear
message exactly at a switching point.

The model is the docs' tether (``docs/model-format.md``, ``[forces.tether]``, taken from the
page): a mass m on a vertical slider hangs from the origin on a tether of natural length L0,
stiffness c and damping d, ``value = -c*max(deflection - L0, 0) - d*deflection_d`` on the
distance ``gap``. Hanging at rest, y_s = −(L0 + m·g/c): the tether is taut, so M̃ = m, P = d,
Q = c, and the eigenvalues are ``−d/(2m) ± i·√(c/m − (d/2m)²)``. With the mass above the
slack length (|y| < L0) only the damper acts: Q = 0.
"""

import json
import re
from pathlib import Path

import numpy as np
import pytest
import symengine as se

import jourdain as jd
from jourdain.cli import main
from jourdain.graph import jet, jet_float
from jourdain.graph.piecewise import SwitchingPoint
from tests.tolerance import EPS, assert_close_eval, state_space_eig_tol

ROOT = Path(__file__).resolve().parents[1]
PARAMETERS = {"m": 2.0, "c": 400.0, "d": 3.0, "L0": 1.0, "g": 9.81}


def docs_tether_block() -> str:
    """The ``[forces.tether]`` block of docs/model-format.md, as the page has it."""
    text = (ROOT / "docs" / "model-format.md").read_text()
    m = re.search(r"^\[forces\.tether\].*?(?=^\s*$|^```)", text, re.S | re.M)
    assert m, "docs/model-format.md has no [forces.tether] example"
    block = m.group(0)
    assert "max(" in block
    return block


def tether_text(nominal: str = "-(L0 + m*g/c)") -> str:
    params = "\n".join(f"{k} = {v}" for k, v in PARAMETERS.items())
    return f"""[model]
name = "tether"
[coordinates]
y = "m"
[parameters]
{params}
[bodies.mass]
parent = "world"
mass = "m"
inertia = "point"
joint = {{ type = "prismatic", coordinate = "y", axis = "y" }}
[quantities.gap]
type = "distance"
body_a = "world"
body_b = "mass"
[forces.gravity]
type = "gravity"
vector = [0, "-g", 0]
{docs_tether_block()}
[nominal.hanging]
y = {{ y = "{nominal}" }}
[simulation]
t_end = 0.5
y0 = {{ y = -1.2 }}
"""


@pytest.fixture(scope="module")
def tether_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("tether") / "tether.toml"
    path.write_text(tether_text())
    return path


@pytest.fixture(scope="module")
def tether(tether_file) -> jd.System:
    return jd.load_model(tether_file).system


def hanging() -> float:
    p = PARAMETERS
    return -(p["L0"] + p["m"] * p["g"] / p["c"])


def residual(system: jd.System, y: float, yd: float) -> float:
    """r = M·ÿ + k − q at rest acceleration ÿ = 0 (the nominal motions here are at rest)."""
    out = system.evaluate([y], [yd])
    return float(out["k"][0] - out["q"][0])


def central(system: jd.System, y: float, yd: float, h: float = 1e-6) -> tuple[float, float]:
    """∂r/∂y and ∂r/∂ẏ by central differences of System.evaluate (truncation error O(h²)
    on a branch: the force is linear in ẏ and quadratic-free in y there)."""
    Q = (residual(system, y + h, yd) - residual(system, y - h, yd)) / (2 * h)
    P = (residual(system, y, yd + h) - residual(system, y, yd - h)) / (2 * h)
    return Q, P


def test_the_docs_tether_linearizes_to_its_closed_form(tether):
    p = PARAMETERS
    lin = tether.linearize({"y": se.sympify("-(L0 + m*g/c)")})
    num = lin.evaluate()
    for name, ref in (("M_tilde", p["m"]), ("P", p["d"]), ("Q", p["c"]), ("D", p["d"]),
                      ("K", p["c"]), ("G", 0.0), ("N", 0.0), ("h", 0.0)):
        # a few operations on the parameters (sqrt of a square, a quotient): rounding only
        assert_close_eval(num[name], np.atleast_2d(ref) if name != "h" else [ref], 8,
                          scale=p["c"], err_msg=name)
    ss = jd.state_space(lin)
    lam, tol = state_space_eig_tol(ss)
    re_, im = -p["d"] / (2 * p["m"]), np.sqrt(p["c"] / p["m"] - (p["d"] / (2 * p["m"])) ** 2)
    ref = np.array([re_ - 1j * im, re_ + 1j * im])
    assert np.all(np.abs(lam - ref) <= tol), (lam, ref, tol)
    # the compiled form gives the same numbers
    compiled = lin.compile()()
    for name in ("M_tilde", "P", "Q"):
        assert_close_eval(compiled[name], num[name], 8, scale=p["c"], err_msg=name)


@pytest.mark.parametrize("y", [hanging(), -0.6], ids=["taut", "slack"])
def test_every_linearization_matches_central_differences(tether, y):
    """Taut (Q = c) and slack (|y| < L0: Q = 0) by the symbolic, general and numeric
    linearizations against central differences of the compiled equations of motion."""
    import warnings

    Q_fd, P_fd = central(tether, y, 0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", jd.NominalMotionWarning)  # slack: not an equilibrium
        symbolic = tether.linearize({"y": y}).evaluate()
        numeric = jd.linearize_numeric(tether, {"y": y})
    general = jd.linearization_general(tether.equations_of_motion()).evaluate([y], [0.0], [0.0])
    # central differences: truncation O(h²)·r''' (zero on a branch) and rounding eps·|r|/h
    tol = 1e3 * EPS * PARAMETERS["c"] * 2 / 1e-6
    for out in (symbolic, general, {"Q": numeric.Q, "P": numeric.P}):
        assert abs(out["Q"][0, 0] - Q_fd) <= tol, (out["Q"], Q_fd)
        assert abs(out["P"][0, 0] - P_fd) <= tol, (out["P"], P_fd)
    assert abs(Q_fd - (PARAMETERS["c"] if abs(y) > PARAMETERS["L0"] else 0.0)) <= tol


def test_exactly_at_the_switching_point_every_linearization_refuses(tether):
    """|y| = L0: the tether is just slack; max(gap − L0, 0) has no derivative there."""
    at = -PARAMETERS["L0"]
    message = r"max\(.*\) switches branches exactly at this state \(two of its arguments"
    with pytest.warns(jd.NominalMotionWarning):  # not an equilibrium: gravity is not held
        lin = tether.linearize({"y": -jd.symbols("L0")})  # the branch depends on parameters
    with pytest.raises(SwitchingPoint, match=message):
        lin.evaluate()
    with pytest.raises(SwitchingPoint, match=message):
        lin.compile()()
    with pytest.raises(SwitchingPoint, match=message):
        jd.linearize_numeric(tether, {"y": at})
    glin = jd.linearization_general(tether.equations_of_motion())
    with pytest.raises(SwitchingPoint, match=message):
        glin.evaluate([at], [0.0], [0.0])
    # a numeric nominal, the parameter moved onto the switch
    lin = tether.linearize({"y": hanging()})
    with pytest.raises(SwitchingPoint, match=message):
        lin.evaluate(parameters={"L0": -hanging()})
    assert lin.evaluate(parameters={"L0": 0.9})["K"][0, 0] == PARAMETERS["c"]
    assert isinstance(SwitchingPoint("x"), jd.EvaluationError)


def test_jourdain_linearize_and_run_keep_D_G_K_N(tether_file, tmp_path, capsys):
    assert main(["linearize", str(tether_file)]) == 0
    out = capsys.readouterr().out
    assert re.search(r"K =\s*\n\[\[400\.\]\]", out), out
    assert "asymptotically stable" in out
    # the switching point (without gravity the tether hangs just slack): a clear message
    assert main(["linearize", str(tether_file), "--set", "g=0"]) == 1
    assert "switches branches exactly at this state" in capsys.readouterr().err
    assert main(["run", str(tether_file), "--out", str(tmp_path / "r")]) == 0
    capsys.readouterr()
    doc = json.loads((tmp_path / "r" / "linearization-hanging.json").read_text())
    assert {"D", "G", "K", "N"} <= set(doc["matrices"])
    assert doc["matrices"]["K"] == [[PARAMETERS["c"]]]


X, A = se.symbols("x a")
CASES = [  # (expression, value of x where it is smooth, its derivative there)
    (se.Max(X, 2 * X), 1.5, 2.0), (se.Max(X, 2 * X), -1.5, 1.0),
    (se.Min(X**2, se.Integer(1)), 0.5, 1.0), (se.Min(X**2, se.Integer(1)), 2.0, 0.0),
    (se.Abs(3 * X), -0.7, -3.0), (se.Abs(3 * X), 0.7, 3.0),
    (se.sign(X) * X, 0.4, 1.0), (se.Max(X, A, -X), 2.0, 1.0),
]


@pytest.mark.parametrize("expr, x, slope", CASES)
def test_piecewise_derivatives_on_either_side(expr, x, slope):
    """jet (symbolic, the branch chosen from the point's number) and jet_float against the
    derivative of the active branch; A = 0.5 for the three-argument max."""
    values = {"x": x, "a": 0.5}
    sym = jet([expr], [X], {X: se.Float(x), A: se.Float(0.5)})
    assert abs(float(sym.gradients[0].get(0, 0)) - slope) <= 10 * EPS * abs(slope)
    num = jet_float([expr], [X], values)
    assert abs(num.jacobian[0, 0] - slope) <= 10 * EPS * abs(slope)
    # with the point symbolic, the derivative carries the step and the switch is recorded
    free = jet([expr], [X], {A: se.Float(0.5)})
    assert free.switches
    d = float(free.gradients[0][0].subs({X: x}))
    assert abs(d - slope) <= 10 * EPS * abs(slope)


@pytest.mark.parametrize("expr, x", [(se.Max(X, 2 * X), 0.0), (se.Abs(X), 0.0),
                                     (se.Min(X, 1 - X), 0.5), (se.sign(X), 0.0)])
def test_piecewise_derivatives_at_the_switch_are_refused(expr, x):
    with pytest.raises(SwitchingPoint, match="switches branches exactly"):
        jet([expr], [X], {X: se.Rational(int(2 * x), 2)})
    with pytest.raises(SwitchingPoint, match="switches branches exactly"):
        jet_float([expr], [X], {"x": x})
    # a branch that does not depend on the variables is no switch: max(a, 0) of a parameter
    assert jet([se.Max(A, 0) + X], [X], {A: se.Integer(0)}).gradients[0] == {0: 1}
