"""Issue 17, items 4 and 7: every numeric option of a simulation is bounded (command line, model
file, API) with a message naming the option; one set of defaults; the command line sets the
method, the tolerances, the initial state and the inputs; progress of long runs; a model that
cannot move (a singular M) is refused by `check`; text from a model file never reaches the
terminal as control characters."""

import math
from pathlib import Path

import numpy as np
import pytest

import jourdain as jd
from jourdain import cli
from jourdain.cli import EXIT_MODEL, EXIT_USAGE, main
from jourdain.io import SimulationSettings, capabilities

ROOT = Path(__file__).resolve().parents[1]
PENDULUM = ROOT / "examples" / "double_pendulum.toml"
CAR = ROOT / "examples" / "quarter_car.toml"
SIMPLE = ROOT / "examples" / "simple_pendulum.toml"


@pytest.fixture
def no_work(monkeypatch):
    def refuse(*args, **kw):
        raise AssertionError("the simulation started with an option out of range")

    monkeypatch.setattr(capabilities, "simulate", refuse)


def _run(capsys, *args) -> tuple[int, str, str]:
    code = main([str(a) for a in args])
    cap = capsys.readouterr()
    assert "Traceback" not in cap.err
    return code, cap.out, cap.err


@pytest.mark.parametrize("option, value, message", [
    ("--samples", "-5", "--samples = -5: at least 2 samples"),
    ("--samples", "1", "--samples = 1: at least 2 samples"),  # was "t = 0 … 0"
    ("--samples", "100000000", "--samples = 100000000: at most 10000000 samples"),  # was 11 GB
    ("--samples", "1e12", "at most 10000000 samples"),  # was a 7 TiB allocation traceback
    ("--samples", "2.5", "must be a whole number"),
    ("--t-end", "1e308", "--t-end = 1e+308: the end time must be at most 1e+09"),  # hung
    ("--t-end", "inf", '--t-end: "inf" is not a number'),
    ("--t-end", "0", "the end time must be positive"),
    ("--t-end", "-1", "the end time must be positive"),
    ("--rtol", "1e300", "--rtol = 1e+300: the relative tolerance must be at least 1e-14"),
    ("--rtol", "1", "and below 1"),
    ("--rtol", "1e-20", "at least 1e-14"),
    ("--rtol", "0", "at least 1e-14"),
    ("--atol", "1e300", "--atol = 1e+300: the absolute tolerance must be positive, finite"),
    ("--atol", "0", "must be positive"),
    ("--atol", "abc", '--atol: "abc" is not a number'),
    ("--method", "Euler", "invalid choice: 'Euler'"),
])
def test_simulation_options_out_of_range_are_usage_errors(option, value, message, capsys,
                                                          no_work):
    try:
        code, _, err = _run(capsys, "simulate", PENDULUM, option, value)
    except SystemExit as exc:  # argparse's choices
        code, err = exc.code, capsys.readouterr().err
    assert code == EXIT_USAGE
    assert message in err


def test_max_ops_must_be_a_count(capsys):
    with pytest.raises(SystemExit) as info:
        main(["eom", str(PENDULUM), "--max-ops", "-1"])
    assert info.value.code == EXIT_USAGE
    assert "expected 0 or more operations" in capsys.readouterr().err


@pytest.mark.parametrize("key, value, message", [
    ("samples", "100000000", "[simulation] → samples: samples = 100000000: at most 10000000"),
    ("samples", "1", "at least 2 samples"),
    ("rtol", "1e300", "[simulation] → rtol: rtol = 1e+300: the relative tolerance"),
    ("atol", "1e300", "[simulation] → atol: atol = 1e+300: the absolute tolerance"),
    ("t_end", "1e308", "[simulation] → t_end: t_end = 1e+308: the end time must be at most"),
])
def test_model_file_simulation_table_is_bounded(key, value, message, tmp_path, capsys):
    text = SIMPLE.read_text().replace("t_end = 4.0\n", "")
    path = tmp_path / "m.toml"
    path.write_text(text.replace("[simulation]\n", f"[simulation]\n{key} = {value}\n"))
    code, _, err = _run(capsys, "check", path)
    assert code == EXIT_MODEL
    assert f"{path}:" in err and message in err


