"""Hostile and extreme model files (issue 17, item 3): numbers that would exhaust memory or crash
the big-integer library, values that are not finite real numbers, physically impossible frames
and inertias, absurd sizes and nesting. Each is refused with exit status 1 and a message naming
the file, the line and the key, never a traceback. Work that could run away (huge powers, a
file of unbounded size) runs in a child process under limits of memory and processor time
(killed, and the test failed, beyond them), or is bounded by what it reads and by the Python
lines it executes: measures that a loaded machine does not change. Wall-clock times are for
benchmarks (benchmarks/hostile_files.py), never for these tests."""

import math
import os
import resource
import subprocess
import sys
import textwrap

import pytest
import symengine as se

import jourdain as jd
from jourdain.cli import main
from jourdain.io import ModelFileError, load_model, loads_model
from jourdain.io.expressions import ExpressionError, parse_expression
from jourdain.io.modelfile import MAX_FILE_BYTES
from jourdain.io.modelfile import loader as loader_module
from jourdain.io.toml_positions import key_lines

BASE = textwrap.dedent('''\
    [model]
    name = "hostile"
    [coordinates]
    phi = "rad"
    [parameters]
    m1 = 1.0
    l1 = 1.0
    g = 9.81
    [bodies.rod]
    parent = "world"
    mass = "m1"
    com = [0, "-l1/2", 0]
    inertia = { rod = { length = "l1", axis = "y" } }
    joint = { type = "revolute", coordinate = "phi", axis = "z" }
    [forces.gravity]
    type = "gravity"
    vector = [0, "-g", 0]
    ''')
JOINT = 'joint = { type = "revolute", coordinate = "phi", axis = "z" }'


def variant(old: str, new: str) -> str:
    assert old in BASE, old
    return BASE.replace(old, new, 1)


def line_of(text: str, snippet: str) -> int:
    return next(i + 1 for i, ln in enumerate(text.splitlines()) if snippet in ln)


def check(tmp_path, text: str, capsys) -> tuple[int, str, str]:
    path = tmp_path / "model.toml"
    path.write_text(text)
    code = main(["check", str(path)])
    out = capsys.readouterr()
    assert "Traceback" not in out.err
    return code, out.err, str(path)


def refused(tmp_path, capsys, text: str, key: str, snippet: str, message: str) -> str:
    """``jourdain check`` of ``text`` exits with 1, naming file:line (of ``snippet``), the key
    and ``message``."""
    code, err, path = check(tmp_path, text, capsys)
    assert code == 1, err
    assert f"{path}:{line_of(text, snippet)}: {key}" in err, err
    assert message in err, err
    return err


#: processor seconds a child ``jourdain check`` may use (about 0.4 s are needed, imports
#: included): beyond it the kernel stops the child (SIGXCPU), whatever the machine's load
CPU_SECONDS = 30


def _limits() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))
    resource.setrlimit(resource.RLIMIT_CPU, (CPU_SECONDS, CPU_SECONDS))


def check_isolated(path) -> subprocess.CompletedProcess:
    """``jourdain check path`` in a child process with 2 GB of address space and
    :data:`CPU_SECONDS` of processor time: a crash (SIGFPE of the big-integer library), a
    runaway allocation or computation there ends the child, never the test run."""
    return subprocess.run([sys.executable, "-m", "jourdain.cli", "check", str(path)],
                          capture_output=True, text=True, preexec_fn=_limits)


def run_isolated(tmp_path, text: str) -> subprocess.CompletedProcess:
    path = tmp_path / "model.toml"
    path.write_text(text)
    return check_isolated(path)


def python_lines(fn, *args):
    """``fn(*args)`` and the number of Python lines it executed (``sys.settrace``): a measure
    of work that does not depend on the machine or its load."""
    count = 0

    def tracer(frame, event, arg):
        nonlocal count
        if event == "line":
            count += 1
        return tracer

    sys.settrace(tracer)
    try:
        value = fn(*args)
    finally:
        sys.settrace(None)
    return value, count


