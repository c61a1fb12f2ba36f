"""What a person reads: symbolic matrices simplified for display (repr, Jupyter's LaTeX, the
text and LaTeX exports, within a time budget), a LaTeX fragment that compiles, and numbers in
the command's text output without round-off noise, with units and the state used — issue 17,
items 11 and 12."""

import re
import shutil
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest

import jourdain as jd
from jourdain.cli import main, reaction_units
from jourdain.io import export
from jourdain.models import double_pendulum, spatial_chain

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"


def run(capsys, *args) -> str:
    code = main([str(a) for a in args])
    out = capsys.readouterr()
    assert code == 0, out.err
    return out.out


# --- symbolic display ---------------------------------------------------------------------------
def test_repr_shows_simplified_expressions():
    """SymEngine kept cos(-phi1 + phi1 + phi2) and -((-1/2)*g*l1*m1 - ...) as built."""
    s = double_pendulum()
    M = s.equations_of_motion().M
    text = repr(M)
    assert "phi1 + phi1" not in text and "cos(phi2)" in text
    assert text.startswith("SymMatrix([\n[") and text.count("\n") == 2
    K = s.linearize({"phi1": 0, "phi2": 0}).K
    assert repr(K) == ("SymMatrix([\n[g*l1*m1/2 + g*l1*m2 + g*l2*m2/2, g*l2*m2/2],\n"
                       "[g*l2*m2/2, g*l2*m2/2]])")


def spring_cart() -> jd.System:
    """A cart on a rail tied to the wall point (-1, 0, 0) by a spring: L = sqrt((x + 1)²)."""
    x, c = jd.symbols("x c")
    cart = jd.Body("cart", "world", jd.Prismatic("rail", x, "x"), mass=1.0,
                   inertia=jd.point_mass())
    return jd.System([x], [cart], [jd.SpringDamper("spring", "world", (-1, 0, 0), "cart",
                                                   (0, 0, 0), stiffness=c, rest_length=0.5)],
                     parameters={"c": 10.0}, name="spring cart")


def test_square_root_of_a_square_reads_as_absolute_value(tmp_path, capsys):
    s = spring_cart()
    q = s.equations_of_motion().q
    assert "sqrt" in str(q[0])  # as derived
    assert "Abs(x + 1)" in repr(q) and "sqrt" not in repr(q)
    text = export.matrix_text(q, s)
    assert "│x + 1│" in text and "√" not in text
    # the same through the command, from a model file
    path = tmp_path / "spring_cart.toml"
    path.write_text("""
[coordinates]
x = "m"
[parameters]
c = 10.0
[bodies.cart]
parent = "world"
mass = 1.0
inertia = "point"
joint = { type = "prismatic", name = "rail", coordinate = "x", axis = "x" }
[forces.spring]
type = "spring_damper"
body_a = "world"
point_a = [-1, 0, 0]
body_b = "cart"
point_b = [0, 0, 0]
stiffness = "c"
rest_length = 0.5
""")
    out = run(capsys, "eom", path)
    assert "│x + 1│" in out and "√" not in out and "sqrt" not in out
    latex = run(capsys, "eom", path, "--format", "latex")
    assert r"\left|{x + 1}\right|" in latex and "sqrt" not in latex


def test_jupyter_latex_has_dots_for_rates():
    k = double_pendulum().equations_of_motion().k
    tex = k._repr_latex_()
    assert tex.startswith("$\\displaystyle") and tex.endswith("$")
    assert r"\dot{\phi}_{1}" in tex and "1 d" not in tex


def test_display_stays_within_its_budget():
    """A matrix too large to read is summarized at once; an expired budget still gives the
    converted (cancelled, real) entries, only without trigonometric simplification."""
    from jourdain import symbolic

    M = spatial_chain(4).equations_of_motion().M

    def never(*args, **kwargs):
        raise AssertionError("a matrix too large to read was converted for display")

    with pytest.MonkeyPatch.context() as mp:  # summarized without converting any entry
        mp.setattr(symbolic, "simplified_sympy", never)
        text = repr(M)
        assert "operations after CSE" in text and "7×7" in text
        assert "operations after CSE" in M._repr_latex_()
    q = spring_cart().equations_of_motion().q
    quick = export.to_sympy_matrix(q, deadline=time.perf_counter() - 1.0)
    assert "Abs(x + 1)" in str(quick[0])


# --- LaTeX fragment ---------------------------------------------------------------------------
def _balanced(tex: str) -> None:
    """Braces, display math and environments open and close in order (a parser check that
    runs where no LaTeX engine is installed)."""
    stack: list[str] = []
    for m in re.finditer(r"\\begin\{(\w+\*?)\}|\\end\{(\w+\*?)\}|\\\[|\\\]|(?<!\\)[{}]", tex):
        tok = m.group(0)
        if tok.startswith("\\begin"):
            stack.append(m.group(1))
        elif tok.startswith("\\end"):
            assert stack and stack.pop() == m.group(2), f"unbalanced \\end{{{m.group(2)}}}"
        elif tok == "\\[":
            assert not stack or stack[-1] != "\\[", "nested display math"
            stack.append("\\[")
        elif tok == "\\]":
            assert stack and stack.pop() == "\\[", "\\] without \\["
        elif tok == "{":
            stack.append("{")
        else:
            assert stack and stack.pop() == "{", "unbalanced }"
    assert not stack, f"not closed: {stack}"