def test_api_bounds(tmp_path):
    s = jd.load_model(SIMPLE).system
    y0, yd0 = [0.5], [0.0]
    bad = [
        ({"t_eval": [0, math.nan, 1]}, r"t_eval\[1\] = nan: output times must be finite"),
        ({"t_eval": [0, 1, 0.5]}, r"t_eval must be sorted: t_eval\[2\] = 0.5"),
        ({"rtol": 1e300, "atol": 1e300}, "the relative tolerance must be at least 1e-14"),
        ({"atol": 1e300}, "the absolute tolerance must be positive, finite and at most"),
        ({"atol": [1e-9, -1]}, "the absolute tolerance must be positive"),
        ({"max_step": 1e-300}, r"max_step = 1e-300 over a span of 1 means at least 1e\+300"),
        ({"t_eval": np.zeros(10**7 + 1)}, "from 1 to 10000000 are allowed"),
        ({"rtol": "1e-6"}, "rtol must be a number"),
        ({"method": "Euler"}, "unknown method 'Euler'"),
        ({"output": str(tmp_path / "r.json")}, "a results file ends in .csv, .h5, .hdf5"),
    ]
    for kw, match in bad:
        with pytest.raises(jd.EvaluationError, match=match):
            s.simulate((0, 1), y0, yd0, **kw)
    with pytest.raises(jd.EvaluationError, match=r"times must lie within ±1e\+09"):
        s.simulate((0, 1e308), y0, yd0)
    with pytest.raises(jd.EvaluationError, match="the span is below the round-off of t"):
        s.simulate((1e8, 1e8 + 1e-6), y0, yd0)
    # the results of a model with many coordinates are bounded by their memory as well
    from jourdain.simulation.simulate import MAX_OUTPUT_BYTES, check_samples, max_samples

    n = max_samples(200)
    assert n < 10**7 and n * 8 * (2 * 401 + 2 * 604) <= MAX_OUTPUT_BYTES
    with pytest.raises(jd.EvaluationError, match="for a model with f = 200"):
        check_samples(n + 1, 200)


def test_one_set_of_defaults():
    """System.simulate had rtol 1e-6, atol 1e-8, model files 1e-8, 1e-10."""
    from jourdain.simulation.simulate import (
        DEFAULT_ATOL,
        DEFAULT_METHOD,
        DEFAULT_RTOL,
        DEFAULT_SAMPLES,
        DEFAULT_T_END,
    )

    settings = SimulationSettings()
    assert (settings.rtol, settings.atol, settings.method) == (DEFAULT_RTOL, DEFAULT_ATOL,
                                                               DEFAULT_METHOD)
    assert (settings.t_end, settings.samples) == (DEFAULT_T_END, DEFAULT_SAMPLES)
    s = jd.load_model(SIMPLE).system
    res = s.simulate((0, 1), [0.5], [0.0])
    assert res.rtol == DEFAULT_RTOL and np.all(res.atol == DEFAULT_ATOL)
    assert res.method == DEFAULT_METHOD
    same = jd.simulate(s, (0, 1), [0.5], [0.0])
    np.testing.assert_array_equal(same.y, res.y)
    # documented once, with the numbers of jourdain.simulation.simulate
    assert (DEFAULT_RTOL, DEFAULT_ATOL) == (1e-8, 1e-10)
    docs = (ROOT / "docs" / "model-format.md").read_text()
    assert "| `rtol`, `atol` | tolerances" in docs and "1e-8, 1e-10" in docs


def test_method_tolerances_state_and_inputs_from_the_command_line(tmp_path, capsys):
    """--method, --rtol, --atol, --y0, --yd0, --input give the run of the Python API with the
    same settings (the other coordinates and inputs from the model file)."""
    out = tmp_path / "car.csv"
    code, _, err = _run(capsys, "simulate", CAR, "--t-end", "1", "--samples", "11",
                        "--method", "Radau", "--rtol", "1e-9", "--atol", "1e-11",
                        "--y0", "z_b=0.05", "--yd0", "z_w_d=0.1", "--input",
                        "z_r=0.02*sin(8*t)", "--out", out)
    assert code == 0, err
    got = jd.Results.load(out)
    model = jd.load_model(CAR)
    system = model.system
    y0 = dict(zip(system.coordinate_names, model.simulation.y0, strict=True))
    y0["z_b"] = 0.05
    yd0 = dict(zip(system.coordinate_names, model.simulation.yd0, strict=True))
    yd0["z_w"] = 0.1
    t = jd.t
    ref = system.simulate((0, 1), [y0[c] for c in system.coordinate_names],
                          [yd0[c] for c in system.coordinate_names],
                          inputs={"z_r": 0.02 * jd.sin(8 * t)}, method="Radau", rtol=1e-9,
                          atol=1e-11, t_eval=np.linspace(0, 1, 11))
    assert got.method == "Radau" and got.rtol == 1e-9
    np.testing.assert_allclose(got.y, ref.y, rtol=0, atol=1e-15)
    np.testing.assert_allclose(got.u[:, 0], 0.02 * np.sin(8 * got.t), atol=1e-15)


