"""FMU export (jourdain.io.fmu, jourdain fmu) validated with FMPy, a peer tool.

FMPy's validate_fmu checks modelDescription.xml; FMPy then runs the FMU, in model exchange
with its CVode (BDF) and in co-simulation with the FMU's own Dormand–Prince 5(4), against
jourdain's simulation (DOP853 in C) of the same model. The tolerance 1e-6 on y and ẏ comes
from the integrators' tolerances: both sides run at relative tolerances 1e-10 (FMU) and 1e-11
(jourdain), so each keeps its local error near 1e-10 of the state, and the global errors over
the runs below (3 s of a double pendulum released from 90°, 2 s of a quarter car) grow to
1e-7 at most (measured on y and ẏ: pendulum 1.2e-7 model exchange, 3.4e-9 co-simulation;
quarter car 2.5e-8 and 5.2e-11; along the road table 1.8e-9): 1e-6 leaves room for other
machines' rounding and stays a thousand times below the states' size, so a wrong term in the
FMU's equations fails it. Reaction outputs are compared with System.evaluate
at the same states by the tolerance of the sub-tree path (tests/README.md, subtree_tol).
"""

from __future__ import annotations

import shutil
import subprocess
import zipfile
from pathlib import Path

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy", reason="FMPy is in the test extra (jourdain[test])")

from fmpy import extract, read_model_description, simulate_fmu  # noqa: E402
from fmpy.fmi2 import FMU2Model, FMU2Slave  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

from jourdain.cli import main  # noqa: E402
from jourdain.errors import EvaluationError, ModelError  # noqa: E402
from jourdain.io import load_model  # noqa: E402
from jourdain.io.fmu import export_fmu, fmi_header_dir  # noqa: E402
from jourdain.numeric.toolchain import CompilerError, compiler  # noqa: E402
from tests.tolerance import subtree_tol, tree_extent  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
#: the agreement of trajectories (see the module docstring)
TRAJ_TOL = 1e-6
FMU_RTOL = 1e-10

try:
    compiler()
    HAVE_CC = True
except CompilerError:
    HAVE_CC = False
needs_cc = pytest.mark.skipif(not HAVE_CC, reason="no C compiler: the FMU binary is compiled")


@pytest.fixture(scope="module")
def pendulum(tmp_path_factory: pytest.TempPathFactory) -> tuple:
    mf = load_model(str(ROOT / "examples" / "double_pendulum.toml"))
    path = tmp_path_factory.mktemp("fmu") / "double_pendulum.fmu"
    return mf, export_fmu(mf, path, reactions="all")


@pytest.fixture(scope="module")
def quarter_car(tmp_path_factory: pytest.TempPathFactory) -> tuple:
    mf = load_model(str(ROOT / "examples" / "quarter_car.toml"))
    path = tmp_path_factory.mktemp("fmu") / "quarter_car.fmu"
    return mf, export_fmu(mf, path, reactions=["wheel_guide.F_x", "body_guide.T_y"])


def _variables(path: Path) -> dict:
    return {v.name: v for v in read_model_description(str(path)).modelVariables}


@needs_cc
def test_fmpy_validates_both(pendulum: tuple, quarter_car: tuple) -> None:
    for _, info in (pendulum, quarter_car):
        assert validate_fmu(str(info.path)) == []
        with zipfile.ZipFile(info.path) as zf:
            names = set(zf.namelist())
        assert f"binaries/linux64/{info.model_identifier}.so" in names
        assert {"sources/fmi2.c", "sources/model.h", "sources/buildDescription.xml",
                "sources/fmi2Functions.h"} <= names


