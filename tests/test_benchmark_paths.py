"""benchmarks/paths.py (the evaluation paths and the cost model) on its quick case: four small
models, every path each can take. It checks that the paths' ÿ agree (to the solve's
cond(M)·eps bound), that the chosen path is one of those measured and is what the cost model
predicts cheapest, and that the fit runs; no time and no speed ratio is asserted (the suite
runs on loaded machines)."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks import paths  # noqa: E402

EPS = 2.2e-16


def test_paths_quick(tmp_path, capsys):
    out = tmp_path / "paths.json"
    rows = paths.main(["--quick", "--fit", "--json", str(out)])
    assert json.loads(out.read_text()) == rows
    assert [r["model"] for r in rows] == [name for name, _ in paths.sweep(True)]
    for r in rows:
        assert r["chosen"] in r["us"] and r["chosen"] in r["predicted_us"], r["model"]
        assert r["predicted_us"][r["chosen"]] == min(r["predicted_us"].values())
        assert all(math.isfinite(t) and t > 0 for t in r["us"].values())
        assert ("planar" in r["us"]) == bool(r["planar"])
        # the paths solve the same M·ÿ = q − k: they agree to its conditioning
        assert r["agreement"] <= 100 * r["f"] * r["cond_M"] * EPS, r
    text = capsys.readouterr().out
    assert "worst chosen/fastest" in text and "fitted COST_NS" in text
