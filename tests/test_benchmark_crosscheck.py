"""The cross-check benchmark runs on its smallest cases, each in a fresh process."""

import json

import pytest

pytest.importorskip("pinocchio")

from benchmarks import crosscheck  # noqa: E402


def test_crosscheck_benchmark_quick_case(capsys):
    assert crosscheck.main(["--n", "3", "--tree", "3", "--states", "1", "--hashseed", "7"]) == 0
    table = capsys.readouterr().out.splitlines()
    assert table[1] == crosscheck.HEADER
    assert table[2].startswith("spatial_chain(3) ") and table[3].startswith("random_tree(3, 0) ")
    assert crosscheck.main(["--tree", "3", "--states", "1", "--hashseed", "8", "--json"]) == 0
    (r,) = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert r["hashseed"] == "8" and r["f"] == 8 and r["states"] == 2
    assert r["eig_min"] > 0 and r["eig_min_0"] > 0 and len(r["source_sha256"]) == 64
    # its first run on the provisional form (nothing compiled yet), then the library: the same
    assert r["first_kind"] != r["final_kind"] == "CompiledFunction" and r["first_same"]
    # errors relative to the largest entry, far below any modelling error
    assert max(r[k] for k in ("M", "M_0", "nle", "rnea", "tau")) < 1e3 * 2.2e-16 * r["f"]
    assert r["aba"] < 1e3 * 2.2e-16 * r["f"] * r["cond"]
