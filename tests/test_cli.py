"""The ``jourdain`` command: every example through check, eom and run; the eval JSON contract
against the Python API; exit statuses; closed-form checks of linearize on the examples."""

import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import symengine as se

from jourdain.cli import EVAL_FORMAT, main
from jourdain.io import load_model, parse_expression
from jourdain.models import double_pendulum
from jourdain.numeric import evaluate
from tests.tolerance import reactions_tol

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "examples").glob("*.toml"))
NAMES = [p.stem for p in EXAMPLES]


def run(capsys, *args: str) -> tuple[int, str, str]:
    code = main([str(a) for a in args])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_the_examples_are_all_there():
    expected = {"simple_pendulum", "double_pendulum", "slider_on_rotating_rod", "heavy_top",
                "gyroscopic_rotor", "rotor_internal_damping", "follower_double_pendulum",
                "quarter_car", "robot_arm"}
    assert expected <= set(NAMES)
    readme = (ROOT / "examples" / "README.md").read_text()
    for n in NAMES:
        assert f"{n}.toml" in readme, f"examples/README.md says nothing about {n}.toml"


@pytest.mark.parametrize("path", EXAMPLES, ids=NAMES)
def test_example_check_and_eom(path, capsys):
    code, out, err = run(capsys, "check", path)
    assert code == 0, err
    system = load_model(path).system
    assert f"degrees of freedom f = {system.f}" in out
    # the tree joints' constrained directions (a closed system's closing rows: its loop lines;
    # an elastic body's reactions are not formed: the count of its joints' directions)
    if not system.groups:
        assert f"constrained directions q = {len(system.tree.reactions().g_names)}:" in out
    code, out, err = run(capsys, "eom", path)
    assert code == 0, err
    if system.is_general:  # the tree's equations with the rows A, a and the contact forces
        assert "A (every constraint row" in out and "M_tree" in out and "λ" in out
        assert "M (mass matrix, f×f) =" not in out
    elif system.closing:  # the tree's equations with Φ, Φ_y and the multipliers, then L
        assert "Φ_y" in out and "M_tree" in out and "λ" in out
        assert "M (mass matrix, f×f) =" not in out
    else:
        assert "M (mass matrix, f×f) =" in out and "q (generalized applied forces, f) =" in out


@pytest.mark.parametrize("path", EXAMPLES, ids=NAMES)
def test_example_run_writes_a_report(path, tmp_path, capsys):
    code, out, err = run(capsys, "run", path, "--out", tmp_path / "r")
    assert code == 0, err
    report = tmp_path / "r" / "report.html"  # one report for trees and closed systems
    assert f"report: {report}" in out
    text = report.read_text()
    assert "<svg" in text
    system = load_model(path).system
    closed = bool(system.closing)
    names = ("values.json", "simulation.csv", "model.toml")
    if system.is_general:  # no symbolic equations; the contacts' and the steady motion's files
        names += ("contacts.csv",)
    elif closed:  # no symbolic equations (their velocity map is numbers only); the loops' files
        names += ("loops.json", "loops.csv")
    else:
        assert "<math" in text
        names += ("equations.json", "equations.tex")
    for name in names:
        assert (tmp_path / "r" / name).is_file(), name


