"""benchmarks/elastic.py (issue 36, item 4) on its tiny setting: every part runs (ROSS's only
where ``ross`` imports) and writes finite numbers to its JSON file. No time or ratio is
asserted (the suite runs on loaded machines)."""

from __future__ import annotations

import json
import math
from pathlib import Path

from benchmarks import elastic


def _finite(x: object) -> bool:
    return isinstance(x, int | float) and not isinstance(x, bool) and math.isfinite(x)


def test_elastic_benchmark_tiny(capsys, tmp_path: Path) -> None:
    ross = elastic._ross() is not None
    out = tmp_path / "elastic.json"
    elastic.main(["--tiny", "--json", str(out), *([] if ross else ["--no-ross"])])
    text = capsys.readouterr().out
    assert "Model to first numbers, empty cache" in text
    assert "Campbell diagram, 5 speeds" in text and "Spin-up (Kane–Ryan–Banerjee)" in text

    data = json.loads(out.read_text())
    assert data["status"] == "complete"
    assert data["done"] == ["first_numbers", "campbell", "spin_up"]

    first = data["first_numbers"]
    for key in ("first_s", "import_s", "build_s", "derive_s", "linearize_s", "eig_s",
                "sim_first_s", "sim_compile_s", "sim_step_s", "sim_cc_s"):
        assert _finite(first[key]) and first[key] >= 0, key
    assert first["first_s"] > 0 and first["sim_cc_calls"] >= 1
    assert len(first["lowest_rad_s"]) == 4 and all(_finite(w) for w in first["lowest_rad_s"])

    camp = data["campbell"]
    for key in ("jd_build_s", "jd_linearize_s", "jd_compile_s", "jd_sweep_s",
                "jd_compiled_sweep_s", "compiled_vs_symbolic_rel"):
        assert _finite(camp[key]), key
    if ross:
        for key in ("ross_campbell_s", "ross_build_s", "ratio", "ratio_with_setup",
                    "rel_diff_max", "rel_diff_lowest4"):
            assert _finite(camp[key]), key
        assert camp["rel_diff_max"] < 0.05  # the same rotor (6 elements: a coarse lumping)
    else:
        assert camp["ratio"] is None

    spin = data["spin_up"]
    assert _finite(spin["peak_m"]) and spin["peak_m"] > 0
    assert _finite(spin["scipy_dop853_at_ref_tol_error"])
    assert set(spin["runs"]) == set(elastic.INTEGRATORS)
    for rows in spin["runs"].values():
        assert rows
        for row in rows:
            assert _finite(row["error"]) and _finite(row["time_s"]) and row["nfev"] > 0
    assert set(spin["matched"]) == {f"{level:.0e}" for level in elastic.LEVELS}
    for entry in spin["matched"].values():
        for name in elastic.INTEGRATORS:
            if entry[name] is not None:
                assert _finite(entry[name]["time_s"]) and _finite(entry[name]["error"])
