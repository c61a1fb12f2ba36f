"""Parameter studies (jourdain.study): study files, batched evaluation against single
evaluations, critical speeds against the closed form, Monte-Carlo reproducibility, resuming,
local processes and a real dask.distributed LocalCluster against the serial run."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("xarray")
pytest.importorskip("h5netcdf")

from jourdain.analysis import stability  # noqa: E402
from jourdain.analysis.state_space import state_space  # noqa: E402  (the module is jourdain.analysis.state_space)
from jourdain.io.capabilities import nominal_mapping  # noqa: E402
from jourdain.study import (  # noqa: E402
    VERDICTS,
    Progress,
    StudyError,
    load_study,
    loads_study,
    open_study,
    run_study,
)
from jourdain.study.compute import context  # noqa: E402
from jourdain.wrenches import joint_wrenches  # noqa: E402
from tests.tolerance import (  # noqa: E402
    EPS,
    assert_close_eval,
    eom_terms,
    state_space_eig_tol,
    subtree_tol,
    tree_extent,
    ydd_tol,
)

DATA = Path(__file__).parent / "data" / "study"
MODEL = DATA / "jeffcott.toml"


def _same(a: object, b: object) -> None:
    """Two datasets with the same variables, coordinates and bit-identical numbers."""
    assert set(a.data_vars) == set(b.data_vars)
    for name in a.data_vars:
        x, y = a[name].values, b[name].values
        assert x.dtype.kind == y.dtype.kind, name
        if x.dtype.kind == "f":
            assert np.array_equal(x, y, equal_nan=True), name
        else:
            assert np.array_equal(x, y), name
    for name in a.coords:
        assert np.array_equal(a[name].values, b[name].values), name


# --- study files ---------------------------------------------------------------------------------

def _study(body: str) -> str:
    return f'[study]\nmodel = "{MODEL}"\n{body}'


@pytest.mark.parametrize("body, where, words", [
    ('design = "sobol"\n[compute.linearize]\n', 2, "design"),
    ('[vary.mass]\nvalues = [1]\n[compute.linearize]\n', 2, "not a parameter, coordinate"),
    ('[vary.m]\nvalues = []\n[compute.linearize]\n', 3, "non-empty list"),
    ('[vary.m]\nrange = { start = 1, stop = 2 }\n[compute.linearize]\n', 3, "num"),
    ('design = "random"\nsamples = 10\n[vary.m]\ndistribution = "normal"\nmean = 1\nstd = 0.1\n'
     '[compute.linearize]\n', 1, "seed"),
    ('design = "random"\nsamples = 10\nseed = 1\n[vary.m]\ndistribution = "gamma"\n'
     '[compute.linearize]\n', 6, "uniform, normal, lognormal"),
    ('design = "random"\nsamples = 10\nseed = 1\n[vary.m]\ndistribution = "normal"\nmean = 1\n'
     'sigma = 0.1\n[compute.linearize]\n', 8, "not a parameter of the normal"),
    ('design = "list"\n[vary.m]\nvalues = [1, 2]\n[vary.k]\nvalues = [1]\n[compute.linearize]\n',
     3, "one length"),
    ('[vary.m]\nvalues = ["__import__(1)"]\n[compute.linearize]\n', 4, "__import__"),
    ('[vary.m]\nvalues = [1]\n', None, "nothing to compute"),
    ('[compute.linearize]\nabout = "upright"\n', 4, "no nominal motion"),
    ('[compute.critical]\nparameter = "Omega"\nlower = 0\n', 3, "lower and upper"),
    ('[compute.simulate]\nseries = ["z"]\n', 4, "coordinates or rates"),
    ('[compute.evaluate]\nreactions = ["hinge"]\n', 4, "joint names"),
    ('[compute.evaluate]\nunknown = 1\n', 4, "unknown key"),
])
def test_study_file_errors_name_the_line_and_key(body: str, where: int | None,
                                                 words: str) -> None:
    with pytest.raises(StudyError) as info:
        loads_study(_study(body), "s.toml")
    msg = str(info.value)
    assert words in msg
    if where is not None:
        assert info.value.line == where + 0 or msg.startswith(f"s.toml:{info.value.line}")
        assert msg.startswith(f"s.toml:{info.value.line}:")


def test_missing_model_and_expression_bounds() -> None:
    with pytest.raises(StudyError, match="no model"):
        loads_study("[compute.linearize]\n", "s.toml")
    spec = loads_study(_study('[vary.Omega]\nrange = { start = 0, stop = "3*sqrt(k/m)", '
                              'num = 4 }\n[compute.linearize]\n'))
    assert spec.varied[0].values == (0.0, 10.0, 20.0, 30.0)  # sqrt(100/1) = 10


# --- batched evaluation against single evaluations ---------------------------------------------

def test_batched_results_equal_single_evaluations() -> None:
    """M, k, q, ÿ and the joint wrench of every case against System.evaluate (another compiled
    code path: the symbolic projection's), the eigenvalues against state_space + eig of the
    uncompiled linearization, the verdicts against jourdain.analysis.stability."""
    spec = load_study(DATA / "map.toml")
    ds = run_study(spec, workers=1)
    ctx = context(spec)
    system, model = ctx.system, ctx.model
    lin = system.linearize(nominal_mapping(system, model.nominal_motion("centred")))
    y0 = np.array(model.simulation.y0)
    yd0 = np.zeros(2)
    assert ds["verdict"].dims == ("Omega", "d_i")
    seen = set()
    for Om in ds.Omega.values[::5]:
        for di in ds.d_i.values:
            pars = {"Omega": float(Om), "d_i": float(di)}
            case = ds.sel(Omega=Om, d_i=di)
            assert case.error.item() == ""
            out = system.evaluate(y0, yd0, parameters=pars)
            JM = np.abs(out["J_bar"]).T @ np.abs(out["M_bar"]) @ np.abs(out["J_bar"])
            assert_close_eval(case.evaluate_M.values, out["M"], 6 * 3, JM.max())
            kt, qt = eom_terms(out)
            assert_close_eval(case.evaluate_k.values, out["k"], 6 * 3, kt.max())
            assert_close_eval(case.evaluate_q.values, out["q"], 6 * 3, qt.max())
            ydd = case.evaluate_ydd.values
            assert np.abs(ydd - np.linalg.solve(out["M"], out["q"] - out["k"])).max() <= \
                2 * ydd_tol(out, ydd)
            w = joint_wrenches(system, out["g"], y0, yd0, parameters=pars)["spin"]
            ours = case.wrench_spin.values
            tol = subtree_tol(out, ydd, tree_extent(system, y0))
            assert np.abs(ours[:3] - w.force).max() <= tol
            assert np.abs(ours[3:] - w.torque).max() <= tol
            assert np.abs(ours).max() > 0
            ss = state_space(lin, parameters=pars)
            ref, tols = state_space_eig_tol(ss)
            lam = case.eigenvalue_real.values + 1j * case.eigenvalue_imag.values
            for z in lam:
                k = int(np.argmin(np.abs(ref - z)))
                assert abs(ref[k] - z) <= 2 * tols[k]
            verdict = stability(ss).verdict
            assert VERDICTS[int(case.verdict)] == verdict
            seen.add(verdict)
    assert seen == set(VERDICTS)  # the map crosses the boundary, and lands on it


def test_critical_speed_equals_closed_form() -> None:
    """Jeffcott rotor with external damping d_a and internal damping d_i: unstable above
    Ω = ω(1 + d_a/d_i), ω = √(k/m) (Kimball; Crandall). Near it Re λ ≈ d_i(Ω − Ω_c)/(2mω), so an
    eigenvalue error δ ≈ c·n·eps·‖A‖ moves the zero crossing by δ/slope."""
    spec = load_study(DATA / "critical.toml")
    ds = run_study(spec, workers=1)
    m, k = 1.0, 100.0
    w = np.sqrt(k / m)
    d_i, d_a = ds.d_i.values, ds.d_a.values
    ref = w * (1 + d_a / d_i)
    ours = ds["critical_Omega"].values
    normA = np.sqrt(k / m) + (d_a + d_i) / m + d_i * ref / m  # ‖A‖ at the crossing (bound)
    slope = d_i / (2 * m * w)
    tol = 10 * 4 * EPS * normA / slope + 4 * EPS * ref
    assert (ds.error.values == "").all()
    assert np.all(np.abs(ours - ref) <= tol), (ours - ref, tol)


def test_critical_spin_of_the_sleeping_top_equals_closed_form() -> None:
    """The sleeping top is stable above C²Ω² = 4·A₀·m·g·L, A₀ = A + m·L² (Klein–Sommerfeld;
    Magnus), with the spin angle cyclic (Routh). The stable side is only marginally stable, so
    the value is the bisection's: where the verdict changes. Within Δ of the threshold the two
    nutation eigenvalues ±(i)·√|C²Ω² − C²Ω_c²|/(2A₀)-apart lie closer than the verdict's
    cluster width r = 1e3·√eps·|λ| (modes._verdict groups them as one Jordan pair), so the
    verdict changes within Δ = A₀²·r²/(2·C²·Ω_c) of Ω_c."""
    root = Path(__file__).resolve().parents[1]
    spec = loads_study(f'[study]\nmodel = "{root / "examples" / "heavy_top.toml"}"\n'
                       'design = "list"\n[vary.L]\nvalues = [0.05, 0.1, 0.15]\n[vary.C]\n'
                       'values = [0.006, 0.008, 0.006]\n[compute.critical]\nparameter = "Omega"\n'
                       'lower = 1\nupper = 400\nabout = "fast"\n')
    ds = run_study(spec, workers=1)
    assert ds.attrs["cyclic_coordinates"] == "gamma"
    m, A, g = 1.0, 0.004, 9.81
    L, C = ds.L.values, ds.C.values
    A0 = A + m * L**2
    ref = np.sqrt(4 * A0 * m * g * L) / C
    r = 1e3 * np.sqrt(EPS) * C * ref / (2 * A0)
    tol = 2 * A0**2 * r**2 / (2 * C**2 * ref) + 1e-12 * ref
    ours = ds["critical_Omega"].values
    assert (ds.error.values == "").all()
    assert np.all(np.abs(ours - ref) <= tol), (ours - ref, tol)


# --- Monte-Carlo, failures, resuming -------------------------------------------------------------

def test_monte_carlo_is_reproducible_from_its_seed() -> None:
    spec = load_study(DATA / "montecarlo.toml")
    a = run_study(spec, workers=1)
    b = run_study(load_study(DATA / "montecarlo.toml"), workers=1)
    _same(a, b)
    # the documented draws: NumPy's Generator from the seed, one quantity after the other
    rng = np.random.default_rng(2026)
    assert np.array_equal(a.k.values, rng.normal(100, 5, 40))
    assert np.array_equal(a.m.values, rng.lognormal(0, 0.1, 40))
    assert np.array_equal(a.x.values, rng.uniform(0.001, 0.002, 40))
    other = loads_study(spec.source.replace("seed = 2026", "seed = 2027"), base=DATA)
    assert not np.array_equal(context(other).cases, context(spec).cases)
    # a case against its own simulation
    ctx = context(spec)
    i = 7
    pars = {"k": float(a.k[i]), "m": float(a.m[i])}
    r = ctx.system.simulate((0.0, 1.0), [float(a.x[i]), 0.0], [0.0, 0.0], parameters=pars,
                            t_eval=a.time.values)
    assert np.array_equal(a.series_x.values[i], r.y[:, 0])
    assert a.max_abs_x.values[i] == np.abs(r.y[:, 0]).max()
    assert np.array_equal(a.final.values[i], np.concatenate([r.y[-1], r.yd[-1]]))


def test_failed_cases_are_recorded_and_do_not_stop_the_study() -> None:
    spec = loads_study(_study('design = "list"\n[vary.m]\nvalues = [1.0, -1.0, 2.0]\n'
                              '[compute.linearize]\n[compute.critical]\nparameter = "Omega"\n'
                              "lower = 0\nupper = 12\n"))
    ds = run_study(spec, workers=1)
    err = ds.error.values
    assert "mass" in err[1] and "negative" in err[1] or "m" in err[1]
    assert int(ds.verdict[1]) == -1 and np.isnan(ds.max_real_part[1])
    # ω = √(k/m): 10 and 7.07 rad/s, thresholds 15 and 10.6: below 12 only for m = 2
    assert "stable at both" in err[0]
    assert err[2] == ""
    assert abs(float(ds.critical_Omega[2]) - np.sqrt(50) * 1.5) < 1e-9
    assert ds.attrs["n_failed"] == 2


def test_resumed_study_equals_uninterrupted(tmp_path: Path) -> None:
    spec = load_study(DATA / "map.toml")  # 124 cases, blocks of 64
    whole = run_study(spec, tmp_path / "whole.nc", workers=1)

    class Stop(Exception):
        pass

    def stop(block: dict) -> None:
        raise Stop

    out = tmp_path / "map.nc"
    with pytest.raises(Stop):
        run_study(spec, out, workers=1, on_block=stop)
    assert not out.exists() and len(list(Path(str(out) + ".parts").glob("block-*.npz"))) == 1
    computed: list[int] = []
    resumed = run_study(spec, out, workers=1, on_block=lambda b: computed.append(b["start"]))
    assert computed == [64]  # only the block that was not saved
    assert not Path(str(out) + ".parts").exists()
    _same(resumed, whole)
    _same(open_study(out), open_study(tmp_path / "whole.nc"))
    assert open_study(out).attrs["model_hash"] == spec.model_hash
    # parts of another study are not mixed in
    other = tmp_path / "other.nc"
    with pytest.raises(Stop):
        run_study(spec, other, workers=1, on_block=stop)
    spec2 = loads_study(spec.source.replace("num = 31", "num = 30"), base=DATA)
    with pytest.raises(StudyError, match="another study"):
        run_study(spec2, other, workers=1)


# --- processes and a Dask cluster ----------------------------------------------------------------

def test_local_processes_and_dask_cluster_equal_the_serial_run() -> None:
    distributed = pytest.importorskip("distributed")
    spec = load_study(DATA / "map.toml")
    serial = run_study(spec, workers=1)
    _same(run_study(spec, workers=2, pool="processes"), serial)
    _same(run_study(spec, workers=2, pool="threads"), serial)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        on_cluster = run_study(spec, scheduler=client)
        # blocks of 16 cases: 8 blocks, two tasks of four (blocks 0, 2, 4, 6 and 1, 3, 5, 7)
        fine = run_study(loads_study(spec.source.replace("block = 64", "block = 16"),
                                     base=DATA), scheduler=client)
        again = run_study(spec, scheduler=client)  # the same study twice on one client
        by_address = run_study(spec, scheduler=cluster.scheduler_address)
        # another client made later (the process's default client now): the study still
        # waits on its own client's loop, not the default one's
        with distributed.Client(cluster.scheduler_address):
            beside = run_study(spec, scheduler=client)
        # both workers took part (two blocks, one each or both on one: at least ran there)
        assert len(client.scheduler_info()["workers"]) == 2
    _same(on_cluster, serial)
    _same(fine, serial)
    _same(again, serial)
    _same(by_address, serial)
    _same(beside, serial)


@pytest.mark.parametrize("blocks, threads, tasks", [
    (20, 2, 2), (20, 1, 2), (32, 2, 2), (33, 2, 4), (176, 2, 12), (3, 8, 3), (1, 4, 1),
    (100, 8, 8), (300, 8, 24), (0, 2, 0)])
def test_cluster_tasks_are_few_strided_groups_of_at_most_16_blocks(
        blocks: int, threads: int, tasks: int) -> None:
    """A cluster's tasks: every block once; one task per worker thread while a thread's share
    is at most 16 blocks (a task's blocks are saved when it ends), else a multiple of the
    threads; sizes differ by one block at most; task k takes blocks k, k + n, k + 2n, ... (a
    region of costly cases is shared, not left to one worker)."""
    from jourdain.study.runner import _groups

    todo = [(512 * i, 512 * (i + 1)) for i in range(blocks)]
    groups = _groups(todo, threads)
    assert len(groups) == tasks
    assert sorted(b for g in groups for b in g) == todo
    sizes = [len(g) for g in groups] or [0]  # no blocks left: no task
    assert max(sizes) <= 16 and max(sizes) - min(sizes) <= 1
    for k, g in enumerate(groups):
        assert [s // 512 for s, _ in g] == list(range(k, blocks, tasks))


def test_auto_pool_uses_threads_unless_cases_simulate_one_by_one(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """pool="auto": a linearization study (one C call and stacked LAPACK per block, the GIL
    released) runs on threads of this process; a study simulating case by case on processes."""
    import jourdain.study.runner as runner

    used: list[str] = []

    def spy(name: str, real):  # noqa: ANN001, ANN202
        def run(*args, **kwargs):  # noqa: ANN002, ANN003, ANN202
            used.append(name)
            yield from real(*args, **kwargs)
        return run

    monkeypatch.setattr(runner, "_run_threads", spy("threads", runner._run_threads))
    monkeypatch.setattr(runner, "_run_local", spy("processes", runner._run_local))
    spec = load_study(DATA / "map.toml")
    _same(run_study(spec, workers=2), run_study(spec, workers=1))
    assert used == ["threads"]
    text = (DATA / "montecarlo.toml").read_text()
    assert "ensemble" not in text
    per_case = loads_study(text.replace("[compute.simulate]",
                                        "[compute.simulate]\nensemble = false"),
                           base=DATA)
    run_study(per_case, workers=2)
    assert used == ["threads", "processes"]


# --- single simulations as labelled arrays, the CLI ----------------------------------------------

def test_results_to_xarray() -> None:
    from jourdain.io.modelfile import load_model
    from jourdain.numeric import mkq_function

    model = load_model(MODEL)
    r = model.system.simulate((0.0, 0.5), [0.001, 0.0], [0.0, 0.0],
                              t_eval=np.linspace(0, 0.5, 11))
    ds = r.to_xarray()
    assert ds["y"].dims == ("time", "coordinate")
    assert list(ds.coordinate.values) == ["x", "y"]
    assert np.array_equal(ds["y"].values, r.y) and np.array_equal(ds.time.values, r.t)
    assert ds["y"].attrs["units"] == "m" and ds["yd"].attrs["units"] == "m/s"
    assert ds.time.attrs["units"] == "s"
    # the content key of the compiled equations of motion that ran the simulation
    assert ds.attrs["model_hash"] == mkq_function(model.system).key


def test_study_written_while_dask_config_names_a_closed_distributed_client(
        tmp_path: Path) -> None:
    """Two Dask clients closed in the order they were made leave ``scheduler =
    "dask.distributed"`` in Dask's configuration with no client; xarray's writer asks for that
    scheduler even for arrays in memory, and failed with Dask's "no Client active"."""
    import dask

    spec = load_study(DATA / "map.toml")
    ref = run_study(spec, workers=1, quiet=True)
    with dask.config.set(scheduler="dask.distributed"):
        ds = run_study(spec, tmp_path / "map.nc", workers=1, quiet=True)
        assert dask.config.get("scheduler") == "dask.distributed"  # the caller's, kept
    back = open_study(tmp_path / "map.nc")
    assert list(back.data_vars) == list(ref.data_vars)
    for name in ref.data_vars:  # values and coordinates; NaN equal to NaN
        assert back[name].equals(ref[name]) and ds[name].equals(ref[name]), name


def test_cli_study(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    from jourdain.cli import main

    out = tmp_path / "mc.nc"
    code = main(["study", "--spec", str(DATA / "montecarlo.toml"), "--out", str(out),
                 "--workers", "1", "--quiet", "--plots", str(tmp_path / "plots")])
    assert code == 0
    text = capsys.readouterr()
    assert "40 cases" in text.out and text.err == ""
    ds = open_study(out)
    assert ds.attrs["seed"] == 2026 and ds.sizes["case"] == 40
    assert (tmp_path / "plots" / "histogram_max_abs_x.png").exists()
    page = (tmp_path / "plots" / "index.html").read_text()
    assert "<svg" in page and "max_abs_x" in page and "Failed cases (0)" in page
    assert main(["study", "--spec", str(DATA / "montecarlo.toml"), "--out", str(out),
                 "--workers", "1", "--quiet"]) != 0
    assert "exists" in capsys.readouterr().err


def test_progress_bar() -> None:
    import io

    class Tty(io.StringIO):
        def isatty(self) -> bool:
            return True

    tty = Tty()
    bar = Progress(10, stream=tty, interval=0.0)
    bar.update(4)
    bar.update(6, 1)
    bar.close()
    lines = tty.getvalue().split("\r")[1:]
    assert lines[0].startswith("[" + "#" * 12 + "-" * 18 + "] 4/10 cases, 0.")
    assert lines[-1].startswith("[" + "#" * 30 + "] 10/10 cases, 1 failed, ")
    assert lines[-1].endswith(" s\n")
    pipe = io.StringIO()  # not a terminal: one line at the end
    bar = Progress(3, stream=pipe)
    bar.update(3)
    assert pipe.getvalue() == ""
    bar.close()
    assert pipe.getvalue().count("\n") == 1 and "3/3 cases" in pipe.getvalue()
    quiet = Tty()
    bar = Progress(3, stream=quiet, quiet=True, interval=0.0)
    bar.update(3)
    bar.close()
    assert quiet.getvalue() == ""


def test_workers_check_the_model_hash_and_the_compiled_keys() -> None:
    import dataclasses

    from jourdain.study import compute_block

    spec = load_study(DATA / "critical.toml")
    block = compute_block(spec, 0, 2, context(spec).keys)
    assert block["errors"] == ["", ""]
    with pytest.raises(StudyError, match="compiled another model"):
        compute_block(spec, 0, 2, {"linearize": "0" * 32})
    edited = dataclasses.replace(spec, model_text=spec.model_text.replace("100.0", "101.0"))
    with pytest.raises(StudyError, match="does not match the study's model hash"):
        compute_block(edited, 0, 2)


# --- frequency response per case ---------------------------------------------------------------

def test_frequency_response_per_case_is_the_jeffcott_closed_form() -> None:
    """The Jeffcott rotor's dynamic compliance in closed form: Z = Q − Ω²M̃ + iΩP =
    [[a, b], [−b, a]] with a = k − mω² + iω(d_a + d_i), b = d_i·Ω (spin Ω, excitation ω), so
    H = [[a, −b], [b, a]]/(a² + b²), for every case of a grid over the spin and the internal
    damping, within cond(Z)·eps of |H|."""
    spec = loads_study(_study(
        'design = "grid"\n[vary.Omega]\nvalues = [0.0, 12.0, 25.0]\n[vary.d_i]\n'
        'values = [0.5, 2.0]\n[compute.frequency_response]\nabout = "centred"\n'
        'excitation = "h"\nomega = { start = 0.5, stop = 40, num = 9, log = true }\n'))
    ds = run_study(spec, workers=1, quiet=True)
    assert ds["frf_magnitude"].dims == ("Omega", "d_i", "omega", "coordinate", "excitation")
    assert list(ds.excitation.values) == ["x", "y"]
    w = ds.omega.values
    assert np.allclose(w, np.geomspace(0.5, 40, 9), rtol=4 * EPS, atol=0)
    m, k, d_a = 1.0, 100.0, 0.5
    for Om in ds.Omega.values:
        for di in ds.d_i.values:
            case = ds.sel(Omega=Om, d_i=di)
            assert case.error.item() == ""
            H = case.frf_magnitude.values * np.exp(1j * case.frf_phase.values)
            for j, wj in enumerate(w):
                a = k - m * wj**2 + 1j * wj * (d_a + di)
                b = di * Om
                Z = np.array([[a, b], [-b, a]])
                ref = np.array([[a, -b], [b, a]]) / (a * a + b * b)
                tol = 10 * np.linalg.cond(Z) * EPS * np.abs(ref).max()
                assert np.abs(H[j] - ref).max() <= tol, (Om, di, wj)


def test_frequency_response_to_inputs_equals_the_single_case_function() -> None:
    """Excitation by the inputs (through B): the quarter car's road input, per case of a
    list over the body mass, against jourdain.analysis.frequency_response of the case's own
    linearization (the uncompiled path), within cond(Z)·eps."""
    from jourdain.analysis import frequency_response

    examples = Path(__file__).parents[1] / "examples"
    spec = loads_study(
        f'[study]\nmodel = "{examples / "quarter_car.toml"}"\ndesign = "list"\n'
        '[vary.m_b]\nvalues = [250.0, 400.0]\n[compute.frequency_response]\n'
        'omega = [1.0, 8.0, 60.0, 200.0]\n')
    ds = run_study(spec, workers=1, quiet=True)
    ctx = context(spec)
    system, model = ctx.system, ctx.model
    lin = system.linearize(nominal_mapping(system, model.nominal_motion(model.nominal[0].name)))
    assert list(ds.excitation.values) == list(system.input_names)
    for c in range(2):
        case = ds.isel(case=c)
        pars = {"m_b": float(case.m_b)}
        ref = frequency_response(lin, ds.omega.values, "inputs", parameters=pars).response
        got = case.frf_magnitude.values * np.exp(1j * case.frf_phase.values)
        ss = state_space(lin, parameters=pars)
        for j, wj in enumerate(ds.omega.values):
            Z = ss.Q - wj**2 * ss.M_tilde + 1j * wj * ss.P
            tol = 10 * np.linalg.cond(Z) * EPS * np.abs(ref[j]).max()
            assert np.abs(got[j] - ref[j]).max() <= tol, (c, wj)


def test_frequency_response_errors() -> None:
    for body, words in [
        ('[compute.frequency_response]\nomega = "fast"\n', "list of frequencies"),
        ('[compute.frequency_response]\nomega = [1, -2]\n', "non-negative"),
        ('[compute.frequency_response]\nomega = { start = 0, stop = 1, num = 3, log = true }\n',
         "0 < start"),
        ('[compute.frequency_response]\nomega = [1]\nexcitation = "inputs"\n', "no inputs"),
    ]:
        with pytest.raises(StudyError, match=words):
            loads_study(_study(body), "s.toml")
