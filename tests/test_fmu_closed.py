"""FMU export of closed systems (issue 32), validated with FMPy.

The four-bar's FMU has the independent coordinate and its rate as its continuous states; its C
code solves the dependent coordinates (Newton on Φ = 0) and rates (velocity map) at every
evaluation. FMPy validates its modelDescription.xml and runs it, in model exchange with its
CVode (BDF) and in co-simulation with the FMU's own Dormand–Prince 5(4), against
System.simulate (coordinate partitioning, DOP853 in C) of the same model over the model file's
t_end (5 s).

Tolerance 1e-6 on all tree coordinates and rates, as in tests/test_fmu.py: the FMU runs at
relative tolerance 1e-10 and the reference at 1e-11, so each keeps its local error near 1e-10
of the state; the global errors over the 5 s grow to (measured) 1.4e-8 on the coordinates and
1.6e-7 on the rates in model exchange (CVode's BDF), 1.3e-9 and 1.4e-8 in co-simulation;
the dependent coordinates are solved to |Φ| ≲ 1e-13 on both sides, so they inherit the
independent one's error through the velocity map (|J_z| of order 1 here). 1e-6 leaves room for
other machines' rounding and stays far below the motion's size (the crank turns by radians), so
a wrong term (M, the convective term, the velocity map) fails it. The closure residual outputs
are checked at 1e-11 (Newton's stop ~1e-13 of the coordinates' scale).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy", reason="FMPy is in the test extra (jourdain[test])")

from fmpy import extract, read_model_description, simulate_fmu  # noqa: E402
from fmpy.fmi1 import FMICallException  # noqa: E402
from fmpy.fmi2 import FMU2Model  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

from jourdain.cli import main  # noqa: E402
from jourdain.errors import ModelError  # noqa: E402
from jourdain.io import load_model  # noqa: E402
from jourdain.io.fmu import export_fmu  # noqa: E402
from tests.test_fmu import FMU_RTOL, ROOT, TRAJ_TOL, needs_cc, state_roundtrip  # noqa: E402

PHI_TOL = 1e-11  # see the module docstring


@pytest.fixture(scope="module")
def four_bar(tmp_path_factory: pytest.TempPathFactory) -> tuple:
    mf = load_model(str(ROOT / "examples" / "four_bar.toml"))
    path = tmp_path_factory.mktemp("fmu") / "four_bar.fmu"
    return mf, export_fmu(mf, path)


def _against_simulate(mf, info, dt: float = 0.01) -> None:
    s, sim = mf.system, mf.simulation
    T = float(sim.t_end)
    t = np.linspace(0.0, T, int(round(T / dt)) + 1)
    ref = s.simulate((0.0, T), list(sim.y0), list(sim.yd0), rtol=FMU_RTOL / 10,
                     atol=FMU_RTOL / 1000, t_eval=t)
    assert ref.status == "finished"
    names = list(s.coordinate_names)
    rates = [f"{n}_d" for n in names]
    phis = [v for v in info.variables if v.startswith("Phi.")]
    assert len(phis) == len(ref.constraints.labels)
    for fmi_type, kw in (("ModelExchange", {"solver": "CVode"}), ("CoSimulation", {})):
        r = simulate_fmu(str(info.path), fmi_type=fmi_type, stop_time=T, output_interval=dt,
                         relative_tolerance=FMU_RTOL, output=names + rates + phis, **kw)
        np.testing.assert_allclose(r["time"], ref.t, rtol=0, atol=1e-12)
        err_y = np.abs(np.column_stack([r[n] for n in names]) - ref.y).max()
        err_yd = np.abs(np.column_stack([r[n] for n in rates]) - ref.yd).max()
        assert err_y < TRAJ_TOL and err_yd < TRAJ_TOL, (fmi_type, err_y, err_yd)
        assert max(np.abs(r[p]).max() for p in phis) < PHI_TOL
        assert np.ptp(r[names[0]]) > 0.5  # it moved


@needs_cc
def test_four_bar_validates(four_bar: tuple) -> None:
    mf, info = four_bar
    assert validate_fmu(str(info.path)) == []
    md = read_model_description(str(info.path))
    assert md.numberOfContinuousStates == 2 and info.states == 2
    assert info.independent == ("theta1",)
    assert [d.variable.derivative.name for d in md.derivatives] == ["theta1", "theta1_d"]
    outs = [o.variable.name for o in md.outputs]
    assert outs == ["theta1", "theta1_d", "theta2", "theta3", "theta2_d", "theta3_d",
                    "Phi.closure.Fx", "Phi.closure.Fy"]
    v = {x.name: x for x in md.modelVariables}
    assert v["theta2"].initial == "calculated" and v["theta2"].unit == "rad"
    assert v["theta3_d"].unit == "rad/s"
    # the start values are the assembled configuration's (theta1 held, as simulate does)
    assert float(v["theta1"].start) == 0.5 and float(v["theta1_d"].start) == 1.0


@needs_cc
def test_four_bar_against_simulate(four_bar: tuple) -> None:
    _against_simulate(*four_bar)


@needs_cc
def test_double_four_bar_against_simulate(tmp_path: Path) -> None:
    mf = load_model(str(ROOT / "examples" / "double_four_bar.toml"))
    info = export_fmu(mf, tmp_path / "dfb.fmu")
    assert validate_fmu(str(info.path)) == []
    _against_simulate(mf, info)


def _instance(info, name: str) -> tuple[FMU2Model, dict]:
    md = read_model_description(str(info.path))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Model(guid=md.guid, unzipDirectory=extract(str(info.path)),
                    modelIdentifier=info.model_identifier, instanceName=name)
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    return fmu, vr


@needs_cc
def test_no_closure_is_an_error(four_bar: tuple, capsys: pytest.CaptureFixture[str]) -> None:
    """Ground pivots farther apart than coupler + rocker reach: no configuration closes the
    loop; the FMU says so (fmi2Error, logged), never numbers."""
    _, info = four_bar
    fmu, vr = _instance(info, "open")
    try:
        capsys.readouterr()
        fmu.setReal([vr["d"]], [3.0])
        with pytest.raises(FMICallException):
            fmu.exitInitializationMode()
        assert "Newton found no configuration" in capsys.readouterr().out
    finally:
        fmu.freeInstance()


@needs_cc
def test_singular_phi_d_is_an_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The partition is fixed in the FMU: where Φ_d's condition number passes the limit the
    FMU returns fmi2Error with a message. A limit below the initial configuration's condition
    number makes that happen at once; the motion with the default limit stays clear of it."""
    mf = load_model(str(ROOT / "examples" / "four_bar.toml"))
    info = export_fmu(mf, tmp_path / "fb.fmu", cond_limit=1.0001)
    fmu, _ = _instance(info, "singular")
    try:
        capsys.readouterr()
        with pytest.raises(FMICallException):
            fmu.exitInitializationMode()
        out = capsys.readouterr().out
        assert "Phi_d is singular here" in out and "condition number" in out
    finally:
        fmu.freeInstance()


@needs_cc
def test_state_restore(four_bar: tuple) -> None:
    """fmi2Get/SetFMUstate and serialization keep the loop kernel's state (Newton's start): a
    re-run from a saved state repeats (to Newton's tolerance: the restored kernel starts
    without the first-order prediction)."""
    state_roundtrip(four_bar[1], ("theta2", "theta3_d"), atol=1e-11)


def test_reactions_refused_and_cli(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    model = str(ROOT / "examples" / "four_bar.toml")
    mf = load_model(model)
    with pytest.raises(ModelError, match="no reaction outputs"):
        export_fmu(mf, tmp_path / "x.fmu", reactions="all", binary=False)
    assert not (tmp_path / "x.fmu").exists()
    out = tmp_path / "fb.fmu"
    # a refusal exits non-zero
    assert main(["fmu", model, "--out", str(out), "--reaction", "all", "--sources-only"]) == 1
    assert "no reaction outputs" in capsys.readouterr().err
    assert main(["fmu", model, "--out", str(out), "--sources-only"]) == 0
    text = capsys.readouterr().out
    assert "2 states" in text and "independent theta1" in text
    assert validate_fmu(str(out)) == []