@needs_cc
def test_model_description_names_causality_units(quarter_car: tuple) -> None:
    mf, info = quarter_car
    md = read_model_description(str(info.path))
    assert md.modelExchange is not None and md.coSimulation is not None
    assert md.numberOfContinuousStates == 4
    v = _variables(info.path)
    # parameters: tunable, with the file's values and units
    for name, value in mf.system.parameter_values.items():
        assert (v[name].causality, v[name].variability) == ("parameter", "tunable")
        assert float(v[name].start) == value
    assert v["k_s"].unit == "N/m" and v["d_s"].unit == "N*s/m" and v["g"].unit == "m/s^2"
    units = {u.name: u for u in md.unitDefinitions}
    assert (units["N*s/m"].baseUnit.kg, units["N*s/m"].baseUnit.s) == (1, -1)
    assert units["N*s/m"].baseUnit.m == 0
    # the input, the states and their derivatives, the chosen reactions
    assert v["z_r"].causality == "input" and v["z_r"].unit == "m"
    states = [d.variable.derivative.name for d in md.derivatives]
    assert states == ["z_b", "z_w", "z_b_d", "z_w_d"]
    assert [d.variable.name for d in md.derivatives] == [
        "der(z_b)", "der(z_w)", "der(z_b_d)", "der(z_w_d)"]
    assert v["z_b_d"].unit == "m/s" and v["der(z_b_d)"].unit == "m/s^2"
    assert [o.variable.name for o in md.outputs] == [
        "z_b", "z_w", "z_b_d", "z_w_d", "wheel_guide.F_x", "body_guide.T_y"]
    assert v["wheel_guide.F_x"].unit == "N" and v["body_guide.T_y"].unit == "N*m"


def _reference(mf, t_end: float, n: int, y0, yd0, **kw):
    t = np.linspace(0.0, t_end, n)
    return mf.system.simulate((0.0, t_end), y0, yd0, rtol=FMU_RTOL / 10, atol=FMU_RTOL / 1000,
                              t_eval=t, **kw)


@needs_cc
def test_double_pendulum_against_jourdain(pendulum: tuple) -> None:
    mf, info = pendulum
    s = mf.system
    T = 3.0
    ref = _reference(mf, T, 301, [np.pi / 2, 0.0], [0.0, 0.0])
    names = ["phi1", "phi2", "phi1_d", "phi2_d"]
    expected = np.column_stack([ref.y, ref.yd])
    for fmi_type, kw in (("ModelExchange", {"solver": "CVode"}), ("CoSimulation", {})):
        r = simulate_fmu(str(info.path), fmi_type=fmi_type, stop_time=T, output_interval=0.01,
                         relative_tolerance=FMU_RTOL, output=names + list(info.reactions), **kw)
        np.testing.assert_allclose(r["time"], ref.t, rtol=0, atol=1e-12)
        got = np.column_stack([r[n] for n in names])
        err = np.abs(got - expected).max()
        assert err < TRAJ_TOL, (fmi_type, err)
    # the reaction outputs at the FMU's own states, against System.evaluate there
    for k in range(0, len(r), 37):
        y = [r["phi1"][k], r["phi2"][k]]
        yd = [r["phi1_d"][k], r["phi2_d"][k]]
        out = s.evaluate(y, yd, t=r["time"][k])
        g = dict(zip(out["g_names"], out["g"], strict=True))
        ydd = np.linalg.solve(out["M"], out["q"] - out["k"])
        tol = subtree_tol(out, ydd, tree_extent(s, y))
        for name in info.reactions:
            assert abs(r[name][k] - g[name]) <= tol, (name, r[name][k], g[name], tol)


@needs_cc
def test_quarter_car_input_and_parameters(quarter_car: tuple) -> None:
    """A road step z_r = 1 cm and two parameters set at instantiation, in FMPy's model exchange
    and co-simulation. (FMPy applies inputs at its communication points only, holding them in
    between, also in model exchange: a constant input is where its run and jourdain's agree.)"""
    mf, info = quarter_car
    T, n = 2.0, 201
    params = {"m_b": 250.0, "k_s": 20000.0}
    ref = _reference(mf, T, n, [0.05, 0.0], [0.0, 0.0], parameters=params,
                     inputs={"z_r": 0.01})
    expected = np.column_stack([ref.y, ref.yd])
    signal = np.array([(0.0, 0.01), (T, 0.01)], dtype=[("time", float), ("z_r", float)])
    names = ["z_b", "z_w", "z_b_d", "z_w_d"]
    start = {**params, "z_b": 0.05}
    for fmi_type, kw in (("ModelExchange", {"solver": "CVode"}), ("CoSimulation", {})):
        r = simulate_fmu(str(info.path), fmi_type=fmi_type, stop_time=T,
                         output_interval=T / (n - 1), relative_tolerance=FMU_RTOL,
                         start_values=start, input=signal, output=names, **kw)
        got = np.column_stack([r[k] for k in names])
        err = np.abs(got - expected).max()
        assert err < TRAJ_TOL, (fmi_type, err)
    # the parameters and the input change the motion (this comparison can fail)
    plain = _reference(mf, T, n, [0.05, 0.0], [0.0, 0.0], inputs={"z_r": 0.0})
    assert np.abs(plain.y - ref.y).max() > 1e3 * TRAJ_TOL


