"""The report's Campbell diagram (jourdain.io.report.campbell) and its parts for elastic bodies
(jourdain.io.report.elastic, the 3-D view's lines), against closed forms."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import jourdain as jd
from jourdain.io.report.campbell import speed_parameter
from jourdain.io.report.document import write_report

EXAMPLES = Path(__file__).parent.parent / "examples"


def test_critical_speeds_of_the_gyroscopic_rotor(tmp_path: Path) -> None:
    """A disc (axial moment C = m r²/2, diametral A = m r²/4 + m h² about the gimbal) on
    tilt springs c, undamped: A·ω² ∓ C·Ω·ω − c = 0, so ω = Ω where Ω² = c/(A ∓ C): the
    backward and forward critical speeds, found to 1e-10 by Brent's method in the report."""
    model = jd.load_model(EXAMPLES / "gyroscopic_rotor.toml")
    assert speed_parameter(model.system) == "Omega"
    info = write_report(model, tmp_path, parameters={"d": 0.0}, t_end=0.1)
    line = next(s for s in info.summary_lines if "critical Omega" in s)
    found = [float(x) for x in re.findall(r"[-+]?\d+\.\d+", line.split(";")[0])]
    m, r, h, c = 2.0, 0.15, 0.1, 40.0
    A, C = m * r * r / 4 + m * h * h, m * r * r / 2
    expected = sorted([np.sqrt(c / (A + C)), np.sqrt(c / (A - C))])
    assert found == pytest.approx(expected, rel=1e-7)  # printed with 8 digits
    csv = np.loadtxt(tmp_path / "campbell-upright.csv", delimiter=",", skiprows=1)
    Om, w1, w2 = csv[:, 0], csv[:, 1], csv[:, 2]
    backward = (-C * Om + np.sqrt((C * Om) ** 2 + 4 * A * c)) / (2 * A)
    forward = (C * Om + np.sqrt((C * Om) ** 2 + 4 * A * c)) / (2 * A)
    assert np.allclose(w1, backward, rtol=1e-9) and np.allclose(w2, forward, rtol=1e-9)


def test_internal_damping_threshold_in_the_report(tmp_path: Path) -> None:
    """The Jeffcott rotor with internal damping loses stability at Ω = √(k/m)·(1 + d_a/d_i)
    = 15 rad/s: the report's stable speed range ends there."""
    model = jd.load_model(EXAMPLES / "rotor_internal_damping.toml")
    info = write_report(model, tmp_path, t_end=0.1)
    line = next(s for s in info.summary_lines if "stable Omega" in s)
    top = float(line.rsplit("–", 1)[1])
    assert top == pytest.approx(15.0, rel=1e-5)


def test_elastic_parts_of_the_report_and_the_view(tmp_path: Path) -> None:
    """The flexible pendulum's report lists its basis's frequencies and draws the mode
    shapes, links 3-D views of its lowest modes; the 3-D view joins the beam's nine mass
    nodes, in order, by its line."""
    model = jd.load_model(EXAMPLES / "flexible_pendulum.toml")
    write_report(model, tmp_path, t_end=0.2)
    page = (tmp_path / "report.html").read_text(encoding="utf-8")
    assert "Elastic bodies" in page and "mode shapes of arm" in page
    # the lowest modes about the nominal "hanging" animated in 3-D views of their own
    for k in (1, 2, 3):
        assert f"href='mode-hanging-{k}.html'" in page
        view_page = (tmp_path / f"mode-hanging-{k}.html").read_text(encoding="utf-8")
        assert "jourdain-view/1" in view_page
    eb = model.system.groups[0]
    assert f"{eb.modal.omega[0]:.6g}" in page or f"{eb.modal.omega[0]:.5g}" in page
    r = model.system.simulate(t_span=(0, 0.1), y0=[0.5, 0, 0, 0], yd0=[0, 0, 0, 0])
    sc = jd.view(r).scene
    assert sc["elastic"] == [{"name": "arm", "nodes": [f"arm_n{k}" for k in range(9)]}]


def test_the_view_draws_a_consistent_body_through_its_gauss_points() -> None:
    """With mass = "consistent" the beam's mass sits at its elements' Gauss points: the line
    of the 3-D view joins those 32 bodies (8 elements), in order along the beam."""
    text = (EXAMPLES / "flexible_pendulum.toml").read_text(encoding="utf-8")
    assert "elastic = { modes = 3," in text
    model = jd.io.modelfile.loads_model(
        text.replace("elastic = { modes = 3,", 'elastic = { modes = 3, mass = "consistent",'),
        "flexible_pendulum.toml")
    r = model.system.simulate(t_span=(0, 0.02), y0=[0.5, 0, 0, 0], yd0=[0, 0, 0, 0])
    sc = jd.view(r).scene
    assert sc["elastic"] == [{"name": "arm", "nodes": [f"arm_g{k}" for k in range(32)]}]
    beads = [b for b in sc["bodies"] if b["name"].startswith("arm_g")]
    assert len(beads) == 32 and all(b["shape"]["kind"] == "sphere" for b in beads)
