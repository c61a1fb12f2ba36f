"""Kinematics of every joint type against finite differences of positions and orientations, and
closed forms for prescribed (rheonomic) motions."""

import numpy as np
import pytest

import jourdain as jd
from jourdain.models import heavy_top, spatial_chain
from tests.kinematics_fd import compile_kinematics, fd_acceleration, fd_velocity, positions


def _all_joints_system() -> jd.System:
    """One body per joint type, chained, with tilted joint frames and a rheonomic general joint."""
    q = jd.symbols("a b c d e f g1 g2 h1 h2 h3 i1 i2 i3 j1 j2 j3 j4 j5")
    Om, amp, w, L = jd.symbols("Om amp w L")
    tilt = [jd.Rot("x", 0.3), jd.Rot("y", -0.2)]
    joints = [
        jd.Revolute("rev", q[0], "z", position=(0.1, 0.2, 0.0), orientation=tilt),
        jd.Prismatic("pri", q[1], (0.6, 0.8, 0.0), position=(0.0, 0.0, L)),
        jd.Cylindrical("cyl", (q[2], q[3]), "y", position=(0.3, 0.0, 0.1)),
        jd.Universal("uni", (q[4], q[5]), ("z", "x"), position=(0.0, 0.2, 0.2)),
        jd.Planar("pla", (q[6], q[7], q[8]), "x", position=(0.1, 0.1, 0.0)),
        jd.Spherical("sph", (q[9], q[10], q[11]), "zxz", position=(0.2, 0.0, 0.0)),
        jd.Free("fre", q[12:18], "xyz", position=(0.0, 0.1, 0.3)),
        jd.General("gen", [jd.Rot("z", Om * jd.t), jd.Trans("x", q[18] + amp * jd.sin(w * jd.t)),
                           jd.Rot((0.0, 0.6, 0.8), q[18] ** 2)], coordinates=[q[18]]),
        jd.Fixed("fix", position=(0.1, 0.0, 0.0), orientation=[jd.Rot("z", 0.5)]),
    ]
    bodies = []
    parent = "world"
    for k, j in enumerate(joints):
        name = f"b{k}"
        bodies.append(jd.Body(name, parent, j, mass=1.0 + k, com=(0.05 * k, -0.1, 0.2),
                              inertia=[[0.3, 0.01, 0.0], [0.01, 0.2, 0.02], [0.0, 0.02, 0.25]]))
        parent = name
    return jd.System(q, bodies, [jd.Gravity((0, 0, -9.81))],
                     parameters={"Om": 2.0, "amp": 0.1, "w": 3.0, "L": 0.4})


@pytest.mark.parametrize("make", [_all_joints_system, heavy_top, lambda: spatial_chain(5)],
                         ids=["all-joint-types", "heavy-top", "spatial-chain-5"])
def test_velocities_and_accelerations_match_finite_differences(make, rng):
    system = make()
    kin, fn = compile_kinematics(system)
    f = system.f
    for _ in range(3):
        y, yd, ydd = rng.uniform(-1, 1, f), rng.uniform(-1, 1, f), rng.uniform(-1, 1, f)
        t = rng.uniform(0, 1)
        out = fn(y, yd, t)
        for b in kin.bodies:
            v_fd, w_fd = fd_velocity(fn, y, yd, t, b.name)
            v = out[f"{b.name}.J_T"] @ yd + out[f"{b.name}.v_bar"].ravel()
            w = out[f"{b.name}.J_R"] @ yd + out[f"{b.name}.omega_bar"].ravel()
            np.testing.assert_allclose(v, v_fd, atol=1e-7, err_msg=f"v of {b.name}")
            np.testing.assert_allclose(w, w_fd, atol=1e-7, err_msg=f"omega of {b.name}")
            np.testing.assert_allclose(out[f"{b.name}.omega"].ravel(), w, atol=1e-12)
            a_fd, al_fd = fd_acceleration(fn, y, yd, ydd, t, b.name)
            a = out[f"{b.name}.J_T"] @ ydd + out[f"{b.name}.a_bar"].ravel()
            al = out[f"{b.name}.J_R"] @ ydd + out[f"{b.name}.alpha_bar"].ravel()
            np.testing.assert_allclose(a, a_fd, atol=1e-6, err_msg=f"a of {b.name}")
            np.testing.assert_allclose(al, al_fd, atol=1e-6, err_msg=f"alpha of {b.name}")
            S = out[f"{b.name}.S"]
            np.testing.assert_allclose(S.T @ S, np.eye(3), atol=1e-12)