@needs_cc
def test_quarter_car_interpolated_input(quarter_car: tuple) -> None:
    """A road profile as a table: a co-simulation master that sets, at each communication
    point, the input and its slope on the next segment (fmi2SetRealInputDerivatives), so that
    the FMU's input is the table's linear interpolation, as jourdain's table input is."""
    mf, info = quarter_car
    T, n = 2.0, 201
    tt = np.linspace(0.0, T, n)
    road = 0.02 * np.sin(2 * np.pi * 1.5 * tt) + 0.01 * (tt > 0.5)
    ref = _reference(mf, T, n, [0.0, 0.0], [0.0, 0.0], inputs={"z_r": (tt, road)},
                     parameters={"d_s": 900.0})
    md = read_model_description(str(info.path))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(info.path)),
                    modelIdentifier=info.model_identifier, instanceName="road")
    fmu.instantiate()
    states = [vr[k] for k in ("z_b", "z_w", "z_b_d", "z_w_d")]
    got = np.empty((n, 4))
    try:
        fmu.setupExperiment(tolerance=FMU_RTOL, startTime=0.0)
        fmu.setReal([vr["d_s"]], [900.0])
        fmu.enterInitializationMode()
        fmu.setReal([vr["z_r"]], [road[0]])
        fmu.exitInitializationMode()
        got[0] = fmu.getReal(states)
        for k in range(n - 1):
            fmu.setReal([vr["z_r"]], [road[k]])
            slope = (road[k + 1] - road[k]) / (tt[k + 1] - tt[k])
            fmu.setRealInputDerivatives([vr["z_r"]], [1], [slope])
            fmu.doStep(tt[k], tt[k + 1] - tt[k])
            got[k + 1] = fmu.getReal(states)
        fmu.terminate()
    finally:
        fmu.freeInstance()
    err = np.abs(got - np.column_stack([ref.y, ref.yd])).max()
    assert err < TRAJ_TOL, err


@needs_cc
def test_reactions_of_a_spatial_arm(tmp_path: Path) -> None:
    """robot_arm: 6 revolute joints about x, y and z; every reaction component at random
    states, read through fmi2GetReal after fmi2ExitInitializationMode."""
    mf = load_model(str(ROOT / "examples" / "robot_arm.toml"))
    s = mf.system
    info = export_fmu(mf, tmp_path / "arm.fmu", reactions="all")
    md = read_model_description(str(info.path))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Model(guid=md.guid, unzipDirectory=extract(str(info.path)),
                    modelIdentifier=info.model_identifier, instanceName="arm")
    fmu.instantiate()
    rng = np.random.default_rng(5)
    coords = s.coordinate_names
    try:
        for _ in range(4):
            y, yd, t = rng.uniform(-1, 1, s.f), rng.uniform(-1, 1, s.f), float(rng.uniform(0, 1))
            fmu.reset()
            fmu.setupExperiment(startTime=t)
            fmu.enterInitializationMode()
            fmu.setReal([vr[c] for c in coords] + [vr[c + "_d"] for c in coords], [*y, *yd])
            fmu.exitInitializationMode()
            got = fmu.getReal([vr[g] for g in info.reactions])
            acc = fmu.getReal([vr[f"der({c}_d)"] for c in coords])
            out = s.evaluate(y, yd, t=t)
            ydd = np.linalg.solve(out["M"], out["q"] - out["k"])
            tol = subtree_tol(out, ydd, tree_extent(s, y, t))
            np.testing.assert_allclose(got, out["g"], rtol=0, atol=tol)
            assert np.abs(np.asarray(acc) - ydd).max() <= tol
            fmu.terminate()
    finally:
        fmu.freeInstance()


