"""The study benchmark runs on a tiny case: the batched verdicts agree with the plain loop's,
and every parallel run (threads, processes, Dask LocalClusters) equals the serial one."""

import os

import pytest

pytest.importorskip("distributed")
pytest.importorskip("xarray")

from benchmarks import study  # noqa: E402


def test_study_benchmark_tiny_case(capsys, tmp_path, monkeypatch):
    import dask

    monkeypatch.chdir(tmp_path)
    scheduler = dask.config.get("scheduler", None)
    r = study.main(["--n", "12", "--loop-cases", "12", "--mc", "16", "--rounds", "1",
                    "--repeat", "1", "--scaling-n", "0", "--ceiling-rounds", "1",
                    "--json", "figures.json"])
    text = capsys.readouterr().out
    assert "stability map, 144 cases" in text and "Monte-Carlo, 16 runs" in text
    # Dask's configuration as it was (its clients closed last-made first), the working folder
    # back, and the relative --json path written there
    assert dask.config.get("scheduler", None) == scheduler
    assert os.getcwd() == str(tmp_path) and (tmp_path / "figures.json").is_file()

    m = r["stability_map"]
    assert m["cases"] == 144
    # the batched run's verdict against stability() of the symbolic linearization, per case
    assert m["verdicts_agree"] == "12/12" and m["compiled_loop_agrees"]
    assert m["identical"] == dict.fromkeys(
        ("1_worker", "2_workers", "2_processes", "dask_1", "dask_2", "dask_fixed_1",
         "dask_fixed_2"), True)
    assert 0 < m["unstable_fraction"] < 1  # the map crosses the stability boundary
    assert m["batched_cases_per_s"] > 0 and m["dask_speedup"] > 0
    assert m["dask_fixed_1_s"] > 0 and m["dask_free_cores_bound"] > 0

    c = r["monte_carlo"]
    assert c["runs"] == 16 and c["failed"] == 0
    assert all(c[k] for k in c if k.endswith("_identical"))
    assert c["nfev_total"] > 0 and 0 < c["mkq_share_of_c"] < 1

    for key in ("ceiling_before", "ceiling_after"):
        median, lo, hi = r[key]
        assert 0 < lo <= median <= hi