@pytest.mark.parametrize("name", ["double_pendulum", "robot_arm", "heavy_top"])
def test_eom_latex_is_a_compilable_fragment(name, tmp_path, capsys):
    tex = run(capsys, "eom", EXAMPLES / f"{name}.toml", "--format", "latex")
    _balanced(tex)
    body = [line for line in tex.splitlines() if line and not line.startswith("%")]
    assert body[0].startswith("\\setcounter{MaxMatrixCols}")
    assert all(line.startswith("\\[ ") and line.endswith(" \\]") for line in body[1:])
    widest = max(len(row.split("&")) for row in re.findall(r"\\begin\{pmatrix\}(.*?)\\\\", tex))
    assert int(re.search(r"MaxMatrixCols\}\{(\d+)\}", tex).group(1)) >= widest
    pdflatex = shutil.which("pdflatex")
    if pdflatex is None:
        pytest.skip("pdflatex is not installed (apt-get install texlive-latex-base); the "
                    "parser check above ran")
    (tmp_path / "eom.tex").write_text(tex)
    (tmp_path / "doc.tex").write_text("\\documentclass{article}\n\\usepackage{amsmath}\n"
                                      "\\begin{document}\n\\input{eom}\n\\end{document}\n")
    res = subprocess.run([pdflatex, "-interaction=nonstopmode", "-halt-on-error", "doc.tex"],
                         cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stdout[-3000:]
    assert (tmp_path / "doc.pdf").exists()


# --- numbers in the text output -----------------------------------------------------------------
ROUND_OFF = re.compile(r"e-1\d|e-[2-9]\d|-0\.(?!\d*[1-9])|\bnan\b")


def numbers_of(out: str) -> str:
    """The output without its explanatory notes (which name the round-off threshold)."""
    return "\n".join(ln for ln in out.splitlines() if not ln.startswith("  ("))


def test_reactions_text_units_state_and_no_round_off(capsys):
    out = run(capsys, "reactions", EXAMPLES / "double_pendulum.toml", "--at", "phi1=0.3")
    assert "t=0, phi1=0.3, phi2=0, phi1_d=0, phi2_d=0" in out.splitlines()[0]
    lines = {ln.split()[0]: ln.split()[1:] for ln in out.splitlines() if ln.startswith("  hinge")}
    # the planar motion has no torques about x, y: round-off of 1e-14 before, 0 now
    assert lines["hinge1.T_x"] == ["0", "N·m"] and lines["hinge2.T_y"] == ["0", "N·m"]
    assert lines["hinge1.F_y"][1] == "N" and float(lines["hinge1.F_y"][0]) > 1.0
    assert not ROUND_OFF.search(numbers_of(out))


def test_reaction_units_follow_the_model_units():
    assert reaction_units(double_pendulum()) == ("N", "N·m")
    x = jd.symbols("x")
    body = jd.Body("b", "world", jd.Prismatic("p", x, "x"), mass=2.0, inertia=jd.point_mass())
    s = jd.System([x], [body], [], units={"x": "mm"})
    assert reaction_units(s) == ("kg·mm/s²", "kg·mm²/s²")


def test_eval_text_has_no_round_off(capsys):
    out = run(capsys, "eval", EXAMPLES / "double_pendulum.toml", "--at", "phi1=0.3, phi1_d=1")
    assert out.splitlines()[0].endswith("t=0, phi1=0.3, phi2=0, phi1_d=1, phi2_d=0")
    assert not ROUND_OFF.search(numbers_of(out))


def test_chop_is_relative_to_the_scale():
    np.testing.assert_array_equal(export.chop([15.0, -4.03364e-14, 1e-8]), [15.0, 0.0, 1e-8])
    assert str(export.chop([-0.0, 1.0])[0]) == "0.0"  # no negative zero
    np.testing.assert_array_equal(export.chop([1e-13, 2e-13]), [1e-13, 2e-13])  # own scale
    np.testing.assert_array_equal(export.chop([1e-13], scale=[100.0]), [0.0])
    assert np.isnan(export.chop([np.nan, 1.0])[0])


def test_eigenvalue_table_has_no_nan_and_no_round_off(capsys):
    out = run(capsys, "linearize", EXAMPLES / "double_pendulum.toml")
    table = out.split("eigenvalues of the state-space system:")[1]
    assert not ROUND_OFF.search(table)
    assert "+2.97723j" in table and "0.0000" in table  # undamped: zeta 0, not -0.0000
    # a free rotor on a damped bearing: λ = 0 (the angle) and λ = -d/J
    phi, d = jd.symbols("phi d")
    disc = jd.Body("disc", "world", jd.Revolute("bearing", phi, "z"), mass=1.0,
                   inertia=(0.05, 0.05, 0.05))
    s = jd.System([phi], [disc], [jd.RotationalSpringDamper("damper", phi, damping=d)],
                  parameters={"d": 0.4})
    text = str(jd.modes(s.linearize({"phi": 0})))
    assert "nan" not in text and "—" in text and "no damping ratio" in text
    assert "-8" in text and "1.0000" in text  # λ = -d/J = -8, overdamped
