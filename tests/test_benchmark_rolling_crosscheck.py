"""benchmarks/rolling_crosscheck.py on a tiny case (its f = 64 run is the benchmark's): the
general path's ÿ and multipliers agree with the augmented system formed from the open tree's
numbers, within cond·eps of their scale."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np

SCRIPT = Path(__file__).resolve().parents[1] / "benchmarks" / "rolling_crosscheck.py"


def test_the_snake_agrees_with_the_augmented_system() -> None:
    spec = importlib.util.spec_from_file_location("rolling_crosscheck", SCRIPT)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    (row,) = mod.main(["--n", "4", "--states", "2"])
    assert row["f"] == 6
    bound = 100 * row["cond"] * np.finfo(float).eps
    assert row["ydd"] <= bound and row["lambda"] <= bound
