"""The linearization of a closed system about a nominal motion and its Floquet analysis
(issue 32: linearize "any nominal motion, --periodic too"), against a tree model of the same
mechanism in other coordinates: Floquet multipliers do not depend on the coordinates.

The mechanism: a bob of mass m on a massless rod of length l, hinged to a mount moved up and
down as A·cos(w·t) (examples/parametric_pendulum.toml, the Mathieu equation). As a closed
system the bob moves in the plane with two prismatic joints (x, y relative to the mount) and
the rod is the closing constraint x² + y² − l² = 0; the tree model has the rod's angle φ. About
the hanging and the upside-down rest relative to the mount (x = 0, y = ∓l) both linearize to
the same Mathieu equation (η_x = ±l·η_φ), so their monodromy matrices are similar and their
multipliers equal; the stability verdicts (stable upside down at the fast excitation,
Kapitza) agree.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import jourdain as jd
from jourdain.model import Body, General, Gravity, Prismatic, Trans, symbols

ROOT = Path(__file__).resolve().parents[1]
RTOL = 1e-9


def closed_pendulum(w_value: float = 100.0) -> jd.System:
    x, y = symbols("x y")
    m, l, A, w, m0, g = symbols("m l A w m0 g")
    bodies = [
        Body("mount", "world", General("shaker", [Trans("y", A * jd.cos(w * jd.t))]),
             mass=m0, inertia=(0, 0, 0)),
        Body("slide", "mount", Prismatic("sx", x, "x"), mass=0, inertia=(0, 0, 0)),
        Body("bob", "slide", Prismatic("sy", y, "y"), mass=m, inertia=(0, 0, 0)),
    ]
    tree = jd.System([x, y], bodies, [Gravity((0, -g, 0))],
                     parameters={"m": 0.2, "l": 0.5, "A": 0.05, "w": w_value, "m0": 1.0,
                                 "g": 9.81}, name="pendulum as a closed system")
    rod = jd.ClosingJoint("rod", "constraint", expressions=[x ** 2 + y ** 2 - l ** 2])
    return tree.closed_by([rod], independent=["x"])


@pytest.mark.parametrize("about,y_s,w", [("inverted", 0.5, 100.0), ("hanging", -0.5, 100.0),
                                         ("hanging", -0.5, 8.86)])
def test_floquet_multipliers_equal_the_tree_models(about: str, y_s: float, w: float) -> None:
    """At w = 100 rad/s both rest positions are stable (upside down: Kapitza); at
    w = 8.86 rad/s = 2·sqrt(g/l) the hanging one is in the first resonance tongue."""
    mf = jd.load_model(ROOT / "examples" / "parametric_pendulum.toml")
    tree_sys = mf.system
    nom = next(n for n in mf.nominal if n.name == about)
    T = 2 * np.pi / w
    nominal = dict(zip(tree_sys.coordinate_names, nom.y, strict=True))
    tree_fl = jd.floquet(tree_sys.linearize(nominal), T, rtol=RTOL, parameters={"w": w})
    closed = closed_pendulum(w)
    lin = closed.linearize({"x": 0.0, "y": y_s})  # at rest on the mount that moves in t
    fl = jd.floquet(lin, T, rtol=RTOL)
    assert fl.state_names == ("x", "x_d")
    # both integrations keep their local errors below rtol over a period: the multipliers
    # agree to a few hundred rtol times their size (the tolerance each Floquet reports)
    tol = fl.tolerance + tree_fl.tolerance
    assert np.max(np.abs(np.sort_complex(fl.multipliers) - np.sort_complex(tree_fl.multipliers))
                  ) <= tol
    assert fl.verdict == tree_fl.verdict
    assert fl.is_stable == (w == 100.0)


def test_time_variant_closed_linearization_is_not_judged_at_a_frozen_time() -> None:
    lin = closed_pendulum().linearize({"x": 0.0, "y": -0.5})
    with pytest.raises(jd.TimeVariantError):
        jd.state_space(lin)
    m = lin.evaluate(0.01)
    assert m["M_tilde"].shape == (1, 1) and m["y_s"][1] == pytest.approx(-0.5, abs=1e-12)
