"""``jourdain run`` of a closed system writes the one report of trees (io.report): the tree
report's sections and files with the closed system's numbers, plus "Closed loops"; and
``jd.view`` draws a closed mechanism closed (issue 32)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

import jourdain as jd
from jourdain.cli import main
from jourdain.io.viewer import closing_ends
from tests.tolerance import EPS

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _sections(page: str) -> list[str]:
    """The report's section headings without their numbers."""
    return [re.sub(r"^\d+\.\s*", "", h) for h in re.findall(r"<h2>(.*?)</h2>", page)]


def _headings(page: str) -> set[str]:
    return set(re.findall(r"<h3>([^<]*)</h3>", page))


@pytest.fixture(scope="module")
def reports(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    out = {}
    for name in ("four_bar", "double_pendulum"):
        folder = tmp_path_factory.mktemp(name) / "report"
        assert main(["run", str(EXAMPLES / f"{name}.toml"), "--out", str(folder)]) == 0
        out[name] = folder
    return out


def test_same_sections_and_files_as_a_tree_report(reports: dict[str, Path]) -> None:
    closed, tree = reports["four_bar"], reports["double_pendulum"]
    page = (closed / "report.html").read_text(encoding="utf-8")
    tree_page = (tree / "report.html").read_text(encoding="utf-8")
    # the tree's sections in the same order, "Closed loops" before the files
    assert _sections(page) == [*_sections(tree_page)[:-1], "Closed loops",
                               _sections(tree_page)[-1]]
    assert re.findall(r"<h2>(\d+)\.", page) == [str(i) for i in range(1, 8)]
    # the tree report's subsections of the motion and the initial state
    for h in ("Snapshots of the motion", "Animation", "3-D view", "Coordinates",
              "Bodies and joints", "Reaction forces g (N̂·g = k̂ − q̂)"):
        assert h in _headings(page) and h in _headings(tree_page)
    for h in ("Closing joints", "Partitions along the motion", "Closure residuals"):
        assert h in _headings(page)
    # no traceback, and section 2 says in words why there are no symbolic equations
    assert "Traceback" not in page
    assert "exists in numbers only" in page
    files = {p.name for p in closed.iterdir()}
    tree_files = {p.name for p in tree.iterdir()}
    common = {"report.html", "run.json", "model.toml", "values.json", "simulation.csv"}
    assert common <= files and common <= tree_files
    assert {f"wrench-{j}.csv" for j in ("ground1", "knee", "ground2", "closure")} <= files
    assert {"loops.json", "loops.csv", "linearization-equilibrium.json"} <= files
    assert not {"equations.tex", "equations.json"} & files  # no open tree's equations
    run = json.loads((closed / "run.json").read_text())
    assert run["status"] == "complete"
    assert set(run["files"]) == files


def test_final_state_is_system_simulate(reports: dict[str, Path]) -> None:
    model = jd.load_model(EXAMPLES / "four_bar.toml")
    sim = model.simulation
    res = model.system.simulate((0.0, sim.t_end), sim.y0, sim.yd0, method=sim.method,
                                rtol=sim.rtol, atol=sim.atol, samples=sim.samples)
    rows = [r for r in (reports["four_bar"] / "simulation.csv").read_text().splitlines()
            if not r.startswith("#")]
    head = rows[0].split(",")
    last = np.array(rows[-1].split(","), float)
    y = last[[head.index(c) for c in model.system.coordinate_names]]
    yd = last[[head.index(f"{c}_d") for c in model.system.coordinate_names]]
    scale = 1.0 + float(np.max(np.abs(res.y)))
    assert last[0] == pytest.approx(sim.t_end, abs=10 * EPS * sim.t_end)
    assert np.max(np.abs(y - res.y[-1])) <= 100 * EPS * scale
    assert np.max(np.abs(yd - res.yd[-1])) <= 100 * EPS * (1 + float(np.max(np.abs(res.yd))))


def test_closure_residuals_small(reports: dict[str, Path]) -> None:
    """max|Φ| and max|Φ̇| along the motion, within rounding of the loop's lengths."""
    model = jd.load_model(EXAMPLES / "four_bar.toml")
    pv = model.system.parameter_values
    lengths = pv["a"] + pv["b"] + pv["c"] + pv["d"]
    doc = json.loads((reports["four_bar"] / "loops.json").read_text())
    rows = [r for r in (reports["four_bar"] / "simulation.csv").read_text().splitlines()
            if not r.startswith("#")]
    head = rows[0].split(",")
    data = np.loadtxt(rows[1:], delimiter=",")
    y = data[:, [head.index(c) for c in model.system.coordinate_names]]
    yd = data[:, [head.index(f"{c}_d") for c in model.system.coordinate_names]]
    # Φ: a sum of n rod vectors of the loop with angles |y|; Φ̇: their rates
    n = model.system.f + 1
    assert doc["max_Phi"] <= 1e3 * n * EPS * lengths * (1 + float(np.max(np.abs(y))))
    assert doc["max_Phi_dot"] <= 1e3 * n * EPS * lengths * (1 + float(np.max(np.abs(yd))))
    # the same numbers in loops.csv, by row
    lp = np.loadtxt(reports["four_bar"] / "loops.csv", delimiter=",", skiprows=1)
    lhead = (reports["four_bar"] / "loops.csv").read_text().splitlines()[0].split(",")
    phi = lp[:, [i for i, h in enumerate(lhead) if h.startswith("Phi[")]]
    assert float(np.max(np.abs(phi))) == pytest.approx(doc["max_Phi"], rel=1e-12, abs=0)
    assert doc["degrees_of_freedom_rank"] == 1 and doc["independent"] == ["theta1"]
    assert doc["degrees_of_freedom_grubler_planar"] == 1


def test_values_have_the_closed_M(reports: dict[str, Path]) -> None:
    values = json.loads((reports["four_bar"] / "values.json").read_text())
    M = np.array(values["values"]["M"], float)
    assert M.shape == (1, 1)  # the closed system's, not the open tree's 3×3
    assert values["independent"] == ["theta1"]
    model = jd.load_model(EXAMPLES / "four_bar.toml")
    sim = model.simulation
    ev = model.system.evaluate(sim.y0, sim.yd0)
    assert np.max(np.abs(M - ev["M"])) <= 100 * EPS * float(np.max(np.abs(ev["M"])))
    assert "closure.Fx" in values["g_names"]


def _ends_coincide(view: jd.View) -> None:
    ends = closing_ends(view.scene)
    assert ends, "the scene has no closing joints"
    for a, b in ends.values():
        # float32 poses: a few float32 epsilons of the scene's size
        tol = 64 * float(np.finfo(np.float32).eps) * view.scene["extent"]
        for k in (0, -1):
            assert np.max(np.abs(a[k] - b[k])) <= tol


def test_view_draws_the_four_bar_closed() -> None:
    model = jd.load_model(EXAMPLES / "four_bar.toml")
    sim = model.simulation
    res = model.system.simulate((0.0, 2.0), sim.y0, sim.yd0)
    view = jd.view(res)
    assert [c["name"] for c in view.scene["closing"]] == ["closure"]
    _ends_coincide(view)
    # the coupler's far end and the rocker's far end: the closing joint's two points
    (c,) = view.scene["closing"]
    assert (c["body_a"], c["body_b"]) == ("coupler", "rocker")
    # one configuration of the system, assembled onto the loop
    still = jd.view(model.system, y=dict(zip(model.system.coordinate_names, sim.y0,
                                             strict=True)))
    assert still.scene["n_frames"] == 1
    _ends_coincide(still)
