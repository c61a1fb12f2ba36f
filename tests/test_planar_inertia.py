"""Planar bodies (issue 38, item 3): an inertia given as (0, 0, I_zz), as planar tools write it,
is refused for a 3-D body with a message that says how to describe a planar body, and accepted
as ``jd.planar_inertia(I_zz, "z")`` (model files: ``inertia = { planar = { moment = ..., axis =
"z" } }``) where the body's angular velocity stays about z; a body that can turn about another
axis is refused; the reaction moments across the plane are flagged.

Reference: with ω about z, the motion is that of any body with the same moment about z and z a
principal axis, e.g. a thin rod along x, inertia (0, I, I): M, k, q and the in-plane reactions
must agree at any state.
"""

import numpy as np
import pytest

import jourdain as jd
from jourdain.cli import main
from tests.tolerance import assert_close_eval, reactions_tol

PARAMETERS = {"m": 1.3, "l": 0.9, "I": 1.3 * 0.81 / 12, "g": 9.81}


def double_pendulum(inertia) -> jd.System:
    phi1, phi2, m, l, g = jd.symbols("phi1 phi2 m l g")
    b1 = jd.Body("link1", "world", jd.Revolute("h1", phi1, "z"), mass=m, com=(l / 2, 0, 0),
                 inertia=inertia())
    b2 = jd.Body("link2", "link1", jd.Revolute("h2", phi2, "z", position=(l, 0, 0)), mass=m,
                 com=(l / 2, 0, 0), inertia=inertia())
    return jd.System([phi1, phi2], [b1, b2], [jd.Gravity((0, -g, 0))],
                     parameters=PARAMETERS)


def planar() -> object:
    return jd.planar_inertia(jd.symbols("I"), "z")


def rod() -> object:
    I = jd.symbols("I")
    return (0, I, I)


def test_planar_bodies_move_as_bodies_with_a_principal_axis():
    a, b = double_pendulum(planar), double_pendulum(rod)
    assert [body.planar for body in a.bodies] == ["z", "z"]
    rng = np.random.default_rng(38)
    for _ in range(5):
        y, yd = rng.uniform(-3, 3, 2), rng.uniform(-3, 3, 2)
        oa, ob = a.evaluate(y, yd), b.evaluate(y, yd)
        scale = PARAMETERS["m"] * PARAMETERS["l"] * (PARAMETERS["g"] + 9 * PARAMETERS["l"])
        for name in ("M", "k", "q"):
            assert_close_eval(oa[name], ob[name], 12, scale=scale, err_msg=name)
        assert oa["g_names"] == ob["g_names"]
        tol = reactions_tol(oa) + reactions_tol(ob)
        inplane = [i for i, n in enumerate(oa["g_names"]) if n.split(".")[1][:3] in
                   ("F_x", "F_y")]
        assert np.abs(oa["g"][inplane] - ob["g"][inplane]).max() <= tol


def test_reaction_moments_across_the_plane_are_flagged():
    assert double_pendulum(planar).reactions().planar_moments == (
        "h1.T_x", "h1.T_y", "h2.T_x", "h2.T_y")
    assert double_pendulum(rod).reactions().planar_moments == ()


def test_a_planar_body_that_can_turn_about_another_axis_is_refused():
    phi, theta, m, I = jd.symbols("phi theta m I")
    body = jd.Body("plate", "world", jd.Universal("u", (phi, theta), ("z", "x")), mass=m,
                   inertia=jd.planar_inertia(I, "z"))
    system = jd.System([phi, theta], [body], [], parameters={"m": 1.0, "I": 0.2})
    with pytest.raises(jd.ModelError, match=r'body "plate": its planar inertia .* angular '
                       r"velocity has components across z"):
        system.equations_of_motion()


def test_the_triangle_inequality_message_says_how_to_describe_a_planar_body():
    phi = jd.symbols("phi")
    with pytest.raises(jd.ModelError, match=r"triangle inequality\)\. A body that moves in a "
                       r"plane .*jd\.planar_inertia\(I_zz, \"z\"\).*planar = \{ moment"):
        jd.Body("plate", "world", jd.Revolute("h", phi, "z"), mass=1, inertia=(0, 0, 2.0))
    with pytest.raises(jd.ModelError, match="axis must be x, y or z"):
        jd.planar_inertia(1.0, "w")


MODEL = """[model]
name = "planar pendulum"
[coordinates]
phi = "rad"
[parameters]
m = 1.3
l = 0.9
I = 0.08775
g = 9.81
[bodies.link]
parent = "world"
mass = "m"
com = ["l/2", 0, 0]
inertia = INERTIA
joint = { type = "revolute", coordinate = "phi", axis = "z" }
[forces.gravity]
type = "gravity"
vector = [0, "-g", 0]
"""


def test_model_files_read_a_planar_inertia(tmp_path, capsys):
    planar_file = tmp_path / "planar.toml"
    planar_file.write_text(MODEL.replace("INERTIA", '{ planar = { moment = "I", axis = "z" } }'))
    rod_file = tmp_path / "rod.toml"
    rod_file.write_text(MODEL.replace("INERTIA", '[0, "I", "I"]'))
    a, b = jd.load_model(planar_file).system, jd.load_model(rod_file).system
    assert a.bodies[0].planar == "z"
    for phi in (0.2, -1.1):
        oa, ob = a.evaluate([phi], [0.4]), b.evaluate([phi], [0.4])
        for name in ("M", "q"):
            assert_close_eval(oa[name], ob[name], 6, scale=20.0, err_msg=name)
    bad = tmp_path / "bad.toml"
    bad.write_text(MODEL.replace("INERTIA", '[0, 0, "I"]'))
    assert main(["check", str(bad)]) == 1
    err = capsys.readouterr().err
    assert 'body "link" → inertia' in err and "planar = { moment" in err, err
