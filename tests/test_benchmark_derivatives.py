"""The derivatives benchmark against Pinocchio (benchmarks/derivatives.py) runs on tiny cases,
and its numbers agree with Pinocchio's (no timing is asserted)."""

import importlib.metadata
import json

import pytest

pytest.importorskip("pinocchio")

from benchmarks import derivatives  # noqa: E402

EPS = 2.2e-16


def _check(r: dict, f: int, states: int) -> None:
    assert r["f"] == f and r["states"] == states
    assert set(r["times"]) == {"jd_fwd_1", "jd_fwd_batch", "jd_fwd_c", "pin_aba_d",
                               "jd_inv_1", "jd_inv_batch", "jd_inv_c", "pin_rnea_d"}
    assert all(t > 0 for t in r["times"].values())
    assert {"bare", "aba_derivatives", "rnea_derivatives"} <= set(r["floor"])
    c = r["check"]
    # evaluated directly: rounding only; through a solve with M: cond(M)·eps
    for k in ("tau", "tau_y", "tau_yd", "M"):
        assert c[k] < 1e3 * EPS * f, (k, c[k])
    for k in ("ydd", "ydd_y", "ydd_yd"):
        assert c[k] < 100 * f * EPS * c["cond_M_max"], (k, c[k])
    assert r["ratios"]["jd_fwd_batch"] > 0


def test_derivatives_benchmark_random_tree(capsys, tmp_path):
    out = tmp_path / "derivatives.json"
    (r,) = derivatives.main(["--robot", "--tree", "3", "--states", "20", "--rounds", "1",
                             "--check", "2", "--json", str(out)])
    text = capsys.readouterr().out
    assert "### random_tree(3, 0): f = " in text and "computeABADerivatives" in text
    assert "states/s" in text
    _check(r, r["f"], 20)
    assert json.loads(out.read_text())[0]["check"] == r["check"]


def test_derivatives_benchmark_quick_panda(capsys):
    try:
        importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        pytest.skip("example-robot-data is not installed")
    (r,) = derivatives.main(["--quick", "--states", "20", "--check", "2"])
    assert "### panda: f = 7, 7 inputs" in capsys.readouterr().out
    _check(r, 7, 20)
    assert "ydd_u" in r["check"]
