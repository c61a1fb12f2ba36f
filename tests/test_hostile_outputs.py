"""What hostile input could do to the files jourdain writes and loads (issue 17, item 3): a name
that would put live TeX commands into equations.tex or shift a CSV header, an infinite constant
that the C compiler would read as a name, and compiled libraries that someone else could have
placed in the cache."""

import dataclasses
import json
import os
import stat
import subprocess
import warnings

import numpy as np
import pytest
import symengine as se

import jourdain as jd
from jourdain.errors import EvaluationError
from jourdain.io import export, loads_model
from jourdain.io.report import write_report
from jourdain.numeric import toolchain
from jourdain.numeric.ccode import function_source
from jourdain.simulation.results import Results

EVIL = "pendulum\n\\immediate\\write18{touch pwned}\r\\input{/etc/passwd}\u2028\\def\\x{1}"

MODEL = """\
[coordinates]
phi = "rad"
[parameters]
m = 1.0
l = 1.0
g = 9.81
[bodies.bob]
parent = "world"
mass = "m"
com = [0, "-l", 0]
inertia = "point"
joint = { type = "revolute", coordinate = "phi", axis = "z" }
[forces.gravity]
type = "gravity"
vector = [0, "-g", 0]
[simulation]
t_end = 0.2
samples = 11
y0 = { phi = 0.3 }
"""


def test_a_latex_comment_holds_one_line_whatever_the_text():
    line = export.latex_comment(EVIL)
    assert line.startswith("% ") and len(line.splitlines()) == 1
    assert "\\immediate" in line  # kept, but inside the comment


def test_equations_tex_csv_json_and_html_keep_a_hostile_name_inert(tmp_path):
    path = tmp_path / "model.toml"
    path.write_text(MODEL)
    mf = loads_model(MODEL, str(path))
    s = mf.system
    evil = jd.System(s.coordinates, s.bodies, s.forces, parameters=s.parameter_values, name=EVIL)
    write_report(dataclasses.replace(mf, system=evil), tmp_path / "out")
    out = tmp_path / "out"
    # TeX: every line that is not a comment is an equation, the column count or empty; the
    # name only in comments
    for line in (out / "equations.tex").read_text().splitlines():
        assert (line.startswith("%") or not line.strip() or "=" in line
                or line.startswith("\\setcounter{MaxMatrixCols}")), line
        assert "\\immediate" not in line or line.startswith("% "), line
        assert "\\input" not in line or line.startswith("% "), line
    # JSON: the name round-trips
    assert json.loads((out / "equations.json").read_text())["model"] == EVIL
    assert json.loads((out / "values.json").read_text())["model"] == EVIL
    # HTML: escaped, so no element comes from the name
    html = (out / "report.html").read_text()
    assert "<h1>pendulum\n\\immediate\\write18{touch pwned}" in html
    # CSV: the header keeps one line per entry and the file reads back
    res = Results.load(out / "simulation.csv")
    assert res.coordinate_names == ["phi"] and len(res.t) == 11
    assert res.name.startswith("pendulum \\immediate")


def test_a_csv_header_with_a_line_break_in_the_name_reads_back(tmp_path):
    phi = jd.symbols("phi")
    m = jd.Body("bob", "world", jd.Revolute("pivot", phi), mass=1.0, com=(0, -1, 0),
                inertia=jd.point_mass())
    system = jd.System([phi], [m], [jd.Gravity((0, -9.81, 0))], name="two\nlines")
    res = system.simulate((0.0, 0.1), [0.2], [0.0], t_eval=np.linspace(0, 0.1, 5))
    back = Results.load(res.save(tmp_path / "r.csv"))
    np.testing.assert_array_equal(back.y, res.y)
    assert back.name == "two lines"


