"""Every command and entry point on a general system (velocity constraints, issue 34): the
benchmark bicycle's model file gives its own numbers everywhere — the paper's eigenvalues from
``linearize``, the static loads from ``eval --json``, the self-stable range from ``run`` and
``study``, the rows from ``eom``, an FMU — or a clean error that names the contacts (an FMU of
speeds given by definition); never the open tree's."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

import jourdain as jd
from jourdain.cli import main
from tests.reference.test_benchmark_bicycle import CAPSIZE, TABLE2, WEAVE

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
BIKE = EXAMPLES / "benchmark_bicycle.toml"


def run(capsys: pytest.CaptureFixture, *args: object) -> tuple[int, str, str]:
    code = main([str(a) for a in args])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_check_names_contacts_rows_and_speeds(capsys: pytest.CaptureFixture) -> None:
    code, out, err = run(capsys, "check", BIKE)
    assert code == 0, err
    assert "contacts: rear, front (2 holonomic and 4 velocity rows" in out
    assert "phi_d, delta_d, thetaR_d" in out


def test_eval_json_gives_the_general_numbers(capsys: pytest.CaptureFixture) -> None:
    code, out, err = run(capsys, "eval", BIKE, "--at", "zc=-0.3, phi=0, thetaR_d=0", "--json")
    assert code == 0, err
    doc = json.loads(out)
    assert doc["format"] == "jourdain-eval/1" and doc["speeds"] == ["phi_d", "delta_d",
                                                                    "thetaR_d"]
    p = jd.load_model(BIKE).system.parameter_values
    weight = p["g"] * (p["mR"] + p["mB"] + p["mH"] + p["mF"])
    f = doc["contact_forces"]
    assert abs(f["rear.N"] + f["front.N"] - weight) <= 1e-12 * weight
    M = np.array(doc["values"]["M"])
    assert M.shape == (3, 3) and abs(M[0, 0] - 80.81722) <= 1e-12 * 80.81722
    assert set(doc["not_available"]) == {"Q_bar", "N_hat", "k_hat", "q_hat", "g"}


def test_reactions_lists_the_contact_forces(capsys: pytest.CaptureFixture) -> None:
    code, out, err = run(capsys, "reactions", BIKE, "--at", "zc=-0.3")
    assert code == 0, err
    for row in ("rear.N", "front.N", "rear.T1", "front.T2"):
        assert row in out


@pytest.mark.parametrize("v", [0.0, 5.0])
def test_linearize_gives_table_2(capsys: pytest.CaptureFixture, v: float) -> None:
    code, out, err = run(capsys, "linearize", BIKE, "--set", f"v={v}", "--json")
    assert code == 0, err
    doc = json.loads(out)
    assert doc["coordinates"] == ["phi", "delta"]
    lam = np.array(doc["eigenvalues"]["real"]) + 1j * np.array(doc["eigenvalues"]["imag"])
    for r in TABLE2[v]:
        assert np.min(np.abs(lam - r)) <= 1e-12 * max(1.0, abs(r))
    assert doc["verdict"] == ("unstable" if v == 0.0 else "asymptotically stable")


def test_simulate_writes_the_motion_with_residuals_at_rounding(
        capsys: pytest.CaptureFixture, tmp_path: Path) -> None:
    out_file = tmp_path / "bike.csv"
    code, out, err = run(capsys, "simulate", BIKE, "--t-end", "0.5", "--out", out_file)
    assert code == 0, err
    assert out_file.exists() and "residuals along the run" in out
    with out_file.open() as fh:
        rows = [r for r in csv.reader(fh) if r and not r[0].startswith("#")]
    assert len(rows) > 10


def test_eom_shows_the_rows_and_the_trees_equations(capsys: pytest.CaptureFixture) -> None:
    code, out, err = run(capsys, "eom", BIKE, "--format", "json")
    assert code == 0, err
    doc = json.loads(out)
    assert doc["contacts"] == ["rear", "front"]
    assert doc["constraint_labels"] == ["rear.N", "front.N", "rear.T1", "rear.T2", "front.T1",
                                        "front.T2"]
    assert "A" in doc["matrices"] if "matrices" in doc else "A" in doc


def test_fmu_exports_the_general_system(capsys: pytest.CaptureFixture,
                                        tmp_path: Path) -> None:
    code, out, err = run(capsys, "fmu", BIKE, "--out", tmp_path / "b.fmu")
    assert code == 0, err
    assert "14 states (independent x, y, psi, phi, thetaR, delta, thetaF" in out
    assert (tmp_path / "b.fmu").is_file()


def test_an_fmu_of_speeds_by_definition_is_refused_naming_the_contacts(
        tmp_path: Path) -> None:
    from jourdain.io.fmu import export_fmu
    from jourdain.models.rolling import chaplygin_sleigh

    with pytest.raises(jd.ClosedSystemError, match="contact"):
        export_fmu(chaplygin_sleigh(), tmp_path / "s.fmu")
    assert not (tmp_path / "s.fmu").exists()


def test_run_reports_the_self_stable_range(capsys: pytest.CaptureFixture,
                                           tmp_path: Path) -> None:
    code, out, err = run(capsys, "run", BIKE, "--out", tmp_path / "rep", "--t-end", "0.5")
    assert code == 0, err
    assert "stable v range about straight: 4.2924 – 6.0243" in out
    html = (tmp_path / "rep" / "report.html").read_text(encoding="utf-8")
    assert "<h2>6. Contacts</h2>" in html
    # the 3-D view draws the wheels: a cylinder of each disc's radius about its axle
    assert "cylinder&quot;,&quot;size&quot;:[0.3," in html
    assert "cylinder&quot;,&quot;size&quot;:[0.35," in html
    rows = np.loadtxt(tmp_path / "rep" / "stability-straight.csv", delimiter=",", skiprows=1)
    assert rows.shape[0] == 101
    bounds = [float(x) for x in html.split("(boundaries ")[1].split(" by")[0].split(", ")]
    assert abs(bounds[0] - WEAVE) <= 1e-10 * WEAVE
    assert abs(bounds[1] - CAPSIZE) <= 1e-10 * CAPSIZE


def test_study_maps_the_stable_band(capsys: pytest.CaptureFixture, tmp_path: Path) -> None:
    spec = tmp_path / "map.toml"
    spec.write_text(f'[study]\nmodel = "{BIKE}"\nname = "bike"\ndesign = "grid"\n'
                    "[vary.v]\nvalues = [3.0, 4.0, 4.5, 5.0, 6.0, 6.5]\n"
                    '[compute.linearize]\nabout = "straight"\n', encoding="utf-8")
    code, out, err = run(capsys, "study", "--spec", spec, "--out", tmp_path / "map.nc")
    assert code == 0, err
    import xarray as xr

    with xr.open_dataset(tmp_path / "map.nc") as d:
        verdict = d["verdict"].values.tolist()
    # 0 asymptotically stable, 2 unstable: stable between the weave and capsize speeds
    assert verdict == [2, 2, 0, 0, 0, 2]


def test_python_entry_points_never_use_the_open_tree() -> None:
    s = jd.load_model(BIKE).system
    assert s.is_closed and s.is_general and not s.tree.contacts
    with pytest.raises(jd.ClosedSystemError, match="rear, front"):
        jd.kinematics(s)
    with pytest.raises(jd.ClosedSystemError, match="rear, front"):
        s.equations_of_motion()
    res = jd.simulate(s, (0.0, 0.2), [0, 0, -0.3, 0, 0.05, 0, 0, 0, 0],
                      [0, 0, 0, 0, 0, 0, -5 / 0.3, 0, 0])
    assert res.constraints is not None and "rear.T1" in res.constraints.labels


def test_every_public_function_handles_or_refuses_a_general_system() -> None:
    """The walk of tests/test_entry_points_closed.py on the bicycle: the functions of the
    tree's numbers refuse it naming the contacts; the analyses of a linearization (sweep and
    stability_boundary linearizing anew per value) and the viewer give its results."""
    import symengine as se

    from tests.test_entry_points_closed import OUTCOME

    s = jd.load_model(BIKE).system
    n = s.coordinate_names
    y0 = np.zeros(9)
    y0[n.index("zc")] = -0.3
    yd0 = np.zeros(9)
    yd0[n.index("thetaR")] = -5 / 0.3
    lin = s.linearize({"zc": -se.Symbol("rR"), "thetaR_d": -se.Symbol("v") / se.Symbol("rR")})
    refused = {
        "kinematics": lambda: jd.kinematics(s),
        "evaluate_reactions": lambda: jd.evaluate_reactions(s, y0, yd0),
        "joint_reactions": lambda: jd.joint_reactions(s, "H", y0, yd0),
        "joint_wrenches": lambda: jd.joint_wrenches(s, np.zeros(15), y0),
        "linearize_numeric": lambda: jd.linearize_numeric(s, {"zc": -0.3}),
        "floquet": lambda: jd.floquet(lin, 1.0),
        "cyclic_coordinates": lambda: jd.cyclic_coordinates(s),
        "find_equilibrium": lambda: jd.find_equilibrium(s, y0),
        "find_equilibria": lambda: jd.find_equilibria(s, [y0]),
        "state_feedback": lambda: jd.state_feedback(s, np.zeros((0, 2)), {"zc": -0.3}),
        "to_casadi": lambda: jd.to_casadi(s),
        "mode_motion": lambda: jd.mode_motion(lin, 1),
    }
    handled = {"sweep", "stability_boundary"}
    assert set(refused) | handled == {k for k, v in OUTCOME.items() if v == "refused"}
    for name, call in refused.items():
        with pytest.raises(jd.ClosedSystemError, match="contact"):
            call()
        assert name
    sw = jd.sweep(lin, "v", [3.0, 5.0, 7.0])
    assert sw.verdicts == ("unstable", "asymptotically stable", "unstable")
    assert abs(jd.stability_boundary(lin, "v", 3.0, 5.0) - WEAVE) <= 1e-10 * WEAVE
    assert jd.state_space(lin).A.shape == (4, 4) and len(jd.modes(lin).eigenvalues) == 4
    assert jd.frequency_response(lin, np.array([1.0]), excitation="h").response.shape == (
        1, 2, 2)
    assert jd.to_control(lin) is not None
    assert jd.view(s.simulate((0.0, 0.1), y0, yd0)) is not None
