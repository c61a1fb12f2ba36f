"""No silent NaN (issue 17, item 1): a result that is not finite is an error naming the
quantities, the state and the joint, body or force element at fault, in Python and in every
command (exit status 1)."""

import subprocess
import sys

import numpy as np
import pytest

import jourdain as jd

SPRING = """
[model]
name = "zero length spring"

[coordinates]
x = { unit = "m" }

[parameters]
m = { value = 1.0 }
k = { value = 10.0 }

[bodies.slider]
parent = "world"
mass = "m"
inertia = "point"
joint = { type = "prismatic", name = "guide", coordinate = "x", axis = "x" }

[forces.spring]
type = "spring_damper"
body_a = "world"
point_a = [0, 0, 0]
body_b = "slider"
point_b = [0, 0, 0]
stiffness = "k"
rest_length = "0.5"
"""


def _spring_system() -> jd.System:
    x = jd.symbols("x")
    body = jd.Body("slider", "world", jd.Prismatic("guide", x, "x"), mass=1.0,
                   inertia=jd.point_mass())
    return jd.System([x], [body], [jd.SpringDamper("spring", "world", (0, 0, 0), "slider",
                                                   (0, 0, 0), stiffness=10.0, rest_length=0.5)])


def test_evaluate_names_the_force_element():
    s = _spring_system()
    assert np.isfinite(s.evaluate([0.3], [0.0])["q"]).all()  # fine away from zero length
    with pytest.raises(jd.EvaluationError, match=r'q_e, q of .* NaN or inf at t = 0, state x=0;'
                       r'.*force "spring" \(SpringDamper\)'):
        s.evaluate([0.0], [0.0])


def test_evaluate_names_the_joint():
    """A joint whose step has no real value at the state (a square root of a negative
    number) is named."""
    x = jd.symbols("x")
    joint = jd.General("slide", [jd.Trans("x", jd.sqrt(x))], coordinates=[x])
    s = jd.System([x], [jd.Body("b", "world", joint, mass=1.0, inertia=jd.point_mass())],
                  [jd.Gravity((0, 0, -9.81))])
    assert np.isfinite(s.evaluate([0.25], [1.0])["M"]).all()
    with pytest.raises(jd.EvaluationError, match=r'joint "slide" \(body "b"\)'):
        s.evaluate([-0.25], [1.0])


@pytest.mark.parametrize("command", [["eval", "--at", "x=0"], ["check"],
                                     ["simulate", "--t-end", "0.5"]])
def test_commands_exit_1_naming_the_spring(command, tmp_path):
    path = tmp_path / "spring.toml"
    path.write_text(SPRING)
    extra = ["--out", str(tmp_path / "out.csv")] if command[0] == "simulate" else []
    proc = subprocess.run([sys.executable, "-m", "jourdain.cli", command[0], str(path),
                           *command[1:], *extra], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 1, proc.stdout + proc.stderr
    assert 'force "spring" (SpringDamper)' in proc.stderr
    assert "Traceback" not in proc.stderr
