"""benchmarks/loops.py --units on a short span: the four-bar in metres, millimetres and
hundredths of a millimetre takes the same right-hand sides (±10 %) and ends at the same angles
(to the rounding of its right-hand sides, eps·nfev·max|θ|) with jourdain, beside the sympy +
SciPy route in the same run. No time is asserted."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("sympy")
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.loops import SCALES, length_units  # noqa: E402


def test_length_units_on_a_short_span() -> None:
    rows = length_units(0.3)
    ours = [r for r in rows if r["route"] == "jourdain"]
    peer = [r for r in rows if r["route"] == "sympy+scipy"]
    assert [r["s"] for r in ours] == list(SCALES) and len(peer) == len(SCALES)
    ref = ours[0]
    for r in ours[1:]:
        assert abs(r["nfev"] - ref["nfev"]) <= 0.1 * ref["nfev"]
        assert r["angles_apart"] <= np.finfo(float).eps * ref["nfev"] * ref["max_angle"]
        assert r["max_Phi_per_length"] <= 1e3 * np.finfo(float).eps * ref["max_angle"]