def test_c_code_never_holds_inf_or_nan_and_the_error_names_the_expression():
    l = se.Symbol("l")
    with pytest.raises(EvaluationError, match=r"cannot generate C code in expression 1 of 2, "
                       r"-inf\.0\*l: the number -inf\.0 is not a finite double"):
        function_source("f", [2 * l, -l * se.Float(1e308) * se.Float(1e308)], {"l": "p[0]"})
    with pytest.raises(EvaluationError, match="is not a finite double"):
        function_source("f", [l * se.Integer(10) ** 400], {"l": "p[0]"})
    # a rational whose numerator and denominator overflow but whose value does not
    src = function_source("f", [l + se.Rational(10**400 + 1, 10**400)], {"l": "p[0]"})
    assert "out[0] = (1.0 + p[0]);" in src


# ------------------------------------------------------------------------------------------
# the cache of compiled libraries
# ------------------------------------------------------------------------------------------

SOURCE = "double jd_answer(void) { return %d.0; }\n"


@pytest.fixture
def fresh_toolchain(monkeypatch, tmp_path):
    """A toolchain with nothing loaded and its cache in ``tmp_path/cache`` (not yet created)."""
    try:
        toolchain.compiler()
    except toolchain.CompilerError:
        pytest.skip("no C compiler")
    monkeypatch.setattr(toolchain, "_loaded", {})
    monkeypatch.setattr(toolchain, "_fallback", None)
    monkeypatch.setenv("JOURDAIN_CACHE", str(tmp_path / "cache"))
    return tmp_path / "cache"


def _answer(lib) -> float:
    import ctypes

    lib.jd_answer.restype = ctypes.c_double
    return lib.jd_answer()


def test_the_cache_is_created_private(fresh_toolchain):
    key = toolchain.content_key("answer-1")
    assert _answer(toolchain.build(key, SOURCE % 1)) == 1.0
    for p in (fresh_toolchain, fresh_toolchain / f"{key}.so"):
        mode = os.stat(p).st_mode
        assert not mode & (stat.S_IWGRP | stat.S_IWOTH), stat.filemode(mode)


def plant(directory, key: str, value: int) -> None:
    """A library under ``key`` in ``directory`` that jourdain did not build (nor load)."""
    directory.mkdir(exist_ok=True)
    source = directory / "planted.c"
    source.write_text(SOURCE % value)
    subprocess.run([toolchain.compiler(), *toolchain.CFLAGS, "-o", str(directory / f"{key}.so"),
                    str(source)], check=True)


def test_a_library_writable_by_others_is_rebuilt_not_loaded(fresh_toolchain):
    key = toolchain.content_key("answer-2")
    plant(fresh_toolchain, key, 666)
    so = fresh_toolchain / f"{key}.so"
    os.chmod(fresh_toolchain, 0o700)
    os.chmod(so, 0o666)  # a file that anyone may have written
    assert toolchain.cached_library(key) is None
    assert _answer(toolchain.build(key, SOURCE % 2)) == 2.0
    assert not os.stat(so).st_mode & (stat.S_IWGRP | stat.S_IWOTH)


@pytest.mark.skipif(not hasattr(os, "getuid") or os.getuid() != 0,
                    reason="giving a file to another user needs root")
def test_a_library_of_another_user_is_not_loaded(fresh_toolchain):
    key = toolchain.content_key("answer-3")
    plant(fresh_toolchain, key, 666)
    os.chmod(fresh_toolchain, 0o700)
    os.chown(fresh_toolchain / f"{key}.so", 12345, 12345)
    assert toolchain.cached_library(key) is None
    assert _answer(toolchain.build(key, SOURCE % 3)) == 3.0


def test_a_cache_directory_writable_by_others_is_not_used(fresh_toolchain):
    key = toolchain.content_key("answer-4")
    plant(fresh_toolchain, key, 666)  # in a shared directory, under the key jourdain looks for
    os.chmod(fresh_toolchain, 0o777)
    toolchain._loaded.clear()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        lib = toolchain.build(key, SOURCE % 4)
    assert _answer(lib) == 4.0
    assert any("does not use its compile cache" in str(w.message)
               and "writable by" in str(w.message) for w in caught)
    private = toolchain.library_dir()
    assert private != fresh_toolchain and (private / f"{key}.so").exists()
    assert not os.stat(private).st_mode & (stat.S_IRWXG | stat.S_IRWXO)
