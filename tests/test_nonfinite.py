"""No silent NaN (issue 17, item 1): a result that is not finite is an error naming the
quantities, the state and the joint, body or force element at fault, in Python and in every
command (exit status 1)."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import jourdain as jd
from jourdain.cli import main

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


# ------------------------------------------------------------------------------------------
# issue 33, items 3-5: overflow is an error naming the quantity; subnormal and absurd
# magnitudes are located model errors; inf never reaches a factorization
# ------------------------------------------------------------------------------------------

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _variant(tmp_path: Path, name: str, old: str, new: str) -> tuple[Path, str]:
    text = (EXAMPLES / name).read_text()
    assert old in text, old
    text = text.replace(old, new, 1)
    path = tmp_path / name
    path.write_text(text)
    return path, text


def _line(text: str, snippet: str) -> int:
    return next(i for i, ln in enumerate(text.splitlines(), 1) if snippet in ln)


def test_eval_json_refuses_an_overflow_instead_of_writing_null(tmp_path, capsys):
    """Q[1][1] = -1.6e308 is finite, K = ½(Q + Qᵀ) overflows. Before: K[1][1] = null, exit 0,
    nothing in not_available; now exit 1 naming K."""
    path, _ = _variant(tmp_path, "quarter_car.toml", 'value = "-k_t*(z_w - z_r)',
                       'value = "-9e302*k_t*(z_w - z_r)')
    assert main(["eval", str(path), "--json"]) == 1
    cap = capsys.readouterr()
    assert cap.out == "" and "Traceback" not in cap.err
    assert "K overflows (inf" in cap.err and "'quarter car'" in cap.err
    assert "RuntimeWarning" not in cap.err  # NumPy's overflow warning stays off the terminal
    # text output too
    assert main(["eval", str(path)]) == 1
    assert "K overflows" in capsys.readouterr().err


@pytest.mark.parametrize("example, old, new, key", [
    # before: a hang in np.linalg.svd (the machine) or exit 0
    ("rotor_internal_damping.toml", "m = { value = 1.0", "m = { value = 1e-320",
     'parameter "m" → value'),
    # before: LinAlgError: SVD did not converge
    ("simple_pendulum.toml", "m = { value = 1.0", "m = { value = 1e-320",
     'parameter "m" → value'),
    # before: OverflowError: intermediate overflow in fsum (graph/numbers via analysis/cyclic)
    ("vehicle_on_bushings.toml", "k_x = { value = 8.0e4", "k_x = { value = 1e308",
     'parameter "k_x"'),
    ("quarter_car.toml", "k_t = { value = 180000.0", "k_t = { value = 1e308", 'parameter "k_t"'),
    ("rotor_internal_damping.toml", 'mass = "m"', "mass = 1e-320", 'body "disc" → mass'),
])
def test_absurd_magnitudes_are_located_model_errors(example, old, new, key, tmp_path):
    path, text = _variant(tmp_path, example, old, new)
    proc = subprocess.run([sys.executable, "-m", "jourdain.cli", "check", str(path)],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 1, proc.stdout + proc.stderr
    assert "Traceback" not in proc.stderr
    assert f"{path}:{_line(text, new)}: {key}" in proc.stderr, proc.stderr
    assert ("subnormal" if "e-320" in new else "too large") in proc.stderr


def test_set_and_the_python_api_check_magnitudes_too(tmp_path, capsys):
    # a subnormal number is no number the command line takes (usage error)
    assert main(["eval", str(EXAMPLES / "simple_pendulum.toml"), "--set", "m=1e-320"]) == 2
    err = capsys.readouterr().err
    assert '--set m: "1e-320" is not a number' in err and "subnormal" in err
    assert main(["eval", str(EXAMPLES / "simple_pendulum.toml"), "--set", "l=1e151"]) == 1
    assert 'parameter "l": 1e+151 is too large' in capsys.readouterr().err
    x = jd.symbols("x")
    body = jd.Body("b", "world", jd.Prismatic("p", x, "x"), mass=1.0, inertia=jd.point_mass())
    for value in (1e-320, 1e200, -1e308):
        with pytest.raises(jd.ModelError, match='parameter "k": .*magnitude must be 0 or'):
            jd.System([x], [body], parameters={"k": value})
    jd.System([x], [body], parameters={"k": 0.0, "c": 1e-150, "d": -1e150})  # the bounds


SOLVE_INF = """
import numpy as np
from jourdain.analysis.reactions import solve_g
N = np.array([[np.inf, 1.0], [1.0, 2.0]])
try:
    solve_g(np.eye(6)[:, :2], N, np.zeros(2), np.zeros(2), np.zeros(6), np.zeros(6), [5])
except Exception as exc:
    print(type(exc).__name__, exc)
"""


def test_inf_never_reaches_a_factorization():
    """solve_g with a bordered system holding inf. Before: np.linalg.svd of it, which on this
    matrix loops without end in LAPACK, deaf to Ctrl-C (hence the child process and its
    timeout); now an EvaluationError naming N_hat."""
    proc = subprocess.run([sys.executable, "-c", SOLVE_INF], capture_output=True, text=True,
                          timeout=120)
    assert proc.stdout.startswith("EvaluationError N_hat contains NaN or inf"), proc
    from jourdain.workflow import mass_matrix_problem

    s = _spring_system()
    assert "not finite" in mass_matrix_problem(s, np.array([[1.7e308, 1.7e308],
                                                            [1.7e308, np.inf]]), {})


def test_float_sums_overflow_to_inf_instead_of_raising():
    """math.fsum raises OverflowError (1e308 + 1e308) and ValueError (inf − inf); the
    evaluation in floating point gives inf and NaN, which its callers check."""
    from jourdain.graph import evaluate_float

    a, b = jd.symbols("a b")
    assert evaluate_float([a + b], {"a": 1e308, "b": 1e308}) == [np.inf]
    assert np.isnan(evaluate_float([a * b - a * b + a + b],
                                   {"a": np.inf, "b": -np.inf})[0])