# ------------------------------------------------------------------------------------------
# exact numbers of unbounded size
# ------------------------------------------------------------------------------------------

@pytest.mark.parametrize("mass", ["(((2^999)^999)^999)^999", "((1000^1000)^1000)^1000",
                                  "(2^999*m1)^999", "((2^(1/2))^999)^999"])
def test_powers_that_would_build_huge_numbers_are_refused(mass, tmp_path):
    text = variant('mass = "m1"', f'mass = "{mass}"')
    proc = run_isolated(tmp_path, text)
    assert proc.returncode == 1, (proc.returncode, proc.stderr[-2000:])
    assert "Traceback" not in proc.stderr
    assert f"model.toml:{line_of(text, 'mass = ')}: body \"rod\" → mass: in expression" in proc.stderr
    assert "this power would build a number of about" in proc.stderr


def test_the_size_of_every_exact_intermediate_is_bounded():
    # each operand small, their products and sums large
    for text in ("(1000^1000)*(1000^1000)*(1000^1000)", "2^999*2^999*2^999*" * 4 + "x",
                 "(2*x)^1000^1000", "x^(10^400)"):
        with pytest.raises(ExpressionError):
            parse_expression(text)
    # exact arithmetic within the bound still cancels to what it is
    assert parse_expression("10^400/10^399*x") == 10 * se.Symbol("x")
    assert parse_expression("(1000^1000)/(1000^999)") == 1000
    # a result beyond floating point is refused: no C literal can hold it
    with pytest.raises(ExpressionError, match="too large for a floating-point number"):
        parse_expression("10^400")


def test_huge_integers_and_decimals_are_refused_with_their_key(tmp_path, capsys):
    digits401 = "1" + "0" * 400
    text = variant("m1 = 1.0", f"m1 = {digits401}")
    refused(tmp_path, capsys, text, 'parameter "m1"', "m1 = 1000",
            "the integer of 401 digits is too large for a floating-point number")
    text = variant('mass = "m1"', f"mass = {digits401}")
    refused(tmp_path, capsys, text, 'body "rod" → mass', "mass = 1000", "401 digits")
    # beyond Python's limit of int-string conversion (4300 digits): tomllib raises ValueError
    text = variant("m1 = 1.0", "m1 = 1" + "0" * 19990)
    refused(tmp_path, capsys, text, "a number the TOML reader refuses", "m1 = 1000",
            "4300 digits")
    text = variant('mass = "m1"', 'mass = "1.' + "0" * 19990 + '"')
    refused(tmp_path, capsys, text, 'body "rod" → mass', "mass = ", "is too long")
    text = variant('mass = "m1"', 'mass = "1e99999999"')
    refused(tmp_path, capsys, text, 'body "rod" → mass', "mass = ", "is too large")


def test_a_mass_of_1e300_gives_no_overflow_in_the_reactions(tmp_path, capsys):
    # the singular-row test of the reactions raised s^3 for s = 1e299: OverflowError
    text = variant('mass = "m1"', 'mass = "1e300"')
    code, err, _ = check(tmp_path, text, capsys)
    assert code == 0, err
    reactions = loads_model(text).system.reactions()
    assert len(reactions.g_names) == 5


# ------------------------------------------------------------------------------------------
# values that are not finite real numbers
# ------------------------------------------------------------------------------------------

