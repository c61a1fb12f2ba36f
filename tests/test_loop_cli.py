"""``jourdain linearize`` and ``jourdain run`` on loop models (jourdain.io.closed_linear, report):
the linearization in the independent coordinates with the parameters of --set, the fallback
where the model has no isolated equilibrium, the closing joint's wrench in the report."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from jourdain.cli import main
from jourdain.io.modelfile import load_model
from jourdain.loops.linearization import equilibrium, linearize_loop
from tests.tolerance import EPS

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def test_linearize_a_loop_model_with_set(capsys: pytest.CaptureFixture) -> None:
    """The document's eigenvalues (exact linearization) equal linearize_loop's about the equilibrium
    (checked against the closed-form four-bar in tests/test_loops.py) at the --set values,
    and a heavier coupler lowers the frequency."""
    path = str(EXAMPLES / "four_bar.toml")
    mf = load_model(path)
    docs = {}
    for m2 in (2.0, 4.0):
        assert main(["linearize", path, "--json", "--set", f"m2={m2}"]) == 0
        docs[m2] = json.loads(capsys.readouterr().out)
        z = equilibrium(mf.system, mf.simulation.y0, parameters={"m2": m2})
        lin = linearize_loop(mf.system, z, parameters={"m2": m2})
        got = np.array([complex(*v) for v in docs[m2]["eigenvalues"]])
        w = float(np.max(np.abs(lin.eigenvalues)))
        # the exact linearization (CLI) against central differences (error ~ ε^(2/3))
        assert np.max(np.abs(got - lin.eigenvalues)) <= 1e-6 * w
        assert docs[m2]["independent"] == ["theta1"]
        assert docs[m2]["frequencies_hz"] == pytest.approx([w / (2 * math.pi)], rel=1e-6)
    assert docs[4.0]["frequencies_hz"][0] < docs[2.0]["frequencies_hz"][0]
    assert main(["linearize", path]) == 0
    text = capsys.readouterr().out
    assert "M_tilde" in text and "eigenvalues" in text and "Hz" in text


def test_linearize_without_isolated_equilibrium_falls_back(capsys: pytest.CaptureFixture
                                                           ) -> None:
    """The spatial RSSR's coupler spins freely about the line of its ball joints: no isolated
    equilibrium (Q singular), so the linearization is about the initial configuration, and
    the free spin gives a double zero eigenvalue."""
    assert main(["linearize", str(EXAMPLES / "spatial_rssr.toml"), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["about"].startswith("initial configuration at rest")
    assert "no isolated equilibrium" in doc["about"]
    ev = np.array([complex(*v) for v in doc["eigenvalues"]])
    scale = float(np.max(np.abs(ev)))
    assert int(np.sum(np.abs(ev) <= 1e-6 * scale)) == 2


def test_run_report_has_the_closing_joint_wrench(tmp_path: Path) -> None:
    """The one report (io.report) of a closed system: the closing joint's wrench file and
    its plot in section 6, the residuals and multipliers by row in loops.csv."""
    out = tmp_path / "rep"
    assert main(["run", str(EXAMPLES / "four_bar.toml"), "--out", str(out), "--t-end",
                 "0.5"]) == 0
    header = (out / "wrench-closure.csv").read_text().splitlines()[0].split(",")
    assert header[1:7] == ["closure.F_x", "closure.F_y", "closure.F_z", "closure.T_x",
                           "closure.T_y", "closure.T_z"]
    lhead = (out / "loops.csv").read_text().splitlines()[0].split(",")
    assert "lambda[closure.Fx]" in lhead and "Phi[closure.Fy]" in lhead
    page = (out / "report.html").read_text()
    assert "<h2>6. Closed loops</h2>" in page
    assert "closing joints&#x27; wrenches along the motion" in page or \
        "closing joints' wrenches along the motion" in page


def test_run_report_files_like_the_tree_report(tmp_path: Path) -> None:
    """run.json lists the files; wrench-<joint>.csv has the tree report's columns, its
    inertial force equal to the multipliers of the pin rows (force of B on A, inertial)."""
    out = tmp_path / "rep"
    assert main(["run", str(EXAMPLES / "four_bar.toml"), "--out", str(out), "--t-end",
                 "0.5"]) == 0
    run = json.loads((out / "run.json").read_text())
    assert run["format"] == "jourdain-run/1" and run["status"] == "complete"
    for f in run["files"]:
        assert (out / f).stat().st_size > 0
    assert "linearization-equilibrium.json" in run["files"]
    lin = json.loads((out / "linearization-equilibrium.json").read_text())
    assert lin["about"].startswith("equilibrium")
    w = np.loadtxt(out / "wrench-closure.csv", delimiter=",", skiprows=1)
    head = (out / "wrench-closure.csv").read_text().splitlines()[0].split(",")
    assert head[:4] == ["t", "closure.F_x", "closure.F_y", "closure.F_z"]
    motion = np.loadtxt(out / "loops.csv", delimiter=",", skiprows=1)
    mhead = (out / "loops.csv").read_text().splitlines()[0].split(",")
    lam = motion[:, [mhead.index("lambda[closure.Fx]"), mhead.index("lambda[closure.Fy]")]]
    Fin = w[:, [head.index("closure.F_x_inertial"), head.index("closure.F_y_inertial")]]
    assert np.max(np.abs(Fin - lam)) <= 1e3 * EPS * (1 + np.max(np.abs(lam)))
