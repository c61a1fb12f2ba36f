"""The derivation benchmark runs on its smallest case and agrees with sympy there."""

from benchmarks import derivation


def test_derivation_benchmark_quick_case(capsys):
    rows = derivation.run({"pendulum": [1]}, timeout=120.0, repeat=1, check_upto=1)
    (row,) = rows
    assert row["sympy_s"] is not None and row["jourdain_s"] > 0
    assert row["max_rel_diff"] is not None and row["max_rel_diff"] < 1e-10
    assert row["jourdain_ops_M"] <= row["sympy_ops_M"]
    assert "pendulum" in capsys.readouterr().out
