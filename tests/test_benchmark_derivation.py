"""The derivation benchmark runs on its smallest cases, each in fresh processes, and agrees with
sympy there; its growth exponents and target lines (no timing asserted)."""

import math

from benchmarks import derivation


def test_derivation_benchmark_quick_case(capsys):
    rows = derivation.run({"pendulum": [1], "chain": [2]}, timeout=120.0, repeat=1,
                          check_upto=2, sympy_upto={"chain": 2})
    assert [(r["family"], r["f"]) for r in rows] == [("pendulum", 2), ("chain", 3)]
    for row in rows:
        assert row["sympy_s"] is not None and row["jourdain_s"] > 0
        assert row["jourdain_rss_mb"] > 0 and row["sympy_rss_mb"] > 0
        assert row["jourdain_heap_mb"] is None or row["jourdain_heap_mb"] >= 0
        assert row["max_rel_diff"] is not None and row["max_rel_diff"] < 1e-10
    assert rows[0]["jourdain_ops_M"] <= rows[0]["sympy_ops_M"]
    text = capsys.readouterr().out
    assert derivation.HEADER in text and "pendulum" in text and "chain" in text


def test_growth_and_targets():
    rows = [{"family": "chain", "n": n, "f": f, "jourdain_s": 1e-4 * f**2,
             "jourdain_rss_mb": 50.0 + 0.01 * f**2, "jourdain_delta_mb": 0.01 * f**2,
             "jourdain_heap_mb": 0.009 * f**2,
             "jourdain_ops_M": 20 * f**2, "jourdain_ops_f": 5 * f**2, "sympy_s": None}
            for n, f in ((4, 7), (16, 31), (32, 63), (64, 127))]
    g = derivation.growth(rows)
    assert (g["fit"]["f_min"], g["top"]["f_min"], g["top"]["f_max"]) == (31, 63, 127)
    assert all(math.isclose(s[k], 2.0) for s in g.values() for k in derivation.GROWTH)
    lines = derivation.summary(rows)
    assert any(line.startswith("targets at f = 127: 1.61 s (≤ 1.5 s: NOT met), peak RSS 211 MB "
                               "(≤ 300 MB: met), growth time f^2.00, operations f^2.00, memory "
                               "f^2.00 (≤ f^2: met)") for line in lines), lines


def test_fit_starts_where_the_composite_bodies_do():
    from jourdain.stages.kinematics.result import SHARED_FROM_F

    assert derivation.FIT_F_MIN == SHARED_FROM_F