@pytest.mark.parametrize("old, new, key, snippet", [
    ('com = [0, "-l1/2", 0]', 'com = [0, "sqrt(-l1)", 0]', 'body "rod" → com[1]', "com = "),
    ('com = [0, "-l1/2", 0]', 'com = [0, "1/(l1 - 1)", 0]', 'body "rod" → com[1]', "com = "),
    ('mass = "m1"', 'mass = "log(m1 - 1)"', 'body "rod" → mass', "mass = "),
    (JOINT, JOINT[:-2] + ', position = ["acos(2*l1)", 0, 0] }',
     'body "rod" → joint → position[0]', "joint = "),
    ('vector = [0, "-g", 0]', 'vector = [0, "-sqrt(-g)", 0]', 'force "gravity" → vector[1]',
     "vector = "),
])
def test_values_without_a_finite_real_value_are_refused_where_given(old, new, key, snippet,
                                                                   tmp_path, capsys):
    refused(tmp_path, capsys, variant(old, new), key, snippet,
            "is not a finite real number at the default parameter values")


def test_complex_and_infinite_constants_are_refused_where_given(tmp_path, capsys):
    text = variant('com = [0, "-l1/2", 0]', 'com = [0, "-l1*1e308*1e308", 0]')
    refused(tmp_path, capsys, text, 'body "rod" → com[1]', "com = ", "is infinite")
    text = variant('com = [0, "-l1/2", 0]', 'com = [0, "(-8)^(1/3)", 0]')
    refused(tmp_path, capsys, text, 'body "rod" → com[1]', "com = ", "not a finite real number")
    text = BASE + '[simulation]\ny0 = { phi = "sqrt(-l1)" }\n'
    refused(tmp_path, capsys, text, "[simulation] → y0 → phi", "y0 = ",
            "is not a finite real number")


# ------------------------------------------------------------------------------------------
# frames and inertias that no rigid body has
# ------------------------------------------------------------------------------------------

@pytest.mark.parametrize("matrix, message", [
    ("[[2, 0, 0], [0, 1, 0], [0, 0, 1]]", "is not a rotation matrix"),
    ("[[1, 0, 0], [0, 1, 0], [0, 0, 0]]", "is not a rotation matrix"),  # singular
    ("[[0.7071, -0.7071, 0], [0.7071, 0.7071, 0], [0, 0, 1]]", "is not a rotation matrix"),
    ("[[-1, 0, 0], [0, 1, 0], [0, 0, 1]]", "is a reflection"),
    ('[["l1", 0, 0], [0, 1, 0], [0, 0, "2*l1"]]', "is not a rotation matrix"),
])
def test_an_orientation_that_is_not_a_rotation_is_refused(matrix, message, tmp_path, capsys):
    text = variant(JOINT, JOINT[:-2] + f", orientation = {matrix} }}")
    err = refused(tmp_path, capsys, text, 'body "rod" → joint → orientation', "joint = ",
                  'the orientation of joint "rod"')
    assert message in err


def test_rotations_are_accepted_as_orientations():
    for matrix in ('[["sqrt(2)/2", "-sqrt(2)/2", 0], ["sqrt(2)/2", "sqrt(2)/2", 0], [0, 0, 1]]',
                   "[[0, -1, 0], [1, 0, 0], [0, 0, 1]]", "[[0.6, -0.8, 0], [0.8, 0.6, 0], [0, 0, 1]]",
                   '[["cos(l1)", "-sin(l1)", 0], ["sin(l1)", "cos(l1)", 0], [0, 0, 1]]'):
        loads_model(variant(JOINT, JOINT[:-2] + f", orientation = {matrix} }}"))


def test_the_python_api_refuses_an_orientation_that_is_not_a_rotation():
    phi = jd.symbols("phi")
    for matrix, message in (([[2, 0, 0], [0, 1, 0], [0, 0, 1]], "not a rotation matrix"),
                            ([[1, 0, 0], [0, 1, 0], [0, 0, -1]], "is a reflection")):
        with pytest.raises(jd.ModelError, match=f'joint "hinge": the orientation .*{message}'):
            jd.Revolute("hinge", phi, "z", orientation=matrix)
        with pytest.raises(jd.ModelError, match='joint "weld"'):
            jd.Fixed("weld", orientation=matrix)
    c, s = math.cos(0.3), math.sin(0.3)
    jd.Revolute("hinge", phi, "z", orientation=[[1, 0, 0], [0, c, -s], [0, s, c]])


