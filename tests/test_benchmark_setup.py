"""The setup benchmark (benchmarks/setup.py) runs its smallest case: fresh processes with an
empty and with a filled cache, the same motion from both, the per-call part in this process.
No timing is asserted (the suite runs on loaded machines)."""

import json

from benchmarks import setup


def test_setup_benchmark_smallest_case(capsys, tmp_path, monkeypatch):
    monkeypatch.setattr(setup, "QUICK_CASES", (("cart", 1),))
    out = tmp_path / "setup.json"
    rows = setup.main(["--quick", "--trials", "1", "--json", str(out)])
    text = capsys.readouterr().out.splitlines()
    assert setup.HEADER in text
    assert any(line.startswith("| n_link_pendulum_on_cart(1) | 2 |") for line in text)
    assert any(line.startswith("simulate() per call") for line in text)
    assert any(line.startswith("step loop, n = 4") for line in text)
    (row,) = rows
    assert row["f"] == 2 and row["bit_identical"]
    assert 0 < row["import_s"] < row["cold_s"] and 0 < row["warm_s"]
    data = json.loads(out.read_text())
    assert data["rows"] == rows
    over = data["overhead"]
    assert over["simulate_us"] > 0 and over["run_nfev"] > over["short_nfev"] > 0
    assert over["mkq_us"] > 0


def test_mujoco_models_are_written_for_both_families():
    """The MJCF of the reference: one joint per coordinate (a ball joint for a spherical one)."""
    cart = setup.mujoco_xml("cart", 3)
    assert cart.count('type="hinge"') == 3 and cart.count('type="slide"') == 1
    chain = setup.mujoco_xml("chain", 3)  # revolute, universal, spherical
    assert chain.count('type="hinge"') == 3 and chain.count('type="ball"') == 1