def state_roundtrip(info, names: tuple[str, ...], atol: float = 0.0) -> None:
    """fmi2Get/SetFMUstate and serialization in co-simulation: a step from a saved state, a
    deserialized one and the state itself gives the variables ``names`` of the first step from
    there again (to ``atol``; 0: bit for bit)."""
    md = read_model_description(str(info.path))
    vr = [v.valueReference for v in md.modelVariables if v.name in names]
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(info.path)),
                    modelIdentifier=info.model_identifier, instanceName="cs")

    def same(got: list[float], first: list[float]) -> None:
        if atol == 0.0:
            np.testing.assert_array_equal(got, first)
        else:
            np.testing.assert_allclose(got, first, rtol=0, atol=atol)

    fmu.instantiate()
    try:
        fmu.setupExperiment(tolerance=1e-9, startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        fmu.doStep(0.0, 0.5)
        state = fmu.getFMUState()
        blob = fmu.serializeFMUState(state)
        fmu.doStep(0.5, 0.5)
        first = fmu.getReal(vr)
        restored = fmu.deSerializeFMUstate(blob)
        fmu.setFMUstate(restored)
        fmu.doStep(0.5, 0.5)
        same(fmu.getReal(vr), first)
        fmu.setFMUstate(state)
        fmu.doStep(0.5, 0.5)
        same(fmu.getReal(vr), first)
        fmu.freeFMUstate(restored)
        fmu.freeFMUstate(state)
        fmu.terminate()
    finally:
        fmu.freeInstance()


@needs_cc
def test_fmu_state_and_serialization(pendulum: tuple) -> None:
    state_roundtrip(pendulum[1], ("phi1", "phi2_d"))  # the same steps, bit for bit


@needs_cc
def test_fmi_errors_are_reported(pendulum: tuple, capsys: pytest.CaptureFixture[str]) -> None:
    """Calls the FMU refuses return fmi2Error with a message to the logger (FMPy's default
    logger prints it): a computed variable set, masses that make M indefinite."""
    from fmpy.fmi1 import FMICallException

    _, info = pendulum
    md = read_model_description(str(info.path))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Model(guid=md.guid, unzipDirectory=extract(str(info.path)),
                    modelIdentifier=info.model_identifier, instanceName="err")
    fmu.instantiate()
    try:
        capsys.readouterr()
        with pytest.raises(FMICallException):
            fmu.setReal([vr["der(phi1_d)"]], [1.0])
        assert "[ERROR] fmi2SetReal: the variable is computed" in capsys.readouterr().out
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.setReal([vr["m1"], vr["m2"]], [-1.0, -0.5])
        with pytest.raises(FMICallException):
            fmu.exitInitializationMode()
        assert "M is not positive definite" in capsys.readouterr().out
    finally:
        fmu.freeInstance()


@needs_cc
def test_sources_rebuild_the_binary(pendulum: tuple, tmp_path: Path) -> None:
    """The sources/ of the FMU compile on their own into a binary that FMPy runs."""
    _, info = pendulum
    d = Path(extract(str(info.path), unzipdir=str(tmp_path / "x")))
    lib = d / info.binary
    lib.unlink()
    src = d / "sources"
    c_files = [str(src / f) for f in ("jd_local.c", "jd_engine.c", "fmi2.c")]
    subprocess.run([compiler(), "-O0", "-fPIC", "-shared", f"-I{src}", "-o", str(lib),
                    *c_files, "-lm"], check=True, capture_output=True)
    a = simulate_fmu(str(d), fmi_type="CoSimulation", stop_time=0.5, output_interval=0.1,
                     output=["phi1"])
    b = simulate_fmu(str(info.path), fmi_type="CoSimulation", stop_time=0.5, output_interval=0.1,
                     output=["phi1"])
    np.testing.assert_allclose(a["phi1"], b["phi1"], rtol=1e-9)
    assert abs(a["phi1"][-1] - np.pi / 2) > 0.1  # it moved


def test_reproducible_sources_only(tmp_path: Path) -> None:
    mf = load_model(str(ROOT / "examples" / "double_pendulum.toml"))
    a = export_fmu(mf, tmp_path / "a.fmu", binary=False, reactions=["hinge2.F_y"])
    b = export_fmu(mf, tmp_path / "b.fmu", binary=False, reactions=["hinge2.F_y"])
    assert a.binary is None and a.guid == b.guid
    assert a.path.read_bytes() == b.path.read_bytes()
    c = export_fmu(mf, tmp_path / "c.fmu", binary=False, parameters={"m1": 2.0})
    assert c.guid != a.guid
    assert float(_variables(c.path)["m1"].start) == 2.0


def test_errors_are_named(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    mf = load_model(str(ROOT / "examples" / "double_pendulum.toml"))
    with pytest.raises(ModelError, match='"hinge1.Fx" is not a reaction component.*hinge1.F_x'):
        export_fmu(mf, tmp_path / "x.fmu", reactions=["hinge1.Fx"], binary=False)
    with pytest.raises(TypeError):
        export_fmu(mf, tmp_path / "x.fmu", reaction=["hinge1.F_x"])  # type: ignore[call-arg]
    with pytest.raises(EvaluationError, match='body "rod1": mass must be a non-negative'):
        export_fmu(mf, tmp_path / "x.fmu", parameters={"m1": -1.0}, binary=False)
    with pytest.raises(EvaluationError, match="unknown parameter"):
        export_fmu(mf, tmp_path / "x.fmu", parameters={"mx": 1.0}, binary=False)
    with pytest.raises(EvaluationError, match="y0: 'psi' is not a coordinate"):
        export_fmu(mf, tmp_path / "x.fmu", y0={"psi": 1.0}, binary=False)
    monkeypatch.setenv("CC", str(tmp_path / "no-such-cc"))
    with pytest.raises(CompilerError, match="no C compiler found"):
        export_fmu(mf, tmp_path / "x.fmu")
    monkeypatch.delenv("CC")
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name == "fmpy" else real(name, *a))
    with pytest.raises(Exception, match=r"jourdain\[fmu\]"):
        fmi_header_dir()
    assert not (tmp_path / "x.fmu").exists()


TILTED = """
[coordinates]
phi = "rad"
[parameters]
beta = 0.3
m = 1.0
[bodies.rod]
parent = "world"
mass = "m"
com = [0, -0.5, 0]
inertia = [0.1, 0.1, 0.1]
joint = { type = "revolute", name = "tilted", coordinate = "phi", axis = ["sin(beta)", 0, "cos(beta)"] }
"""


def test_unsupported_reactions_named(tmp_path: Path) -> None:
    """A joint axis with a parameter: the model exports, its reactions cannot (named)."""
    from jourdain.io import loads_model

    mf = loads_model(TILTED)
    assert export_fmu(mf, tmp_path / "t.fmu", binary=False).reactions == ()
    with pytest.raises(ModelError, match='cannot be exported: joint "tilted"'):
        export_fmu(mf, tmp_path / "t.fmu", binary=False, reactions="all")


def test_cli(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    model = str(ROOT / "examples" / "quarter_car.toml")
    out = tmp_path / "qc.fmu"
    assert main(["fmu", model, "--out", str(out), "--reaction", "body_guide.F_x",
                 "--set", "m_b=250", "--sources-only"]) == 0
    assert "modelIdentifier quarter_car" in capsys.readouterr().out
    assert validate_fmu(str(out)) == []
    v = _variables(out)
    assert float(v["m_b"].start) == 250.0 and "body_guide.F_x" in v
    assert main(["fmu", model, "--out", str(out)]) == 2  # exists: --force
    assert "--force" in capsys.readouterr().err
    assert main(["fmu", model, "--out", str(out), "--force", "--reaction", "bogus"]) == 1
    assert '"bogus" is not a reaction component' in capsys.readouterr().err
    assert main(["fmu", model, "--out", str(tmp_path / "qc.zip")]) == 2
    assert main(["fmu", model, "--out", str(out), "--force", "--set", "m_b=-1"]) == 1
    capsys.readouterr()
    shutil.rmtree(tmp_path, ignore_errors=True)


@needs_cc
def test_elastic_body_against_jourdain(tmp_path: Path) -> None:
    """An FMU of a model with an elastic body (the flexible pendulum: its elastic coordinates
    are states like any other) against jourdain's simulation of the same model."""
    mf = load_model(str(ROOT / "examples" / "flexible_pendulum.toml"))
    info = export_fmu(mf, tmp_path / "flexible_pendulum.fmu")
    T = 1.0
    y0 = [0.8, 0.0, 0.0, 0.0]
    ref = _reference(mf, T, 101, y0, [0.0] * 4)
    names = mf.system.coordinate_names
    r = simulate_fmu(str(info.path), fmi_type="CoSimulation", stop_time=T, output_interval=0.01,
                     relative_tolerance=FMU_RTOL, output=names)
    got = np.column_stack([r[n] for n in names])
    assert np.abs(got - ref.y).max() < TRAJ_TOL