@pytest.mark.parametrize("inertia", ["[1, 1, 5]", "[[1, 0, 0], [0, 1, 0], [0, 0, 2.1]]",
                                     '["l1", "l1", "3*l1"]'])
def test_an_inertia_that_violates_the_triangle_inequality_is_refused(inertia, tmp_path, capsys):
    text = variant('inertia = { rod = { length = "l1", axis = "y" } }', f"inertia = {inertia}")
    refused(tmp_path, capsys, text, 'body "rod" → inertia', "inertia = ",
            "exceeds the sum of the other two")


def test_the_python_api_refuses_an_impossible_inertia_naming_the_body():
    phi = jd.symbols("phi")
    with pytest.raises(jd.ModelError, match='body "bob": inertia tensor is not that of a rigid '
                       "body: its largest principal moment 5"):
        jd.Body("bob", "world", jd.Revolute("pivot", phi), mass=1, inertia=(1, 1, 5))
    # the limiting cases are rigid bodies: a thin rod, a thin disc
    jd.Body("rod", "world", jd.Revolute("p1", phi), mass=1, inertia=jd.rod(1, 1.0))
    jd.Body("disc", "world", jd.Revolute("p2", phi), mass=1, inertia=jd.disc(1, 0.3))


def test_an_infinite_constant_from_the_python_api_is_refused():
    phi, m = jd.symbols("phi m")
    with pytest.raises(jd.ModelError, match='body "bob" mass: .* contains the non-finite'):
        jd.Body("bob", "world", jd.Revolute("pivot", phi), mass=m * se.Float(1e308) * 1e308,
                inertia=jd.point_mass())


# ------------------------------------------------------------------------------------------
# --set is checked like the file
# ------------------------------------------------------------------------------------------

@pytest.mark.parametrize("assignment, message", [
    ("m1=-1", 'body "rod": mass must be a non-negative number, got -1'),
    ("m1=2", None),
])
def test_parameters_set_on_the_command_line_are_checked(assignment, message, tmp_path, capsys):
    path = tmp_path / "model.toml"
    path.write_text(BASE)
    code = main(["eval", str(path), "--set", assignment])
    err = capsys.readouterr().err
    if message is None:
        assert code == 0, err
        return
    assert code == 1, err
    assert f"with --set {assignment}: {message}" in err and "Traceback" not in err


def test_set_that_makes_an_orientation_a_non_rotation_is_refused(tmp_path, capsys):
    text = variant("g = 9.81", "g = 9.81\na = 1.0").replace(
        JOINT, JOINT[:-2] + ', orientation = [["a", 0, 0], [0, "a", 0], [0, 0, 1]] }')
    path = tmp_path / "model.toml"
    path.write_text(text)
    assert main(["eval", str(path), "--set", "a=1"]) == 0
    capsys.readouterr()
    for command in ("eval", "reactions", "linearize", "simulate"):
        assert main([command, str(path), "--set", "a=2"]) == 1
        err = capsys.readouterr().err
        assert ('with --set a=2: joint "rod": the orientation [2, 0, 0; 0, 2, 0; 0, 0, 1] is not '
                "a rotation matrix") in err, err


# ------------------------------------------------------------------------------------------
# size and nesting
# ------------------------------------------------------------------------------------------

