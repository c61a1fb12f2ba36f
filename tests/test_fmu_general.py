"""FMU export of a general system (velocity constraints, issue 34), validated with FMPy.

The benchmark bicycle's FMU has its seven independent coordinates and their rates as states;
its C code (``general_c.h`` and ``io/fmu/general.c``) solves the dependent coordinates (the
rear centre's height and the pitch: Newton on the wheels' touching rows), the velocity map
``ẏ = L·z + l`` from the no-slip rows and the accelerations at every evaluation. FMPy
validates its modelDescription.xml and runs it in model exchange (CVode) and co-simulation (the
FMU's Dormand–Prince 5(4)) against System.simulate over 2 s at 5 m/s with a lean of 0.05 rad.

Tolerances as in tests/test_fmu.py (TRAJ_TOL on coordinates and rates; the FMU at rtol 1e-10,
the reference at 1e-11); the rows' residual outputs are checked at rounding of the
coordinates' scale (1e-11: Newton's stop on the holonomic rows, the velocity rows by
construction).
"""

from __future__ import annotations

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy", reason="FMPy is in the test extra (jourdain[test])")

from fmpy import read_model_description, simulate_fmu  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

from jourdain.io import load_model  # noqa: E402
from jourdain.io.fmu import export_fmu  # noqa: E402
from tests.test_fmu import FMU_RTOL, ROOT, TRAJ_TOL, needs_cc  # noqa: E402

RESIDUAL_TOL = 1e-11


@needs_cc
def test_the_bicycle_fmu_runs_the_motion_of_simulate(tmp_path) -> None:
    mf = load_model(str(ROOT / "examples" / "benchmark_bicycle.toml"))
    info = export_fmu(mf, tmp_path / "bike.fmu")
    assert validate_fmu(str(info.path)) == []
    md = read_model_description(str(info.path))
    assert info.independent == ("x", "y", "psi", "phi", "thetaR", "delta", "thetaF")
    assert md.numberOfContinuousStates == 14
    s, sim = mf.system, mf.simulation
    T, dt = 2.0, 0.02
    t = np.linspace(0.0, T, int(round(T / dt)) + 1)
    ref = s.simulate((0.0, T), list(sim.y0), list(sim.yd0), rtol=FMU_RTOL / 10,
                     atol=FMU_RTOL / 1000, t_eval=t)
    assert ref.status == "finished"
    names = list(s.coordinate_names)
    rates = [f"{n}_d" for n in names]
    res = [v.name for v in md.modelVariables if v.name.startswith("Phi.")]
    assert res == [f"Phi.{lab}" for lab in ref.constraints.labels]
    for fmi_type, kw in (("ModelExchange", {"solver": "CVode"}), ("CoSimulation", {})):
        r = simulate_fmu(str(info.path), fmi_type=fmi_type, stop_time=T, output_interval=dt,
                         relative_tolerance=FMU_RTOL, output=names + rates + res, **kw)
        np.testing.assert_allclose(r["time"], ref.t, rtol=0, atol=1e-12)
        err_y = np.abs(np.column_stack([r[n] for n in names]) - ref.y).max()
        err_yd = np.abs(np.column_stack([r[n] for n in rates]) - ref.yd).max()
        assert err_y < TRAJ_TOL and err_yd < TRAJ_TOL, (fmi_type, err_y, err_yd)
        assert max(np.abs(r[p]).max() for p in res) < RESIDUAL_TOL
        assert np.ptp(r["x"]) > 5.0  # it rode on