def test_eval_json_matches_the_python_api(capsys):
    path = ROOT / "examples" / "double_pendulum.toml"
    code, out, err = run(capsys, "eval", path, "--at", "phi1=0.3, phi1_d=1.0, phi2=-0.2, t=0",
                         "--set", "m2=0.8", "--json")
    assert code == 0, err
    data = json.loads(out)
    assert data["format"] == EVAL_FORMAT
    assert data["parameters"]["m2"] == 0.8
    ref = double_pendulum()  # built in Python, independently of the model file
    y, yd = [0.3, -0.2], [1.0, 0.0]
    values = ref.evaluate(y, yd, parameters={"m2": 0.8})
    for key in ("M_bar", "J_bar", "q_c", "q_e", "M", "k", "q", "Q_bar", "N_hat", "k_hat",
                "q_hat"):  # evaluated directly, a few operations on numbers of order 1
        np.testing.assert_allclose(np.array(data["values"][key], float),
                                   np.asarray(values[key], float).reshape(
                                       np.array(data["values"][key]).shape),
                                   rtol=1e-12, atol=1e-12, err_msg=key)
    # g: one solve of N̂·g = k̂ − q̂ on each side
    np.testing.assert_allclose(data["values"]["g"], values["g"], rtol=0,
                               atol=2 * reactions_tol(values), err_msg="g")
    assert data["g_names"] == list(values["g_names"])
    # linearization about this state (nominal ÿ = 0): M̃ = M, h = q − k, and P, Q are the
    # derivatives of k − q by rates and coordinates (central differences of the Python API)
    v = {k: np.array(x, float) for k, x in data["values"].items() if x is not None}
    np.testing.assert_allclose(v["M_tilde"], values["M"], rtol=1e-12)
    np.testing.assert_allclose(v["h"], (values["q"] - values["k"]).ravel(), atol=1e-12)

    def r(yy, yyd):
        e = evaluate(ref, yy, yyd, parameters={"m2": 0.8})
        return (e["k"] - e["q"]).ravel()

    eps = 1e-6
    P = np.column_stack([(r(y, np.add(yd, eps * np.eye(2)[j])) - r(y, np.subtract(
        yd, eps * np.eye(2)[j]))) / (2 * eps) for j in range(2)])
    Q = np.column_stack([(r(np.add(y, eps * np.eye(2)[j]), yd) - r(np.subtract(
        y, eps * np.eye(2)[j]), yd)) / (2 * eps) for j in range(2)])
    np.testing.assert_allclose(v["P"], P, rtol=1e-6, atol=1e-7)
    np.testing.assert_allclose(v["Q"], Q, rtol=1e-6, atol=1e-7)
    np.testing.assert_allclose(v["K"], 0.5 * (Q + Q.T), rtol=1e-6, atol=1e-7)
    np.testing.assert_allclose(v["G"], 0.5 * (P - P.T), rtol=1e-6, atol=1e-7)
    assert data["not_available"] == {}
    # the documented contract: these keys, no others (jourdain-eval/1)
    assert set(data) == {"format", "model", "file", "coordinates", "t", "y", "yd", "parameters",
                         "inputs", "values", "g_names", "g_undetermined", "not_available",
                         "joint_wrenches", "units"}
    assert data["units"]["y"] == ["rad", "rad"] and data["units"]["k"] == ["N m", "N m"]
    assert set(data["values"]) == {"M_bar", "J_bar", "q_c", "q_e", "M", "k", "q", "Q_bar",
                                   "N_hat", "k_hat", "q_hat", "g", "M_tilde", "P", "Q", "h",
                                   "D", "G", "K", "N"}


def test_eval_with_inputs_and_defaults_from_the_model(capsys):
    path = ROOT / "examples" / "quarter_car.toml"
    code, out, err = run(capsys, "eval", path, "--at", "z_b=0.01, z_r=0.005", "--json")
    assert code == 0, err
    data = json.loads(out)
    assert data["inputs"] == {"z_r": 0.005} and data["y"] == [0.01, 0.0]
    p = data["parameters"]
    # q of the wheel: tyre force + preload + suspension spring (compressed by z_b - z_w)
    q_w = -p["k_t"] * (0 - 0.005) + (p["m_b"] + p["m_w"]) * p["g"] - p["m_w"] * p["g"] \
        - p["m_b"] * p["g"] + p["k_s"] * 0.01
    assert data["values"]["q"][1] == pytest.approx(q_w, rel=1e-12)


def test_eom_json_is_readable_by_the_restricted_parser(capsys):
    """The exported expressions (with shared temporaries) read back with jourdain's own
    parser and evaluate to the compiled numbers."""
    path = ROOT / "examples" / "heavy_top.toml"
    code, out, err = run(capsys, "eom", path, "--format", "json")
    assert code == 0, err
    data = json.loads(out)
    system = load_model(path).system
    y, yd = [0.3, 0.7, -0.2], [1.5, -0.4, 30.0]
    env = {**data["parameters"], **dict(zip(data["coordinates"], y, strict=True)),
           **dict(zip(data["rates"], yd, strict=True)), "t": 0.0}
    names = set(env)
    for name, text in data["temporaries"]:
        env[name] = float(parse_expression(text, names | {name}).subs(
            {se.Symbol(k): v for k, v in env.items()}))
        names.add(name)
    subs = {se.Symbol(k): v for k, v in env.items()}
    ref = evaluate(system, y, yd)
    for key in ("M", "k", "q", "J_bar"):
        got = np.array([[float(parse_expression(e, names).subs(subs)) for e in row]
                        for row in data["matrices"][key]["entries"]])
        np.testing.assert_allclose(got, np.asarray(ref[key]).reshape(got.shape), rtol=1e-12,
                                   atol=1e-12, err_msg=key)


def test_eom_latex(capsys):
    code, out, _ = run(capsys, "eom", ROOT / "examples" / "simple_pendulum.toml", "--format",
                       "latex")
    assert code == 0
    assert r"\bar{M} =" in out and r"\varphi" in out and r"\begin{pmatrix}" in out


def _lin(capsys, name: str, *extra: str) -> dict:
    code, out, err = run(capsys, "linearize", ROOT / "examples" / f"{name}.toml", "--json",
                         *extra)
    assert code == 0, err
    return json.loads(out)


