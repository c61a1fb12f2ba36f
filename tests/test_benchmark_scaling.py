"""The scaling benchmark runs its smallest cases, each in a fresh process with an empty cache."""

import json
import math

import pytest

from benchmarks import scaling


def test_scaling_benchmark_quick_case(capsys, tmp_path):
    out = tmp_path / "scaling.json"
    rows = scaling.main(["--n", "2", "--tree", "2", "--states", "20", "--repeat", "1",
                         "--trials", "1", "--json", str(out)])
    text = capsys.readouterr().out.splitlines()
    assert scaling.HEADER in text
    assert any(line.startswith("| spatial_chain(2) ") for line in text)
    assert any(line.startswith("| random_tree(2, 0) ") for line in text)
    assert [(r["kind"], r["f"]) for r in rows] == [("chain", 3), ("tree", 7)]
    for r in rows:
        assert r["source_bytes"] > 0 and r["source_all_bytes"] >= r["source_bytes"]
        assert 0 < r["first_s"] < r["wall_s"] and r["derive_s"] > 0
        assert r["batch_us"] > 0 and r["dynamics_us"] > 0 and r["rss_mb"] >= r["rss_first_mb"]
        # the integrator's M and System.evaluate's: two compiled functions, the same numbers
        assert r["M_vs_evaluate"] < 1e3 * 2.2e-16 * r["f"]
    assert json.loads(out.read_text())["rows"] == rows


def test_growth_exponents():
    rows = [{"kind": "chain", "f": f, **{k: 3.0 * f**2 for k in scaling.GROWTH}}
            for f in (8, 16, 128)]
    g = scaling.growth(rows)
    assert (g["chain"]["f_min"], g["chain"]["f_max"]) == (8, 128)
    assert (g["chain, top"]["f_min"], g["chain, top"]["f_max"]) == (16, 128)
    assert all(math.isclose(s[k], 2.0) for s in g.values() for k in scaling.GROWTH)
    assert list(scaling.growth(rows[:2])) == ["chain"] and scaling.growth(rows[:1]) == {}


def test_combine_trials():
    base = {"source_bytes": 10, "source_all_bytes": 20, "M_vs_evaluate": 1e-16, "f": 3}
    runs = [{**base, **dict.fromkeys(scaling.TIMES, t)} for t in (3.0, 1.0, 2.0)]
    r = scaling.combine(runs)
    assert all(r[k] == 1.0 for k in scaling.TIMES) and r["trials"] == 3 and r["f"] == 3
    runs[1]["source_bytes"] = 11
    with pytest.raises(RuntimeError, match="differs between trials"):
        scaling.combine(runs)


def test_matching_tree():
    from jourdain.models import TREE_JOINTS, random_tree_data

    n = scaling.matching_tree(48)
    f = sum(TREE_JOINTS[d["joint"]] for d in random_tree_data(n, 0))
    assert abs(f - 48) <= 2


def test_derivation_targets():
    rows = [{"kind": "chain", "n": n, "f": f, **{k: 1e-4 * f**2 for k in scaling.GROWTH}}
            for n, f in ((4, 7), (32, 63), (64, 127))]
    (line,) = scaling.derivation_targets(rows, scaling.growth(rows))
    assert line.startswith("symbolic M, k, q of spatial_chain(64), f = 127: 1.61 s (target ≤ "
                           "1.5 s: NOT met), 2 MB held; growth of its time and memory at most "
                           "f^2.00 (target ≤ f²: met)"), line
    assert scaling.derivation_targets(rows[:2], scaling.growth(rows[:2])) == []
