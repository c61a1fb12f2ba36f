"""Ensembles of simulations (jourdain.study.ensemble): a block of runs integrated in one C call
must give, bit for bit, what a per-case jourdain.simulation.simulate.simulate gives (the same
steps, outputs, work and counters), with any number of threads; a study gives the same dataset
with ensembles as with one run per case; a run that fails in the ensemble records the per-case
run's own error."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("xarray")

from jourdain.io.modelfile import load_model, loads_model  # noqa: E402
from jourdain.simulation.simulate import simulate  # noqa: E402
from jourdain.study import loads_study, run_study  # noqa: E402
from jourdain.study.context import context  # noqa: E402
from jourdain.study.ensemble import Ensemble  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
CAR = ROOT / "examples" / "quarter_car.toml"


def _cases(system: object, n: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Parameters and initial states scattered about the quarter car's defaults."""
    names = [k for k, _ in system.parameters]
    rng = np.random.default_rng(seed)
    P = np.tile([v for _, v in system.parameters], (n, 1))
    for name, rel in (("m_b", 0.05), ("k_s", 0.05), ("d_s", 0.1), ("k_t", 0.05)):
        j = names.index(name)
        P[:, j] *= 1 + rel * rng.standard_normal(n)
    Y = rng.normal(0.0, 0.01, (n, system.f))
    YD = rng.normal(0.0, 0.05, (n, system.f))
    return P, Y, YD


@pytest.mark.parametrize("method", ["DOP853", "RK45", "Radau"])
def test_ensemble_equals_per_case_simulation_bit_for_bit(method: str) -> None:
    model = load_model(CAR)
    system = model.system
    inputs = dict(model.simulation.inputs)  # an expression in t and parameters (C-compiled)
    t_eval = np.linspace(0.0, 2.0, 201)
    P, Y, YD = _cases(system, 12, seed=3)
    ens = Ensemble(system, (0.0, 2.0), t_eval, inputs=inputs, method=method, rtol=1e-7,
                   atol=1e-9)
    run = ens.run(P, Y, YD, accelerations=True)
    assert run.ok.all()
    names = [k for k, _ in system.parameters]
    for i in range(len(P)):
        r = simulate(system, (0.0, 2.0), Y[i], YD[i],
                     parameters=dict(zip(names, P[i].tolist(), strict=True)), inputs=inputs,
                     method=method, rtol=1e-7, atol=1e-9, t_eval=t_eval)
        assert np.array_equal(run.y[i], r.y), i
        assert np.array_equal(run.yd[i], r.yd), i
        assert np.array_equal(run.W[i], r.W), i
        assert np.array_equal(run.ydd[i], r.ydd), i
        assert (run.nfev[i], run.nsteps[i]) == (r.nfev, r.nsteps), i
    # the cases differ (the comparison is not of one motion with itself)
    assert np.ptp(run.y[:, -1, 0]) > 1e-4
    # threads: each case's numbers depend on that case alone
    for threads in (2, 5):
        other = ens.run(P, Y, YD, threads=threads)
        assert np.array_equal(other.y, run.y) and np.array_equal(other.yd, run.yd)


def test_ensemble_refuses_what_it_cannot_run_in_c() -> None:
    system = load_model(CAR).system
    assert not Ensemble.supports("BDF", {"z_r": 0.0})
    assert not Ensemble.supports("DOP853", {"z_r": lambda t: 0.0})
    assert Ensemble.supports("DOP853", {"z_r": "a*sin(t)"})
    with pytest.raises(ValueError, match="advanced together"):
        Ensemble(system, (0.0, 1.0), [0.0, 1.0], inputs={"z_r": 0.0}, method="LSODA")
    ens = Ensemble(system, (0.0, 1.0), [0.0, 1.0], inputs={"z_r": 0.0})
    with pytest.raises(ValueError, match="P: expected"):
        ens.run(np.zeros((2, 3)), np.zeros((2, 2)), np.zeros((2, 2)))