def test_a_50_mb_file_is_refused_at_once(tmp_path, capsys, monkeypatch):
    path = tmp_path / "big.toml"
    with open(path, "w") as fh:
        fh.write(BASE.replace("[parameters]\n", "[parameters]\n"))
        line = "# " + "x" * 98 + "\n"
        fh.write(line * (50_000_000 // len(line)))
    reads: list[int] = []

    class Counted:
        """The file object, its reads' sizes recorded."""

        def __init__(self, fh):
            self.fh = fh

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.fh.close()

        def fileno(self):
            return self.fh.fileno()

        def read(self, n=-1):
            data = self.fh.read(n)
            reads.append(len(data))
            return data

    monkeypatch.setattr(loader_module, "open", lambda *a, **k: Counted(open(*a, **k)),
                        raising=False)
    code = main(["check", str(path)])
    # refused from its first MAX_FILE_BYTES + 1 bytes: the rest is never read, nothing parsed
    assert reads and sum(reads) <= MAX_FILE_BYTES + 1
    err = capsys.readouterr().err
    assert code == 1 and f"{path}: the file is too large (50.0 MB); model files are at most 4 MB" in err
    with pytest.raises(ModelFileError, match="at most 4 MB"):
        loads_model(path.read_text())


def test_a_file_just_under_the_limit_is_read_and_its_mistake_located(tmp_path):
    # its time is measured by benchmarks/hostile_files.py
    params = "".join(f"p{i} = {{ value = {i}.5, unit = \"kg\" }}\n" for i in range(80_000))
    text = BASE.replace("[parameters]\n", "[parameters]\n" + params).replace(
        'axis = "z" }', 'axis = "w" }')
    assert 3_000_000 < len(text) <= MAX_FILE_BYTES
    path = tmp_path / "large.toml"
    path.write_text(text)
    with pytest.raises(ModelFileError) as info:
        load_model(path)
    assert info.value.line == line_of(text, 'axis = "w"')
    assert 'body "rod" → joint → axis' in str(info.value)


def test_key_lines_work_grows_with_the_keys_not_the_characters():
    # 3 MB of comments and strings: the old scanner read every character in Python (~4 s);
    # the work is counted in Python lines executed, which no machine or load changes
    text = ("# " + "c" * 1_000_000 + "\n" + 'd = "' + "s" * 1_000_000 + '"\n'
            + "e = '''" + "m\n" * 500_000 + "'''\n" + BASE)
    small = "# c\n" + 'd = "s"\n' + "e = '''m\n'''\n" + BASE  # the same keys
    lines, work = python_lines(key_lines, text)
    _, small_work = python_lines(key_lines, small)
    assert work < 2 * small_work, (work, small_work)
    assert lines[("bodies", "rod", "mass")] == line_of(text, 'mass = "m1"')


@pytest.mark.parametrize("value", ["{ a = " * 5000 + "1" + " }" * 5000,
                                   "[" * 100_000 + "]" * 100_000])
def test_deeply_nested_values_are_refused_with_their_key(value, tmp_path, capsys):
    text = BASE + f"[simulation]\ny0 = {value}\n"
    refused(tmp_path, capsys, text, "[simulation] → y0", "y0 = ",
            "arrays or inline tables nested too deeply")


def test_special_files_are_read_only_up_to_the_limit():
    if not os.path.exists("/dev/zero"):
        pytest.skip("no /dev/zero")
    # in a child: a reader that went on reading would exhaust its memory or processor limit
    proc = check_isolated("/dev/zero")
    assert proc.returncode == 1, (proc.returncode, proc.stderr[-2000:])
    assert "/dev/zero: the file is too large" in proc.stderr


# ------------------------------------------------------------------------------------------
# user strings that reach the output files
# ------------------------------------------------------------------------------------------

@pytest.mark.parametrize("old, new, key", [
    ('name = "hostile"', 'name = "x\\n\\\\immediate\\\\write18{rm -rf ~}"', "[model] → name"),
    ('phi = "rad"', 'phi = "rad\\r\\nx"', 'coordinate "phi"'),
    ("m1 = 1.0", 'm1 = { value = 1.0, unit = "kg\\u2028x" }', 'parameter "m1" → unit'),
])
def test_names_and_units_are_one_line_of_text(old, new, key, tmp_path, capsys):
    text = variant(old, new)
    refused(tmp_path, capsys, text, key, new.split(" = ")[0] + " = ",
            "expected one line of text, got a string with the control character")
