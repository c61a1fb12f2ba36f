"""benchmarks/rolling.py in its quick mode on a tiny case (3 speeds, a 0.3 s run): jourdain's
linearization of the benchmark bicycle equals the paper's matrices and Table 2, and the nonlinear
runs of jourdain and of sympy + SciPy (Kane's equations lambdified) agree with each other and
with a tight reference. No time is asserted.

sympy's ``linearize`` of the bicycle takes 3.5–7.5 minutes, so the quick mode takes it only from
the cache a full run leaves; the tests' compile cache is empty, so here that part is left out,
and the test checks that the output says why."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("sympy")
pytest.importorskip("scipy")
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks import rolling  # noqa: E402


def test_rolling_benchmark_quick(capsys, tmp_path) -> None:
    out = tmp_path / "rolling.json"
    r = rolling.main(["--quick", "--speeds", "3", "--T", "0.3", "--json", str(out)])
    text = capsys.readouterr().out
    assert "model to eigenvalues at 3 speeds" in text and "nonlinear run" in text
    assert json.loads(out.read_text())["simulation"]["T"] == 0.3

    eig = r["eigenvalues"]
    # the paper prints 14 digits; the complex step adds rounding only
    assert max(eig["jourdain_vs_paper"].values()) <= 1e-12
    assert eig["jourdain_table2"] <= 1e-12
    assert len(eig["jourdain_warm"]["eig"]) == 3
    for lam in eig["jourdain_warm"]["eig"]:
        assert len(lam) == 4
    # with an empty compile cache the same numbers come out
    cold = eig["jourdain_cold"]
    assert isinstance(cold, dict)
    assert np.allclose(cold["eig"], eig["jourdain_warm"]["eig"], rtol=0, atol=1e-12)
    sym = eig["sympy"]
    if isinstance(sym, str):  # no full run has cached sympy's linearization (the usual case)
        assert "takes minutes" in sym and "without --quick" in sym and sym in text
    else:
        assert eig["sympy_vs_paper_A"] <= 1e-10 and eig["sympy_table2"] <= 1e-10
        assert eig["eig_apart"] <= 1e-10

    sim = r["simulation"]
    # the two models' tight runs: the same motion to rounding of the coordinates' size
    assert sim["references_apart"] <= 1e-10 * sim["reference_scale"]
    rows = {(x["route"], x["rtol"]): x for x in sim["rows"]}
    assert set(rows) == {(k, t) for k in ("jourdain", "sympy+scipy") for t in (1e-6, 1e-8)}
    for (route, rtol), row in rows.items():
        # DOP853 at rtol over a short run: the error at rtol's order of the coordinates' size
        assert row["error"] <= 100 * rtol * sim["reference_scale"], (route, row)
        assert row["error_lean_steer"] <= row["error"] and row["nfev"] > 0
    # jourdain's holonomic rows by Newton: rounding; sympy's pitch drifts with the integration
    assert rows["jourdain", 1e-8]["max_Phi"] <= 1e-14
    assert rows["sympy+scipy", 1e-8]["Phi_end"] <= 1e-6
