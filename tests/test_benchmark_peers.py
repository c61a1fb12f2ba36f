"""benchmarks/peers.py (work-precision against MuJoCo and Exudyn) on its tiny case: a 2-link
chain over 0.5 s, jourdain alone and with whichever peers are installed. It checks the table,
the JSON file and that the numbers are finite, the models identical and the references in
agreement; no time and no speed ratio is asserted (the suite runs on loaded machines)."""

from __future__ import annotations

import importlib.util
import json
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks import peers  # noqa: E402

INSTALLED = [p for p in ("mujoco", "exudyn") if importlib.util.find_spec(p) is not None]


def _check_results(data: dict, tools: set[str]) -> None:
    (model,) = data["models"]
    assert model["model"] == "chain2" and model["f"] == 2 and model["T"] == 0.5
    assert set(model["best"]) == tools
    for how, d in model["reference"]["agreement"].items():
        assert d < 1e-9, (how, d)  # a 2-link chain over 0.5 s: both integrations near 1e-14
    for tool, d in model["accelerations_check"].items():
        assert d < 1e-12, (tool, d)  # the same model in every tool: rounding only
    for entry in model["runs"]:
        assert entry["runs"], entry["integrator"]
        for r in entry["runs"]:
            assert r["setting"] > 0 and r["error"] >= 0
            assert r["cpu_s"] > 0 or math.isnan(r["cpu_s"])
    for tool, per in model["best"].items():
        assert set(per) == {f"{x:.0e}" for x in peers.LEVELS}
        for b in per.values():
            t = b["cpu_s"] if "cpu_s" in b else b["slowest_cpu_s"]
            assert math.isfinite(t) and t > 0, (tool, b)
    # jourdain reaches every level on so easy a case
    for level, b in model["best"]["jourdain"].items():
        assert "cpu_s" in b and b["error"] <= float(level), (level, b)


def test_tiny_case_jourdain_alone(capsys, tmp_path) -> None:
    out = tmp_path / "peers.json"
    results = peers.main(["--tiny", "--peers", "--json", str(out)])
    text = capsys.readouterr().out
    assert "### planar 2-link pendulum, 0.5 s" in text
    assert "| error | jourdain | jourdain setting |" in text
    assert "| 1e-08 |" in text
    data = json.loads(out.read_text())
    assert data["levels"] == list(peers.LEVELS)
    assert data["models"] == json.loads(json.dumps(results))
    _check_results(data, {"jourdain"})


def test_tiny_case_with_installed_peers(capsys, tmp_path) -> None:
    out = tmp_path / "peers.json"
    peers.main(["--tiny", "--peers", *INSTALLED, "--json", str(out)])
    text = capsys.readouterr().out
    names = {"mujoco": "MuJoCo", "exudyn": "Exudyn"}
    for p in INSTALLED:
        assert f"{names[p]}/jourdain" in text
        assert f"accelerations at a random state, {names[p]} against jourdain" in text
    _check_results(json.loads(out.read_text()), {"jourdain", *(names[p] for p in INSTALLED)})


def test_a_missing_peer_is_skipped_naming_the_extra(capsys, monkeypatch) -> None:
    monkeypatch.setitem(sys.modules, "mujoco", None)  # import mujoco raises ImportError
    monkeypatch.setitem(sys.modules, "exudyn", None)
    assert peers.available_peers(["mujoco", "exudyn"]) == {"MuJoCo": False, "Exudyn": False}
    text = capsys.readouterr().out
    assert "MuJoCo is not installed" in text and "Exudyn is not installed" in text
    assert "jourdain[bench]" in text


def test_peer_models_have_one_joint_per_coordinate() -> None:
    """The generated MJCF: one hinge per coordinate, the four-bar closed by one equality."""
    chain = peers.mjcf_serial(peers._chain_links(4), (0.0, -9.81, 0.0))
    assert chain.count('type="hinge"') == 4 and 'gravity="0.0 -9.81 0.0"' in chain
    from jourdain.models import robot_arm_data

    assert peers.mjcf_serial(robot_arm_data(), (0.0, 0.0, -9.81)).count("fullinertia") == 7
    bar = peers.mjcf_fourbar({"a": 0.4, "b": 1.0, "c": 0.8, "d": 1.1, "m1": 1.0, "m2": 2.0,
                              "m3": 1.5, "g": 9.81})
    assert bar.count('type="hinge"') == 3 and bar.count("<connect ") == 1