def test_study_with_ensembles_equals_one_run_per_case(tmp_path: Path,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    body = f"""[study]
model = "{CAR}"
design = "random"
samples = 30
seed = 5
block = 8
[vary.k_s]
distribution = "normal"
mean = 15000
std = 1500
[vary.z_b]
distribution = "uniform"
low = -0.02
high = 0.02
[compute.simulate]
t_end = 1.5
samples = 61
series = ["z_b", "z_w_d"]
max_abs = ["z_b"]
max = ["z_w"]
method = "RK45"
"""
    together = loads_study(body)
    alone = loads_study(body.replace('method = "RK45"', 'method = "RK45"\nensemble = false'))
    assert context(together).ensemble is not None and context(alone).ensemble is None
    a = run_study(together, workers=1, quiet=True)
    b = run_study(alone, workers=1, quiet=True)
    assert a.attrs["n_failed"] == 0
    for name in ("series_z_b", "series_z_w_d", "max_abs_z_b", "max_z_w", "final"):
        assert np.array_equal(a[name].values, b[name].values), name
    # two threads over the blocks (the ensembles release the GIL): the same numbers
    c = run_study(together, workers=2, pool="threads", quiet=True)
    for name in ("series_z_b", "final"):
        assert np.array_equal(a[name].values, c[name].values), name
    # a block's runs in several ensemble calls (3 runs each: memory bounded) give the same
    import jourdain.study.motion as motion

    monkeypatch.setattr(motion, "ENSEMBLE_BYTES", 3 * 8 * 61 * 5)
    e = run_study(together, workers=1, quiet=True)
    for name in ("series_z_b", "final", "max_z_w"):
        assert np.array_equal(a[name].values, e[name].values), name
    # the command line: 2 threads asked for, the NetCDF file the same
    from jourdain.cli import main
    from jourdain.study import open_study

    spec_file = tmp_path / "mc.toml"
    spec_file.write_text(body)
    assert main(["study", "--spec", str(spec_file), "--out", str(tmp_path / "mc.nc"),
                 "--workers", "2", "--pool", "threads", "--quiet"]) == 0
    d = open_study(tmp_path / "mc.nc")
    assert np.array_equal(a.series_z_b.values, d.series_z_b.values)


BLOWUP = """
[model]
name = "hardening"
[coordinates]
x = { unit = "m" }
[parameters]
m = { value = 1.0, unit = "kg" }
k = { value = 1.0, unit = "N/m" }
c = { value = 0.0, unit = "N/m^3" }
[bodies.mass]
parent = "world"
mass = "m"
inertia = "point"
joint = { type = "prismatic", name = "slide", coordinate = "x", axis = "x" }
[forces.spring]
type = "generalized"
coordinate = "x"
value = "-k*x + c*x*x*x"
[simulation]
t_end = 1.0
y0 = { x = 1.0 }
"""


def test_a_failed_run_in_an_ensemble_records_the_per_case_error(tmp_path: Path) -> None:
    """x'' = −x + c·x³ from x = 1 escapes to infinity in finite time for c ≫ 1 (a negative
    cubic stiffness): that case fails, its neighbours finish."""
    model_file = tmp_path / "hardening.toml"
    model_file.write_text(BLOWUP)
    spec = loads_study(f'[study]\nmodel = "{model_file}"\ndesign = "list"\n[vary.c]\n'
                       "values = [0.0, 1.0e4, 0.5]\n[compute.simulate]\nt_end = 1.0\n"
                       'samples = 11\nmax_abs = ["x"]\n')
    assert context(spec).ensemble is not None
    ds = run_study(spec, workers=1, quiet=True)
    err = ds.error.values
    assert err[0] == "" and err[2] == ""
    system = loads_model(BLOWUP, str(model_file)).system
    with pytest.raises(Exception) as exc:  # noqa: PT011 - the message is what is compared
        simulate(system, (0.0, 1.0), [1.0], [0.0], parameters={"c": 1.0e4},
                 t_eval=np.linspace(0.0, 1.0, 11))
    assert err[1] == f"simulate: {exc.value}"
    assert np.isnan(ds.max_abs_x.values[1])
    # c = 0: the harmonic oscillator from rest at x = 1, |x| ≤ 1 with the maximum at t = 0
    assert ds.max_abs_x.values[0] == 1.0
