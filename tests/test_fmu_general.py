"""FMU export of a general system (velocity constraints, issue 34), validated with FMPy.

The benchmark bicycle's FMU has its seven independent coordinates and their rates as states;
its C code (``general_c.h`` and ``io/fmu/general.c``) solves the dependent coordinates (the
rear centre's height and the pitch: Newton on the wheels' touching rows), the velocity map
``ẏ = L·z + l`` from the no-slip rows and the accelerations at every evaluation. FMPy
validates its modelDescription.xml and runs it in model exchange (CVode) and co-simulation (the
FMU's Dormand–Prince 5(4)) against System.simulate over the model file's 5 s at 5 m/s with a
lean of 0.05 rad, by the closed systems' comparison (tests/test_fmu_closed.py: TRAJ_TOL on
coordinates and rates, the rows' residual outputs below 1e-11: Newton's stop on the holonomic
rows, the velocity rows by construction).
"""

from __future__ import annotations

import pytest

fmpy = pytest.importorskip("fmpy", reason="FMPy is in the test extra (jourdain[test])")

from fmpy import read_model_description  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

from jourdain.io import load_model  # noqa: E402
from jourdain.io.fmu import export_fmu  # noqa: E402
from tests.test_fmu import ROOT, needs_cc  # noqa: E402
from tests.test_fmu_closed import _against_simulate  # noqa: E402


@needs_cc
def test_the_bicycle_fmu_runs_the_motion_of_simulate(tmp_path) -> None:
    mf = load_model(str(ROOT / "examples" / "benchmark_bicycle.toml"))
    info = export_fmu(mf, tmp_path / "bike.fmu")
    assert validate_fmu(str(info.path)) == []
    md = read_model_description(str(info.path))
    assert info.independent == ("x", "y", "psi", "phi", "thetaR", "delta", "thetaF")
    assert md.numberOfContinuousStates == 14
    res = [v.name for v in md.modelVariables if v.name.startswith("Phi.")]
    assert res == [f"Phi.{lab}" for lab in mf.system.constraints().labels]
    _against_simulate(mf, info, dt=0.02)  # model exchange and co-simulation, the file's 5 s