def test_rotating_frame_centrifugal_and_coriolis():
    """Point mass in a plane turning at the prescribed rate Ω about z, coordinates x, y in the
    turning frame: a = (ẍ - 2Ωẏ - Ω²x, ÿ + 2Ωẋ - Ω²y) in that frame (closed form)."""
    x, y, Om, m = jd.symbols("x y Om m")
    body = jd.Body("mass", "world",
                   jd.General("plane", [jd.Rot("z", Om * jd.t), jd.Trans("x", x), jd.Trans("y", y)],
                              coordinates=[x, y]),
                   mass=m, inertia=jd.point_mass())
    s = jd.System([x, y], [body], parameters={"Om": 1.7, "m": 2.0})
    out = s.evaluate([0.4, -0.3], [0.5, 0.2], t=0.0)  # at t = 0 the turning frame = inertial
    Omv, mv = 1.7, 2.0
    np.testing.assert_allclose(out["M"], mv * np.eye(2), rtol=1e-14)
    k_closed = mv * np.array([-2 * Omv * 0.2 - Omv**2 * 0.4, 2 * Omv * 0.5 - Omv**2 * (-0.3)])
    np.testing.assert_allclose(out["k"], k_closed, rtol=1e-13)


def test_slider_on_rotating_rod():
    """Slider (point mass m) at distance s on a rod turning at Ω·t: m s̈ - m Ω² s = 0; the
    Coriolis force 2 m Ω ṡ is perpendicular to the rod, taken by the reaction, not in k."""
    s_, Om, m = jd.symbols("s Om m")
    rod = jd.Body("rod", "world", jd.General("drive", [jd.Rot("z", Om * jd.t)]), mass=1.0,
                  com=(0.5, 0, 0), inertia=jd.rod(1.0, 1.0, "x"))
    slider = jd.Body("slider", "rod", jd.Prismatic("guide", s_, "x"), mass=m,
                     inertia=jd.point_mass())
    sys_ = jd.System([s_], [rod, slider], parameters={"Om": 3.0, "m": 0.5})
    for t in (0.0, 0.7):
        out = sys_.evaluate([0.8], [1.5], t=t)
        np.testing.assert_allclose(out["M"], [[0.5]], rtol=1e-14)
        np.testing.assert_allclose(out["k"], [-0.5 * 9.0 * 0.8], rtol=1e-13)
        kin = sys_.kinematics()
        assert kin["rod"].J_T.shape == (3, 1)


def test_merged_single_axis_rotations_give_absolute_angles():
    """A planar chain described by relative angles q_i - q_(i-1) has S = R_z(q_i) exactly."""
    from jourdain.models import n_link_pendulum_on_cart

    kin = n_link_pendulum_on_cart(3).kinematics()
    S = kin["link3"].S
    import symengine as se

    assert S[0, 0] == se.cos(se.Symbol("q3"))
    assert S[1, 0] == se.sin(se.Symbol("q3"))


def test_positions_of_general_joint_with_time(rng):
    """The prescribed translation a·sin(ωt) shows up in r exactly."""
    z, amp, w = jd.symbols("z amp w")
    base = jd.Body("base", "world", jd.General("shaker", [jd.Trans("z", amp * jd.sin(w * jd.t))]),
                   mass=1.0, inertia=jd.point_mass())
    top = jd.Body("top", "base", jd.Prismatic("spring", z, "z"), mass=1.0, inertia=jd.point_mass())
    s = jd.System([z], [base, top], parameters={"amp": 0.2, "w": 5.0})
    _, fn = compile_kinematics(s)
    for t in rng.uniform(0, 2, 3):
        r, _ = positions(fn, np.array([0.3]), t, "top")
        np.testing.assert_allclose(r, [0, 0, 0.3 + 0.2 * np.sin(5.0 * t)], atol=1e-14)
