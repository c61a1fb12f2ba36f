"""The HTML report of ``jourdain run``: self-contained, and its equations render in a browser.

The browser test uses headless Chromium (Debian's ``chromium`` package; ``make test`` installs it
when missing and it runs as root). Without it the test is skipped with the reason.
"""

import json
import os
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from jourdain.io import load_model
from jourdain.io.report import write_report

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def report(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("report")
    info = write_report(load_model(ROOT / "examples" / "double_pendulum.toml"), out)
    assert info.html == out / "report.html"
    return out


def test_report_is_self_contained(report):
    text = (report / "report.html").read_text()
    # no scripts, no external resources: opens offline, from a mail attachment, in ten years
    assert "<script" not in text.lower()
    urls = set(re.findall(r"(?:src|href)=['\"]([^'\"]+)", text))
    assert all(not u.startswith(("http:", "https:", "//")) for u in urls), urls
    assert text.count("<math") >= 10  # headline equations, M̄, J̄, q̄^c, q̄^e, M, k, q, symbols
    assert text.count("<svg") >= 5  # plots, eigenvalues, snapshot strip, animation
    assert "<animate " in text
    for name in ("hinge1.F_x", "marginally stable", "unstable", "conservative"):
        assert name in text


def test_report_data_files_agree_with_the_model(report):
    import json

    values = json.loads((report / "values.json").read_text())
    model = load_model(ROOT / "examples" / "double_pendulum.toml")
    ref = model.system.evaluate(values["y"], values["yd"])
    np.testing.assert_allclose(values["values"]["M"], ref["M"], rtol=1e-12)
    lin = json.loads((report / "linearization-hanging.json").read_text())
    assert lin["stability"]["verdict"] == "marginally stable"
    header = [ln for ln in (report / "simulation.csv").read_text().splitlines()
              if not ln.startswith("#")][0]
    assert header.split(",")[:3] == ["t", "phi1", "phi2"]


def _chromium() -> str | None:
    for name in ("chromium", "chromium-browser", "google-chrome"):
        exe = shutil.which(name)
        if exe:
            return exe
    return None


def _screenshot(exe: str, page: Path, png: Path, size: str, tmp: Path) -> None:
    cmd = [exe, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
           "--no-first-run", "--disable-background-networking", "--disable-component-update",
           "--disable-sync", "--hide-scrollbars", f"--user-data-dir={tmp / 'profile'}",
           f"--window-size={size}", f"--screenshot={png}", page.as_uri()]
    subprocess.run(cmd, capture_output=True, timeout=120, env={**os.environ, "HOME": str(tmp)})


def _ink_box(png: Path) -> tuple[int, int]:
    """Width and height of the non-white part of a screenshot."""
    from PIL import Image

    a = np.asarray(Image.open(png).convert("L"))
    rows = np.flatnonzero((a < 200).any(axis=1))
    cols = np.flatnonzero((a < 200).any(axis=0))
    if rows.size == 0:
        return 0, 0
    return int(cols[-1] - cols[0] + 1), int(rows[-1] - rows[0] + 1)


def test_equations_render_in_headless_chromium(report, tmp_path):
    exe = _chromium()
    if exe is None:
        pytest.skip("headless Chromium not found (Debian: apt-get install chromium; `make test` "
                    "installs it when run as root); the browser rendering check is skipped")
    text = (report / "report.html").read_text()
    # the full report, for a person to look at
    full = tmp_path / "report.png"
    _screenshot(exe, report / "report.html", full, "1200,3000", tmp_path)
    assert full.is_file() and full.stat().st_size > 20_000, "Chromium wrote no screenshot"
    # one equation alone: rendered MathML lays the 2×2 mass matrix with its fractions out in
    # two dimensions; without MathML support the same markup is a single line of text
    style = re.search(r"<style>(.*?)</style>", text, re.S).group(1)
    eq = [m for m in re.findall(r'<div class="eq">(.*?)</div>', text, re.S)
          if "<mrow><mi>M</mi><mo>=</mo>" in m and "<mtable" in m][0]
    page = tmp_path / "eq.html"
    page.write_text(f"<!DOCTYPE html><html><head><meta charset='utf-8'><style>{style}"
                    f"body{{margin:10px;max-width:none}}</style></head><body>{eq}</body></html>")
    plain = tmp_path / "plain.html"
    plain.write_text(page.read_text().replace("<math", "<span").replace("</math>", "</span>"))
    png, png_plain = tmp_path / "eq.png", tmp_path / "plain.png"
    _screenshot(exe, page, png, "1400,600", tmp_path)
    _screenshot(exe, plain, png_plain, "1400,600", tmp_path)
    w, h = _ink_box(png)
    w0, h0 = _ink_box(png_plain)
    assert h > 0 and h0 > 0, "nothing rendered"
    # two matrix rows of stacked fractions: several text lines tall, and narrower than the
    # same symbols strung out on a line
    print("ink boxes (MathML, plain):", (w, h), (w0, h0))
    assert h >= 2.5 * h0, (w, h, w0, h0)
    assert w < w0, (w, h, w0, h0)


def test_heavy_upright_equilibrium_is_not_reported_with_h_nonzero(tmp_path):
    """Upright at φ = π the residual h is round-off of sin(π)·m·g·l: with masses of 1e8 kg it
    is ≈ 2e-7 in absolute terms, but a round-off relative to the forces at work. The report
    judges h with the nominal check (against those forces) in every place it mentions h, not
    against an absolute 1e-9."""
    text = (ROOT / "examples" / "double_pendulum.toml").read_text()
    path = tmp_path / "model.toml"  # π as a float: sin(π) is round-off, not exactly 0
    path.write_text(text.replace('phi1 = "pi"', "phi1 = 3.141592653589793"))
    write_report(load_model(path), tmp_path / "out", parameters={"m1": 1e8, "m2": 1e8})
    html = (tmp_path / "out" / "report.html").read_text()
    assert "h ≠ 0" not in html
    assert "does not solve the equations of motion" not in html


def test_report_equations_tex_is_the_compilable_fragment(report):
    """equations.tex holds displayed equations with the column count of the widest matrix
    (M̄ of two bodies has 12 columns), like ``jourdain eom --format latex``."""
    from tests.test_display_output import _balanced

    tex = (report / "equations.tex").read_text()
    _balanced(tex)
    body = [line for line in tex.splitlines() if line and not line.startswith("%")]
    assert body[0] == "\\setcounter{MaxMatrixCols}{12}"
    assert all(line.startswith("\\[ ") and line.endswith(" \\]") for line in body[1:])


def test_report_embeds_the_3d_view(report):
    """The 3-D view (jourdain.io.viewer, tested in tests/test_viewer.py) is its own page in a
    sandboxed iframe: the report page itself still runs no script; the view holds the bodies
    of the model."""
    import html

    from tests.test_viewer import _scene_of

    text = (report / "report.html").read_text()
    m = re.search(r"<h3>3-D view</h3><iframe class='jourdain-view' srcdoc=\"([^\"]*)\" "
                  r"sandbox='allow-scripts'", text)
    assert m, "no 3-D view in the report"
    sc = _scene_of(html.unescape(m.group(1)))
    assert [b["name"] for b in sc["bodies"]] == ["rod1", "rod2"]
    assert sc["n_frames"] > 100


def test_report_compiles_the_evaluation_library_beside_the_summarys(tmp_path, monkeypatch):
    """write_report starts System.evaluate's library (the recursion's M̄, J̄, …, Q̄) in its own
    thread before the summary compiles the integrator's M, k, q: both libraries are built, the
    evaluation's in that thread and the summary's in the calling one (or in the model's build
    thread, where the summary's first run is interpreted while it compiles: whichever of the
    two gets there first), and the numbers are those of the library built in this thread
    alone. Whether the two compilers overlap in time is the
    scheduler's business, not a test's (benchmarks/report.py times whole runs)."""
    import threading

    from jourdain import numeric
    from jourdain.numeric import compiled, toolchain

    monkeypatch.setenv("JOURDAIN_CACHE", str(tmp_path / "cache"))  # nothing compiled yet
    numeric.clear_cache()
    toolchain._loaded.clear()
    built_in: dict[str, str] = {}
    build = compiled.build

    def recorded(key, *args, **kwargs):
        lib = build(key, *args, **kwargs)
        built_in.setdefault(key, threading.current_thread().name)
        return lib

    monkeypatch.setattr(compiled, "build", recorded)
    model = load_model(ROOT / "examples" / "robot_arm.toml")
    write_report(model, tmp_path / "out")
    eom_key = compiled._eom_function(model.system).key
    mkq_key = compiled.mkq_function(model.system).key
    assert built_in[eom_key] == "jourdain-eom-build"
    assert built_in[mkq_key] in (threading.main_thread().name, "jourdain-model-build")
    doc = json.loads((tmp_path / "out" / "values.json").read_text())
    numeric.clear_cache()
    toolchain._loaded.clear()
    monkeypatch.setenv("JOURDAIN_CACHE", str(tmp_path / "cache2"))  # built again, here
    ref = load_model(ROOT / "examples" / "robot_arm.toml").system.evaluate(
        np.asarray(doc["y"]), np.asarray(doc["yd"]), t=doc["t"], parameters=doc["parameters"],
        inputs=doc["inputs"])
    for name in ("M_bar", "J_bar", "M", "k", "q"):
        assert np.array_equal(np.asarray(doc["values"][name], dtype=float),
                              np.asarray(ref[name], dtype=float)), name