def test_linearize_simple_pendulum_frequency(capsys):
    data = _lin(capsys, "simple_pendulum")
    assert data["conservative"] is True
    assert data["stability"]["verdict"] == "marginally stable"
    freqs = [f for f in data["natural_frequencies_hz"] if f]
    assert freqs[0] == pytest.approx(math.sqrt(9.81 / 1.0) / (2 * math.pi), rel=1e-12)


def test_linearize_gyroscopic_rotor_whirl_frequencies(capsys):
    """Forward and backward whirl of a spinning disc on an elastic gimbal:
    A0·ω² ∓ C·Ω·ω − c = 0 with A0 = m r²/4 + m h², C = m r²/2."""
    data = _lin(capsys, "gyroscopic_rotor")
    m, r, h, c, Om = 2.0, 0.15, 0.1, 40.0, 100.0
    A0, C = m * r**2 / 4 + m * h**2, m * r**2 / 2
    w = sorted(abs(s * C * Om + math.sqrt((C * Om) ** 2 + 4 * A0 * c)) / (2 * A0)
               for s in (-1, 1))
    damped = sorted({round(abs(im), 9) for _, im in data["eigenvalues"]})
    np.testing.assert_allclose(damped, w, rtol=2e-4)  # light damping d shifts them slightly
    G = np.array(data["matrices"]["G"])
    assert abs(G[0, 1]) == pytest.approx(C * Om, rel=1e-12) and G[0, 1] == -G[1, 0]


@pytest.mark.parametrize("omega, verdict", [(14.5, "asymptotically stable"), (15.5, "unstable")])
def test_internal_damping_threshold(capsys, omega, verdict):
    """Jeffcott rotor: unstable above Omega = sqrt(k/m)·(1 + d_e/d_i) = 15 rad/s."""
    data = _lin(capsys, "rotor_internal_damping", "--set", f"Omega={omega}")
    assert data["stability"]["verdict"] == verdict
    N = np.array(data["matrices"]["N"])
    assert N[0, 1] == pytest.approx(1.0 * omega) and N[1, 0] == pytest.approx(-omega)


@pytest.mark.parametrize("P, verdict", [(20.5, "marginally stable"), (21.2, "unstable")])
def test_ziegler_flutter_load(capsys, P, verdict):
    """Ziegler's column (masses 2m, m): flutter at P = (7/2 − √2)·c/l = 20.86 N."""
    data = _lin(capsys, "follower_double_pendulum", "--set", f"P={P}")
    assert data["stability"]["verdict"] == verdict
    assert data["conservative"] is False


def test_simulate_simple_pendulum_small_swing(tmp_path, capsys):
    out = tmp_path / "sim.csv"
    code, text, err = run(capsys, "simulate", ROOT / "examples" / "simple_pendulum.toml",
                          "--t-end", "2", "--out", out)
    assert code == 0, err
    assert out.is_file() and "final state: phi=" in text
    model = ROOT / "examples" / "simple_pendulum.toml"
    small = tmp_path / "small.toml"
    small.write_text(model.read_text().replace('y0 = { phi = "pi/4" }', 'y0 = { phi = 0.001 }'))
    code, text, err = run(capsys, "simulate", small, "--t-end", "2")
    assert code == 0, err
    phi = float(text.split("final state: phi=")[1].split()[0])
    assert phi == pytest.approx(0.001 * math.cos(math.sqrt(9.81) * 2.0), rel=2e-3)


@pytest.mark.parametrize("args, code, message", [
    (["check"], 2, "the following arguments are required: MODEL"),
    (["frobnicate", "x.toml"], 2, "invalid choice"),
    (["eom", "EX", "--format", "word"], 2, "invalid choice: 'word'"),
    (["eval", "EX", "--at", "phi9=1"], 2, '"phi9" is not a coordinate'),
    (["eval", "EX", "--at", "phi1"], 2, "expected name=value"),
    (["eval", "EX", "--at", "phi1=__import__(x)"], 2, "double-underscore"),
    (["eval", "EX", "--set", "mass=2"], 2, '"mass" is not a parameter'),
    (["run", "EX"], 2, "--out"),
    # usage errors, not model errors (issue 17, item 5): a file or a name that is not there
    (["check", "missing.toml"], 2, "missing.toml: no such model file"),
    (["linearize", "EX", "--about", "nowhere"], 2, 'no nominal motion "nowhere"'),
    (["linearize", "EX", "--about", "uprigt"], 2, '(did you mean "upright"?)'),
    (["simulate", "EX", "--out", "sim.json"], 2, "unknown file type '.json'; use .csv, .h5"),
    ([], 2, "usage"),
])
def test_exit_status_and_messages(args, code, message, capsys):
    ex = str(ROOT / "examples" / "double_pendulum.toml")
    args = [ex if a == "EX" else a for a in args]
    try:
        got = main(args)
    except SystemExit as exc:  # argparse's own usage errors
        got = exc.code
    out = capsys.readouterr()
    assert got == code
    assert message in out.err
    assert "Traceback" not in out.err


