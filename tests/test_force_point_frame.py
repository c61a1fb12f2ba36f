"""A force's point of application given in another frame (``Force(..., point_frame=...)``,
``point_frame`` in model files; issue 38, item 6): the force acts on the body's material point
that is at that place at the instant, so its moment follows the point as it travels over the
body, as the kinematic quantities' ``point_frame`` does.

Closed forms: a disk turning by φ about z, a constant force F along x acting at the place
(0, −r, 0) fixed in the world: the generalized force is r·F whatever φ (the material point
under the axle changes); at the disk's own point (0, −r, 0) it is r·F·cos φ. The wheel of
examples/wheel_creep.toml needs no torque of its own: the creep force at the contact point
gives the same equations as the force at the hub plus the torque r·F it had.
"""

from pathlib import Path

import numpy as np
import pytest

import jourdain as jd
from jourdain.cli import main
from tests.tolerance import assert_close_eval

ROOT = Path(__file__).resolve().parents[1]


def disk(point_frame: str | None) -> jd.System:
    phi, r, F = jd.symbols("phi r F")
    body = jd.Body("disk", "world", jd.Revolute("axle", phi, "z"), mass=1,
                   inertia=(1, 1, 1))
    force = jd.Force("push", "disk", (F, 0, 0), point=(0, -r, 0), point_frame=point_frame)
    return jd.System([phi], [body], [force], parameters={"r": 0.3, "F": 2.0})


@pytest.mark.parametrize("phi", [0.0, 0.4, 1.9, -2.6])
def test_force_at_a_place_fixed_in_the_world_against_the_closed_form(phi):
    r, F = 0.3, 2.0
    moving = disk("world").evaluate([phi], [0.7])
    fixed = disk(None).evaluate([phi], [0.7])
    # a cross product of two vectors of size r and F, rotated: a few terms of scale r·F
    assert_close_eval(moving["q"], [r * F], 6, scale=r * F)
    assert_close_eval(fixed["q"], [r * F * np.cos(phi)], 6, scale=r * F)
    assert disk(None).bodies[0].name == "disk"
    assert jd.Force("f", "disk", (1, 0, 0)).point_frame == "disk"


def test_point_frame_must_name_a_body_or_the_world():
    phi = jd.symbols("phi")
    body = jd.Body("disk", "world", jd.Revolute("axle", phi, "z"), mass=1, inertia=(1, 1, 1))
    with pytest.raises(jd.ModelError, match='force "push": unknown point_frame "hub"'):
        jd.System([phi], [body], [jd.Force("push", "disk", (1, 0, 0), point_frame="hub")])


def _wheel(with_point: bool) -> jd.System:
    x, phi, m, I, r, c = jd.symbols("x phi m I r c")
    hub = jd.Body("hub", "world", jd.Prismatic("road", x, "x", position=(0, r, 0)), mass=0,
                  inertia=jd.point_mass())
    wheel = jd.Body("wheel", "hub", jd.Revolute("axle", phi, "z"), mass=m,
                    inertia=(I / 2, I / 2, I))
    vs = jd.velocity("v_s", "wheel", (0, -r, 0), frame="world", point_frame="hub")
    F = -c * vs[0]
    if with_point:
        forces = [jd.Force("creep", "wheel", (F, 0, 0), point=(0, -r, 0), point_frame="hub")]
    else:
        forces = [jd.Force("creep", "wheel", (F, 0, 0)),
                  jd.Torque("creep_moment", "wheel", (0, 0, r * F))]
    return jd.System([x, phi], [hub, wheel], forces,
                     parameters={"m": 3.0, "I": 0.06, "r": 0.25, "c": 40.0})


def test_wheel_creep_at_the_contact_equals_force_plus_torque():
    rng = np.random.default_rng(38)
    a, b = _wheel(True), _wheel(False)
    for _ in range(5):
        y, yd = rng.uniform(-3, 3, 2), rng.uniform(-3, 3, 2)
        qa, qb = a.evaluate(y, yd)["q"], b.evaluate(y, yd)["q"]
        assert_close_eval(qa, qb, 6, scale=40.0 * 0.25 * (1 + np.abs(yd).sum()))
    lin = a.linearize({"x": 0, "phi": 0}).evaluate()
    c, r = 40.0, 0.25
    assert_close_eval(lin["P"], c * np.array([[1, r], [r, r * r]]), 4, scale=c)


def test_wheel_example_has_no_separate_torque_and_rolls(tmp_path, capsys):
    """examples/wheel_creep.toml: one force at the contact point (point_frame = "hub"); the
    slip decays as exp(−c(1/m + r²/I)·t) and the hub ends at the rolling speed 2/(1 + I/(m r²))."""
    mf = jd.load_model(ROOT / "examples" / "wheel_creep.toml")
    s = mf.system
    assert [type(f).__name__ for f in s.forces] == ["Force", "Force"]
    creep = s.forces[0]
    assert creep.point_frame == "hub" and str(creep.point[1]) == "-r"
    p = s.parameter_values
    m, I, r, c = p["m"], p["I"], p["r"], p["c"]
    res = s.simulate((0.0, 0.5), [0.0, 0.0], [2.0, 0.0], rtol=1e-10, atol=1e-12)
    vs = res.yd[:, 0] + r * res.yd[:, 1]
    # integrator tolerances: fixed, as tests/README.md allows for trajectories
    np.testing.assert_allclose(vs, 2.0 * np.exp(-c * (1 / m + r * r / I) * res.t), atol=1e-7)
    np.testing.assert_allclose(res.yd[-1, 0], 2.0 / (1 + I / (m * r * r)), rtol=1e-6)
    bad = tmp_path / "bad.toml"
    text = (ROOT / "examples" / "wheel_creep.toml").read_text()
    creep = 'point = [0, "-r", 0]\npoint_frame = "hub"\n\n[forces.drag]'
    assert text.count(creep) == 1
    bad.write_text(text.replace(creep, creep.replace('"hub"', '"axle"')))
    assert main(["check", str(bad)]) == 1
    err = capsys.readouterr().err
    assert 'forces.creep.point_frame' in err or 'point_frame: unknown frame "axle"' in err, err
