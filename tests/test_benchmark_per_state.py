"""The per-state benchmark against Pinocchio runs on its smallest case, and the numbers agree."""

import json

import pytest

pytest.importorskip("pinocchio")

from benchmarks import per_state  # noqa: E402

EPS = 2.2e-16


def test_per_state_benchmark_quick_case(capsys, tmp_path):
    out = tmp_path / "per_state.json"
    (r,) = per_state.main(["--quick", "--states", "30", "--json", str(out)])
    text = capsys.readouterr().out
    assert "### spatial_chain(3): f = 6" in text and "(a) M + bias" in text
    assert r["f"] == 6 and r["states"] == 30
    assert all(t > 0 for t in r["times"].values())
    assert {"crba_nle", "aba", "rnea", "bare"} <= set(r["floor"])
    c = r["check"]
    # evaluated without a solve: rounding only; ÿ and the wrenches through a solve with M
    assert c["M"] < 1e3 * EPS * r["f"] and c["bias"] < 1e3 * EPS * r["f"]
    assert c["ydd"] < 10 * r["f"] * EPS * c["cond_M_max"]
    assert c["wrenches"] < 10 * r["f"] * EPS * c["cond_M_max"]
    assert r["ratios"]["pin_aba"] > 0
    assert json.loads(out.read_text())[0]["check"] == c