@pytest.mark.parametrize("sub", ["check", "eom", "eval", "reactions", "linearize", "simulate",
                                 "run"])
def test_help_has_an_example(sub, capsys):
    with pytest.raises(SystemExit) as info:
        main([sub, "--help"])
    assert info.value.code == 0
    out = capsys.readouterr().out
    assert "example:" in out and f"jourdain {sub} examples/" in out


def test_console_script_exit_statuses(tmp_path):
    """The installed entry point: 0, 1 (model error, no traceback), 2 (usage error)."""
    exe = shutil.which("jourdain", path=str(Path(sys.executable).parent))
    cmd = [exe] if exe else [sys.executable, "-m", "jourdain.cli"]
    ok = subprocess.run([*cmd, "check", str(ROOT / "examples" / "simple_pendulum.toml")],
                        capture_output=True, text=True, timeout=120)
    assert ok.returncode == 0, ok.stderr
    bad = tmp_path / "bad.toml"
    bad.write_text((ROOT / "examples" / "simple_pendulum.toml").read_text().replace(
        'mass = "m"', 'mass = "m.__class__"'))
    res = subprocess.run([*cmd, "check", str(bad)], capture_output=True, text=True, timeout=120)
    assert res.returncode == 1
    assert "attribute access is not allowed" in res.stderr and "Traceback" not in res.stderr
    assert f"{bad}:" in res.stderr
    use = subprocess.run([*cmd, "eval"], capture_output=True, text=True, timeout=120)
    assert use.returncode == 2 and "Traceback" not in use.stderr


def test_reactions_command(capsys):
    code, out, err = run(capsys, "reactions", ROOT / "examples" / "simple_pendulum.toml",
                         "--at", "phi=0, phi_d=2", "--json")
    assert code == 0, err
    data = json.loads(out)
    g = dict(zip(data["g_names"], data["g"], strict=True))
    # hanging bob at rest-angle 0 swinging with rate 2: the rod pulls with m·(g + l·φ̇²) along
    # the rod (body y axis, from the bob towards the hinge); g from a solve, to its tolerance
    tol = reactions_tol(load_model(ROOT / "examples" / "simple_pendulum.toml").system.evaluate(
        [0.0], [2.0]))
    assert g["hinge.F_y"] == pytest.approx(1.0 * (9.81 + 1.0 * 2.0**2), rel=0, abs=tol)
    assert g["hinge.F_x"] == pytest.approx(0.0, abs=tol)


def test_linearize_slider_on_rotating_rod_relative_equilibrium(capsys):
    """In the rod turning at Omega the spring balances the centrifugal force at
    s = c·L0/(c − m·Ω²); the stiffness about it is c − m·Ω², the damping d."""
    data = _lin(capsys, "slider_on_rotating_rod")
    m, c, d, Om = 0.5, 50.0, 0.2, 6.0
    assert data["h_norm"] == pytest.approx(0.0, abs=1e-12)
    assert data["matrices"]["K"][0][0] == pytest.approx(c - m * Om**2, rel=1e-12)
    assert data["matrices"]["D"][0][0] == pytest.approx(d, rel=1e-12)
    assert data["matrices"]["M_tilde"][0][0] == pytest.approx(m, rel=1e-12)
    assert data["stability"]["verdict"] == "asymptotically stable"


def test_constrained_direction_that_does_work(tmp_path, capsys):
    """A general joint whose declared constrained direction does work violates J̄ᵀQ̄ = 0:
    `check` reports it at the key, `eval` still gives the equations of motion and says why the
    reactions are missing."""
    path = tmp_path / "slider.toml"
    path.write_text(
        '[coordinates]\ns = "m"\n[parameters]\nm = 1.0\n[bodies.slider]\nparent = "world"\n'
        'mass = "m"\ninertia = "point"\njoint = { type = "general", steps = [{ trans = "x", '
        'distance = "s" }], constrained = ["F_x", "F_y", "F_z", "T_x", "T_y", "T_z"] }\n')
    code, _, err = run(capsys, "check", path)
    assert code == 1 and "Traceback" not in err
    assert f"{path}:9: body \"slider\" → joint → constrained:" in err
    assert "slider.F_x" in err and "orthogonality" in err
    code, out, err = run(capsys, "eval", path, "--at", "s=0.5", "--json")
    assert code == 0, err
    data = json.loads(out)
    assert data["values"]["M"] == [[1.0]]
    assert "could not be formed" in data["not_available"]["Q_bar"]
