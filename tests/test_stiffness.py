"""Issue 33, item 9: a stiff model run with an explicit method says so ("stiff: try
`--method Radau`") instead of taking a million steps per simulated second without a word;
Radau steps over the fast motion where it is not excited, and says when it has to follow it
(an explicit method is then the faster one)."""

from __future__ import annotations

import warnings

import pytest

import jourdain as jd
from jourdain.cli import main
from jourdain.errors import StiffnessWarning

#: two unit masses on a soft spring (1 N/m), joined by a stiff one (1e12 N/m), no damping
STIFF = """
[model]
name = "stiff pair"
[coordinates]
x1 = "m"
x2 = "m"
[parameters]
m = 1.0
k = 1.0
K = 1e12
[bodies.a]
parent = "world"
mass = "m"
inertia = "point"
joint = {{ type = "prismatic", coordinate = "x1", axis = "x" }}
[bodies.b]
parent = "world"
mass = "m"
inertia = "point"
joint = {{ type = "prismatic", coordinate = "x2", axis = "x" }}
[forces.soft]
type = "generalized"
coordinate = "x1"
value = "-k*x1 + K*(x2 - x1)"
[forces.stiff]
type = "generalized"
coordinate = "x2"
value = "-K*(x2 - x1)"
[simulation]
t_end = {t_end}
y0 = {{ x1 = 0.1, x2 = {x2} }}
"""


def _model(tmp_path, t_end: float, x2: str = "0.1") -> str:
    path = tmp_path / "stiff.toml"
    path.write_text(STIFF.format(t_end=t_end, x2=x2))
    return str(path)


def test_an_explicit_method_held_by_stability_says_try_radau(tmp_path, capsys):
    """Before: 120 000 steps for 0.1 s and nothing said."""
    assert main(["simulate", _model(tmp_path, 0.1)]) == 0
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if "warning" in ln]
    assert len(lines) == 1, err
    assert lines[0].startswith("jourdain simulate: warning: stiff: try `--method Radau`: the "
                               "explicit method's step size is held at its stability limit")
    assert "h·|λ| = " in lines[0] and "1.41e+06 1/s" in lines[0]
    # Python: the warning names the keyword, once per run
    model = jd.load_model(_model(tmp_path, 0.1))
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        for method in ("DOP853", "RK45"):
            model.system.simulate((0, 0.1), [0.1, 0.1], [0, 0], method=method)
    stiff = [w for w in seen if w.category is StiffnessWarning]
    assert len(stiff) == 2 and all('stiff: try method="Radau"' in str(w.message) for w in stiff)


def test_radau_steps_over_the_stiff_spring(tmp_path, capsys):
    """The same run with Radau: a few hundred steps for the whole 10 s, no warning."""
    model = jd.load_model(_model(tmp_path, 10.0))
    with warnings.catch_warnings():
        warnings.simplefilter("error", StiffnessWarning)
        res = model.system.simulate((0, 10), [0.1, 0.1], [0, 0], method="Radau")
    assert res.status == "finished" and res.nsteps < 2000
    ref = model.system.simulate((0, 0.02), [0.1, 0.1], [0, 0], method="DOP853",
                                t_eval=[0.02])
    fast = model.system.simulate((0, 0.02), [0.1, 0.1], [0, 0], method="Radau", t_eval=[0.02])
    assert fast.y[-1] == pytest.approx(ref.y[-1], rel=1e-6)


def test_radau_following_an_excited_fast_motion_says_an_explicit_method_is_faster(tmp_path,
                                                                                   capsys):
    """x2 − x1 = 1e-4 at the start: the 1.4e6 rad/s mode oscillates undamped at 140 m/s, which
    every method must follow; Radau (third-order error estimate) takes some 25 times DOP853's
    steps. It says so (before: nothing, > 120 s for a few seconds of motion)."""
    path = _model(tmp_path, 0.002, x2="0.1001")
    assert main(["simulate", path, "--method", "Radau"]) == 0
    err = capsys.readouterr().err
    assert "jourdain simulate: warning: not stiff: try `--method DOP853`: Radau follows every " \
           "oscillation of the fastest motion" in err
    assert main(["simulate", path]) == 0  # DOP853 follows it without a word
    assert "warning" not in capsys.readouterr().err


def test_the_examples_run_without_a_stiffness_warning():
    from pathlib import Path

    root = Path(__file__).resolve().parents[1] / "examples"
    with warnings.catch_warnings():
        warnings.simplefilter("error", StiffnessWarning)
        for name in ("quarter_car", "robot_arm", "double_pendulum"):
            model = jd.load_model(root / f"{name}.toml")
            for method in ("DOP853", "Radau"):
                model.system.simulate((0, 20), model.simulation.y0 or None,
                                      model.simulation.yd0 or None, method=method,
                                      inputs={u: 0.0 for u in model.system.input_names})