@pytest.mark.parametrize("args, message", [
    (["--y0", "phi9=1"], '--y0: "phi9" is not a coordinate'),
    (["--y0", "phi1"], "--y0: expected name=value"),
    (["--yd0", "phi1_d=__import__('os')"], "--yd0 phi1_d:"),
    (["--input", "F=1"], '--input: "F" is not an input of the model'),
])
def test_state_and_input_options_are_checked(args, message, capsys, no_work):
    code, _, err = _run(capsys, "simulate", PENDULUM, *args)
    assert code == EXIT_USAGE and message in err


def test_input_laws_are_never_python(capsys, no_work):
    code, _, err = _run(capsys, "simulate", CAR, "--input", "z_r=__import__('os').getcwd()")
    assert code == EXIT_USAGE and "--input z_r" in err
    code, _, err = _run(capsys, "simulate", CAR, "--input", "z_r=phi*t")
    assert code == EXIT_USAGE and "unknown name 'phi'" in err


def test_progress_on_request(capsys, monkeypatch):
    monkeypatch.setattr(cli.outputs, "PROGRESS_SECONDS", 0.0)  # read by the printer
    code, _, err = _run(capsys, "simulate", PENDULUM, "--t-end", "5000", "--progress")
    assert code == 0
    lines = [ln for ln in err.splitlines() if ln.startswith("simulating double pendulum: t = ")]
    assert lines and lines[-1].endswith("%)") and " of 5000 (" in lines[-1]
    # not a terminal and not asked: no progress lines
    code, _, err = _run(capsys, "simulate", PENDULUM, "--t-end", "200")
    assert code == 0 and "simulating" not in err


def test_check_refuses_a_model_that_cannot_move(tmp_path, capsys):
    """A model whose only body is massless was "OK": M = 0 at every state."""
    path = tmp_path / "massless.toml"
    path.write_text(SIMPLE.read_text().replace('mass = "m"', "mass = 0"))
    code, _, err = _run(capsys, "check", path)
    assert code == EXIT_MODEL
    assert "the mass matrix M is singular: no mass or inertia moves with phi" in err
    assert 'body "bob"' in err and f"{path}:" in err


def test_failing_radau_run_suggests_something_else():
    x = jd.symbols("x")
    body = jd.Body("b", "world", jd.Prismatic("s", x, "x"), mass=1.0, inertia=jd.point_mass())
    s = jd.System([x], [body], [jd.GeneralizedForce("push", x, x**3)], name="blow-up")
    with pytest.raises(jd.IntegrationError, match=r"try method='Radau'"):
        s.simulate((0, 10), [1.0], [0.0])
    with pytest.raises(jd.IntegrationError) as info:
        s.simulate((0, 10), [1.0], [0.0], method="Radau")
    assert "try method='Radau'" not in str(info.value)
    assert "Radau does not get past it either" in str(info.value)


def test_control_characters_from_a_model_file_are_escaped(tmp_path, capsys):
    """An unknown key holding ESC [31m was echoed raw to the terminal."""
    path = tmp_path / "esc.toml"
    path.write_text(SIMPLE.read_text().replace(
        "[forces.gravity]", '[forces.gravity]\n"\\u001b[31mbad" = 1'))
    code, _, err = _run(capsys, "check", path)
    assert code == EXIT_MODEL
    assert "\x1b" not in err and "\\x1b[31mbad" in err
    assert cli.printable("a\x1b[2J\u202eb\nc\td\r") == "a\\x1b[2J\\u202eb\nc\td\\r"
