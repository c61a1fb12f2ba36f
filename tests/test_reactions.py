"""Reaction forces (METHOD.md §4): closed forms derived by hand, the full Newton–Euler residual,
the single-joint path against the full solve, and the orthogonality check."""

import numpy as np
import pytest
import symengine as se
import sympy

import jourdain as jd
from jourdain.analysis.reactions import check_orthogonality
from jourdain.models import double_pendulum, n_link_pendulum_on_cart, spatial_chain
from jourdain.stages.reactions import graph_values
from tests.tolerance import (
    eom_terms,
    eval_tol,
    newton_euler_tol,
    reactions_tol,
    solve_scale,
    solve_tol,
    subtree_tol,
    tree_extent,
    ydd_of,
)


def _pendulum(inertia: str):
    phi, m, l, g = jd.symbols("phi m l g")
    if inertia == "point":
        body = jd.Body("bob", "world", jd.Revolute("hinge", phi, "z"), mass=m, com=(0, -l, 0),
                       inertia=jd.point_mass())
    else:  # uniform thin rod: singular inertia about its own axis
        body = jd.Body("rod", "world", jd.Revolute("hinge", phi, "z"), mass=m,
                       com=(0, -l / 2, 0), inertia=jd.rod(m, l, "y"))
    return jd.System([phi], [body], [jd.Gravity((0, -g, 0))],
                     parameters={"m": 1.3, "l": 0.8, "g": 9.81})


_ydd = ydd_of


def _residual(out):
    """M̄·J̄·ÿ + q̄^c − q̄^e − Q̄·g, and its tolerance (tests/tolerance.py: the errors of the
    solves for ÿ and g mapped to forces, and the rounding of the summed terms)."""
    ydd = _ydd(out)
    lhs = out["M_bar"] @ (out["J_bar"] @ ydd) + out["q_c"] - out["q_e"]
    return lhs - out["Q_bar"] @ out["g"], newton_euler_tol(out, ydd)


def test_pendulum_rod_force_closed_form():
    """Point mass on a massless rod: the rod force m·l·φ̇² + m·g·cos φ (radial, +y of the body
    frame, towards the pivot); no tangential force and no torques (statics of the massless rod)."""
    s = _pendulum("point")
    r = s.reactions()
    assert r.g_names == ("hinge.F_x", "hinge.F_y", "hinge.F_z", "hinge.T_x", "hinge.T_y")
    assert len(r.singular_rows) == 3  # the rotational rows of the point mass
    assert repr(r).startswith("Reactions(") and "Q_bar 6x5" in repr(r)
    phi, phi_d, m, l, g = sympy.symbols("phi phi_d m l g")
    G = r.g()
    expected = [0, m * l * phi_d**2 + m * g * sympy.cos(phi), 0, 0, 0]
    for got, want in zip(G, expected, strict=True):
        assert sympy.simplify(got - want) == 0
    rng = np.random.default_rng(1)
    for _ in range(5):
        y, yd = rng.uniform(-np.pi, np.pi, 1), rng.uniform(-3, 3, 1)
        out = s.evaluate(y, yd)
        want = [0, 1.3 * 0.8 * yd[0] ** 2 + 1.3 * 9.81 * np.cos(y[0]), 0, 0, 0]
        np.testing.assert_allclose(out["g"], want, rtol=0, atol=reactions_tol(out))
        assert out["g_undetermined"] == []


def test_rod_pendulum_tangential_force():
    """Uniform rod (com at l/2, I = m l²/12 across, 0 along): with φ̈ = −3g/(2l)·sin φ the hinge
    carries F_x = m g sin φ / 4 across the rod and F_y = m (l/2) φ̇² + m g cos φ along it."""
    s = _pendulum("rod")
    r = s.reactions()
    assert len(r.singular_rows) == 1  # only the axial rotational row
    rng = np.random.default_rng(2)
    m, l, g = 1.3, 0.8, 9.81
    for _ in range(5):
        y, yd = rng.uniform(-np.pi, np.pi, 1), rng.uniform(-3, 3, 1)
        out = s.evaluate(y, yd)
        want = [m * g * np.sin(y[0]) / 4, m * l / 2 * yd[0] ** 2 + m * g * np.cos(y[0]), 0, 0, 0]
        np.testing.assert_allclose(out["g"], want, rtol=0, atol=reactions_tol(out))


def _rotor(driven: bool):
    """Unbalanced rotor: centre of mass (e, 0, h), products of inertia Ixz, Iyz, spinning about
    the bearing's z axis; gravity along -z. ``driven``: angle Ω t + α t²/2 prescribed (all six
    directions constrained), with a sled on a slider as the system's coordinate."""
    m, e, h, A, B, C, Ixz, Iyz, g, Om, al = jd.symbols("m e h A B C Ixz Iyz g Omega alpha")
    phi, x = jd.symbols("phi x")
    I = [[A, 0, Ixz], [0, B, Iyz], [Ixz, Iyz, C]]
    params = {"m": 2.5, "e": 0.01, "h": 0.2, "A": 0.05, "B": 0.06, "C": 0.09, "Ixz": 0.004,
              "Iyz": -0.003, "g": 9.81}
    if not driven:
        rotor = jd.Body("rotor", "world", jd.Revolute("bearing", phi, "z"), mass=m,
                        com=(e, 0, h), inertia=I)
        return jd.System([phi], [rotor], [jd.Gravity((0, 0, -g))], parameters=params)
    params.update({"Omega": 30.0, "alpha": 4.0})
    rotor = jd.Body("rotor", "world",
                    jd.General("bearing", [jd.Rot("z", Om * jd.t + al * jd.t**2 / 2)]), mass=m,
                    com=(e, 0, h), inertia=I)
    sled = jd.Body("sled", "world", jd.Prismatic("slider", x, "x", position=(2, 0, 0)), mass=1,
                   inertia=(0.1, 0.1, 0.1))
    return jd.System([x], [rotor, sled], [jd.Gravity((0, 0, -g))], parameters=params)


def _rotor_hand(p, Om, al):
    """Bearing wrench (body frame, at the bearing) from Newton and Euler by hand:
    F = m·(−e Ω², e α, g); T = I·(0, 0, α) + ω × I ω + c × F."""
    m, e, h, g = p["m"], p["e"], p["h"], p["g"]
    Ixz, Iyz, C = p["Ixz"], p["Iyz"], p["C"]
    F = np.array([-m * e * Om**2, m * e * al, m * g])
    T = np.array([Ixz * al - Om**2 * Iyz - h * m * e * al,
                  Iyz * al + Om**2 * Ixz - h * m * e * Om**2 - e * m * g,
                  (C + m * e**2) * al])
    return F, T


def test_rotor_bearing_forces_steady_spin():
    s = _rotor(driven=False)
    p = s.parameter_values
    for phi, Om in [(0.3, 40.0), (-2.0, 12.0)]:
        out = s.evaluate([phi], [Om])
        # spin about a fixed axis, no axial torque: q − k cancels to rounding of its terms
        ydd = _ydd(out)
        assert abs(ydd[0]) <= solve_tol(out["M"], solve_scale(out["M"], ydd, eom_terms(out)))
        F, T = _rotor_hand(p, Om, 0.0)
        g = dict(zip(out["g_names"], out["g"], strict=True))
        np.testing.assert_allclose([g["bearing.F_x"], g["bearing.F_y"], g["bearing.F_z"],
                                    g["bearing.T_x"], g["bearing.T_y"]],
                                   [*F, T[0], T[1]], rtol=0, atol=reactions_tol(out))


def test_rotor_on_driven_shaft_rheonomic():
    """Prescribed spin-up: the drive transmits all six components, including the drive torque
    T_z = (C + m e²)·α; Ω(t) = Ω0 + α t."""
    s = _rotor(driven=True)
    p = s.parameter_values
    r = s.reactions()
    assert r.joint("bearing").names == tuple(f"bearing.{n}" for n in
                                             ("F_x", "F_y", "F_z", "T_x", "T_y", "T_z"))
    for t in (0.0, 0.7, 1.9):
        out = s.evaluate([0.2], [0.5], t=t)
        F, T = _rotor_hand(p, p["Omega"] + p["alpha"] * t, p["alpha"])
        np.testing.assert_allclose(out["g"][:6], [*F, *T], rtol=0, atol=reactions_tol(out))
        res, tol = _residual(out)
        assert np.abs(res).max() <= tol


@pytest.mark.parametrize("make", [lambda: spatial_chain(6), lambda: n_link_pendulum_on_cart(4)],
                         ids=["spatial_chain-6", "cart-pendulum-4"])
def test_newton_euler_residual(make, rng):
    """M̄·J̄·ÿ + q̄^c − q̄^e − Q̄·g = 0 at random states, ÿ from the equations of motion; the
    single-joint path (sub-tree residual) gives the same components. Both to the rounding the
    solves for ÿ and g allow at the state (cond(M) reaches 1e7..1e9 at some states of the
    chain)."""
    s = make()
    joints = [b.joint.name for b in s.bodies]
    for _ in range(4):
        y = rng.uniform(-np.pi, np.pi, s.f)
        yd = rng.uniform(-3, 3, s.f)
        kw = {"inputs": {"F": rng.uniform(-5, 5)}} if s.inputs else {}
        out = s.evaluate(y, yd, **kw)
        res, tol = _residual(out)
        assert np.abs(res).max() <= tol
        assert out["g_undetermined"] == []
        one = jd.joint_reactions(s, joints, y, yd, **kw)
        g1 = np.array([one[n] for n in out["g_names"]])
        tol1 = subtree_tol(out, _ydd(out), tree_extent(s, y))
        assert np.abs(g1 - out["g"]).max() <= tol1
        if not s.reactions().singular_rows:  # N̂ symmetric positive definite
            N = out["N_hat"]
            assert np.abs(N - N.T).max() == 0.0
            assert np.linalg.eigvalsh(N).min() > 0


def test_point_masses_are_statics_of_massless_links():
    """Cart pendulum: the links are massless rods with point masses, so each hinge transmits a
    force along its rod only (F_x = 0 across it), and no torques in the plane (T_x = T_y = 0)."""
    s = n_link_pendulum_on_cart(3)
    rng = np.random.default_rng(5)
    out = s.evaluate(rng.uniform(-2, 2, s.f), rng.uniform(-2, 2, s.f), inputs={"F": 1.0})
    g = dict(zip(out["g_names"], out["g"], strict=True))
    tol = reactions_tol(out)
    for i in (1, 2, 3):
        assert abs(g[f"hinge{i}.F_x"]) <= tol and abs(g[f"hinge{i}.F_y"]) > 1e3 * tol
        assert abs(g[f"hinge{i}.T_x"]) <= tol and abs(g[f"hinge{i}.T_y"]) <= tol


def test_massless_link_and_weld():
    """A massless link on a hinge carries a point mass welded to its end: the hinge and the weld
    transmit the rod force m·l·φ̇² + m·g·cos φ; the weld transmits no torque."""
    phi, m, l, g = jd.symbols("phi m l g")
    bodies = [jd.Body("link", "world", jd.Revolute("hinge", phi, "z"), mass=0,
                      inertia=jd.point_mass()),
              jd.Body("bob", "link", jd.Fixed("weld", position=(0, -l, 0)), mass=m,
                      inertia=jd.point_mass())]
    s = jd.System([phi], bodies, [jd.Gravity((0, -g, 0))],
                  parameters={"m": 0.7, "l": 1.1, "g": 9.81})
    out = s.evaluate([0.4], [2.0])
    g_ = dict(zip(out["g_names"], out["g"], strict=True))
    radial = 0.7 * 1.1 * 4.0 + 0.7 * 9.81 * np.cos(0.4)
    tol = reactions_tol(out)
    for j in ("hinge", "weld"):
        assert g_[f"{j}.F_y"] == pytest.approx(radial, rel=0, abs=tol)
        assert abs(g_[f"{j}.F_x"]) <= tol
    for c in "xyz":
        assert abs(g_[f"weld.T_{c}"]) <= tol
    res, tol = _residual(out)
    assert np.abs(res).max() <= tol


def _zoo():
    """Every joint type, with offsets, turned joint frames and full inertia tensors."""
    y = jd.symbols("x1 phi2 s2 u3 v3 th3 a5 b5 e1 e2 e3 f1 f2 f3 f4 f5 f6 h8")
    g = jd.symbols("g")
    I = [[0.03, 0.002, -0.001], [0.002, 0.04, 0.003], [-0.001, 0.003, 0.05]]
    tilt = [[1, 0, 0], [0, np.cos(0.3), -np.sin(0.3)], [0, np.sin(0.3), np.cos(0.3)]]
    u = (0.6, 0.0, 0.8)
    bodies = [
        jd.Body("A", "world", jd.Prismatic("slide", y[0], u), mass=2.0, com=(0.1, 0.0, 0.05),
                inertia=I),
        jd.Body("B", "A", jd.Cylindrical("cyl", (y[1], y[2]), "y", position=(0.2, 0.1, 0)),
                mass=1.5, com=(0.0, 0.1, 0.1), inertia=I),
        jd.Body("C", "B", jd.Planar("plane", y[3:6], "x", orientation=tilt,
                                    position=(0, 0.3, 0)), mass=1.0, com=(0.05, 0.1, 0), inertia=I),
        jd.Body("D", "C", jd.Fixed("weld", position=(0.1, 0.1, 0.1), orientation=tilt), mass=0.5,
                com=(0, 0, 0.1), inertia=I),
        jd.Body("E", "D", jd.Universal("cardan", y[6:8], ("z", "x"), position=(0, 0, 0.2)),
                mass=0.8, com=(0.05, -0.02, 0.15), inertia=I),
        jd.Body("F", "E", jd.Spherical("ball", y[8:11], "zxz", position=(0, 0, 0.3)), mass=0.6,
                com=(0.02, 0.03, 0.1), inertia=I),
        jd.Body("G", "F", jd.Free("float", y[11:17], position=(0.1, 0, 0.2)), mass=0.4,
                com=(0.01, 0.02, 0.03), inertia=I),
        jd.Body("H", "C", jd.General("screw", [jd.Trans("z", 0.05 * y[17]), jd.Rot("z", y[17])],
                                     coordinates=[y[17]], position=(0.2, 0, 0)), mass=0.3,
                com=(0.1, 0, 0), inertia=I),
    ]
    return jd.System(list(y), bodies, [jd.Gravity((0, 0, -g))], parameters={"g": 9.81})


def test_every_joint_type(rng):
    s = _zoo()
    r = s.reactions()
    counts = {jr.joint.name: len(jr.names) for jr in r.joints}
    assert counts == {"slide": 5, "cyl": 4, "plane": 3, "weld": 6, "cardan": 4, "ball": 3,
                      "float": 0, "screw": 5}
    assert r.joint("screw").names == tuple(f"screw.{n}" for n in ("F_x", "F_y", "T_x", "T_y",
                                                                     "W_1"))
    assert r.joint("cardan").names[-1] == "cardan.T_n"
    # each joint's directions are orthogonal to its motions identically (expanded products)
    assert dict(r.orthogonality) == dict.fromkeys(counts, "symbolic")
    for _ in range(3):
        y = rng.uniform(-np.pi, np.pi, s.f)
        yd = rng.uniform(-2, 2, s.f)
        out = s.evaluate(y, yd)
        res, tol = _residual(out)
        assert np.abs(res).max() <= tol
        one = jd.joint_reactions(s, ["cardan", "plane"], y, yd)
        tol1 = subtree_tol(out, _ydd(out), tree_extent(s, y))
        for k, v in one.items():
            assert v == pytest.approx(out["g"][out["g_names"].index(k)], rel=0, abs=tol1), k


def test_joint_moved_by_another_joints_coordinate_is_rejected():
    """A screw turned by the angle of another joint couples the two joints: that coupling force
    is no single joint's reaction, so Q̄ cannot be complete; the error names the joint."""
    phi, g = jd.symbols("phi g")
    bodies = [jd.Body("disc", "world", jd.Revolute("hinge", phi, "z"), mass=1.0,
                      inertia=(0.1, 0.1, 0.2)),
              jd.Body("nut", "world", jd.General("screw", [jd.Trans("z", 0.01 * phi),
                                                           jd.Rot("z", phi)],
                                                 position=(1, 0, 0)), mass=0.5,
                      inertia=(0.01, 0.01, 0.02))]
    s = jd.System([phi], bodies, [jd.Gravity((0, 0, -g))], parameters={"g": 9.81})
    with pytest.raises(jd.ModelError, match=r'"screw" \(moves in 1 directions, drives 0'):
        s.reactions()
    out = s.evaluate([0.3], [1.0])  # the equations of motion are still there, g is not
    assert "M" in out and "g" not in out and '"screw"' in out["reactions_error"]


def test_general_joint_derives_the_revolute_directions(rng):
    """A general joint Rot('z', q) gets the directions of a revolute joint, and the same g."""
    s = double_pendulum()
    phi1, phi2 = s.coordinates
    bodies = [jd.Body(b.name, b.parent, jd.General(b.joint.name, list(b.joint.steps),
                                                   coordinates=b.joint.coordinates,
                                                   position=b.joint.position),
                      mass=b.mass, com=b.com, inertia=b.inertia) for b in s.bodies]
    s2 = jd.System(s.coordinates, bodies, s.forces, parameters=dict(s.parameters))
    assert s2.reactions().g_names == s.reactions().g_names
    y, yd = rng.uniform(-2, 2, 2), rng.uniform(-2, 2, 2)
    out = s.evaluate(y, yd)  # two solves, one on each side
    np.testing.assert_allclose(s2.evaluate(y, yd)["g"], out["g"], rtol=0,
                               atol=2 * reactions_tol(out))


def test_symbolic_single_joint_matches_numbers(rng):
    """``Reactions.joint_g`` (in y, ẏ, ÿ) with ÿ from the equations of motion equals g."""
    s = double_pendulum()
    r = s.reactions()
    expr = r.joint_g("hinge1")
    y, yd = rng.uniform(-2, 2, 2), rng.uniform(-2, 2, 2)
    out = s.evaluate(y, yd)
    ydd = _ydd(out)
    vals = {**dict(zip(s.y, y, strict=True)), **dict(zip(s.yd, yd, strict=True)),
            **dict(zip(s.ydd, ydd, strict=True)),
            **{jd.symbols(k): v for k, v in s.parameter_values.items()}}
    got = np.array(graph_values(expr.entries(), vals), dtype=float)
    cols = list(r.joint("hinge1").columns)
    np.testing.assert_allclose(got, out["g"][cols], rtol=0,
                               atol=subtree_tol(out, ydd, tree_extent(s, y)))


def test_user_directions_violating_orthogonality_are_rejected():
    phi = jd.symbols("phi")
    bad = jd.General("hinge", [jd.Rot("z", phi)], coordinates=[phi],
                     constrained=["F_x", "F_y", "F_z", "T_x", ("T_tilt", (0, 0, 0, 0, 0.6, 0.8))])
    s = jd.System([phi], [jd.Body("b", "world", bad, mass=1, com=(0, -1, 0),
                                  inertia=(0.1, 0.1, 0.1))], [])
    with pytest.raises(jd.ModelError, match=r'joint "hinge".*"hinge.T_tilt".*J̄ᵀ·Q̄ = 0'):
        s.reactions()
    good = jd.General("hinge", [jd.Rot("z", phi)], coordinates=[phi],
                      constrained=["F_x", "F_y", "F_z", "T_x", ("T_w", (0, 0, 0, 0, 1, 0))])
    s = jd.System([phi], [jd.Body("b", "world", good, mass=1, com=(0, -1, 0),
                                  inertia=(0.1, 0.1, 0.1))], [])
    assert s.reactions().g_names[-1] == "hinge.T_w"


def test_bad_user_directions_are_reported():
    phi = jd.symbols("phi")
    for constrained, msg in [(["F_q"], "not one of"), ([("T", (0, 0, 0))], "6-vector"),
                             ([("T", (0, 0, 0, 0, 0, 0))], "is zero"),
                             (["F_x", "F_x"], "given twice")]:
        j = jd.General("pin", [jd.Rot("z", phi)], coordinates=[phi], constrained=constrained)
        s = jd.System([phi], [jd.Body("b", "world", j, mass=1, inertia=(1, 1, 1))], [])
        with pytest.raises(jd.ModelError, match=f'joint "pin".*{msg}'):
            s.reactions()


def test_redundant_directions_are_undetermined():
    """Two constrained directions along the same axis share one force: a statically
    indeterminate joint; both are reported as undetermined, the others as numbers."""
    phi = jd.symbols("phi")
    j = jd.General("hinge", [jd.Rot("z", phi)], coordinates=[phi],
                   constrained=["F_x", "F_y", "F_z", "T_x", "T_y", ("F_x2", (1, 0, 0, 0, 0, 0))])
    g = jd.symbols("g")
    s = jd.System([phi], [jd.Body("b", "world", j, mass=2.0, com=(0, -1, 0),
                                  inertia=(0.1, 0.1, 0.1))], [jd.Gravity((0, -g, 0))],
                  parameters={"g": 9.81})
    out = s.evaluate([0.0], [1.0])
    assert sorted(out["g_undetermined"]) == ["hinge.F_x", "hinge.F_x2"]
    g_ = dict(zip(out["g_names"], out["g"], strict=True))
    assert np.isnan(g_["hinge.F_x"]) and np.isnan(g_["hinge.F_x2"])
    tol = reactions_tol(out)  # minimum-norm solve: condition number over its rank
    assert g_["hinge.F_y"] == pytest.approx(2.0 * 1.0 + 2.0 * 9.81, rel=0, abs=tol)
    with pytest.raises(jd.JourdainError, match="undetermined"):
        s.reactions().g()
    one = jd.joint_reactions(s, "hinge", [0.0], [1.0])
    assert np.isnan(one["hinge.F_x"]) and np.isnan(one["hinge.F_x2"])
    assert one["hinge.F_y"] == pytest.approx(g_["hinge.F_y"], rel=0,
                                             abs=subtree_tol(out, _ydd(out), tree_extent(s, [0.0])))


def test_unknown_joint_is_named():
    s = double_pendulum()
    with pytest.raises(jd.ModelError, match='unknown joint "hinge9"'):
        jd.joint_reactions(s, "hinge9", [0, 0], [0, 0])
    with pytest.raises(jd.ModelError, match='unknown joint "hinge9"'):
        s.reactions().joint("hinge9")


@pytest.mark.parametrize("make", [lambda: spatial_chain(6), lambda: n_link_pendulum_on_cart(4),
                                  _zoo], ids=["spatial_chain-6", "cart-pendulum-4", "zoo"])
def test_assembled_orthogonality(make):
    """J̄ᵀ·Q̄ = 0 for the assembled matrices (not only joint by joint)."""
    r = make().reactions()
    # relative to |J̄|ᵀ|Q̄|: the rounding of a sum of 6p products
    assert check_orthogonality(r, samples=4) <= eval_tol(r.Q_bar.shape[0], 1.0)


def test_assembly_error_is_caught_by_orthogonality():
    """A Q̄ with a wrong lever arm on the parent (a column of the second hinge without its
    moment on the first rod) breaks J̄ᵀ·Q̄ = 0, and the error names the joint."""
    import dataclasses

    r = double_pendulum().reactions()
    c = r.g_names.index("hinge2.F_x")
    rows = [list(row) for row in r.Q_bar.rows]
    p = len(r.system.bodies)
    for a in range(3):
        rows[3 * p + a][c] = se.Integer(0)  # rotational rows of rod1 (the parent)
    bad = dataclasses.replace(r, Q_bar=jd.SymMatrix.from_rows(rows))
    with pytest.raises(jd.ModelError, match=r'joint "hinge2".*"hinge2.F_x".*J̄ᵀ·Q̄ = 0'):
        check_orthogonality(bad)


def test_heavy_top_axial_pivot_force_closed_form(rng):
    """Heavy top (Euler angles z-x-z): along the symmetry axis the pivot pushes with
    m·(g·cos θ − L·(θ̇² + ψ̇²·sin²θ)) (gravity's axial part minus the centripetal force of the
    centre of mass on its sphere of radius L, |ω × e_z|² = θ̇² + ψ̇² sin²θ)."""
    from jourdain.models import heavy_top

    s = heavy_top()
    r = s.reactions()
    assert r.g_names == ("pivot.F_x", "pivot.F_y", "pivot.F_z")
    G = r.g(simplify=False)
    psi, theta, phi, psi_d, theta_d, phi_d = sympy.symbols("psi theta phi psi_d theta_d phi_d")
    m, L, A, C, g = sympy.symbols("m L A C g")
    args = (psi, theta, phi, psi_d, theta_d, phi_d, m, L, A, C, g)
    Fz = sympy.lambdify(args, G[2], "numpy")
    for _ in range(5):
        x = np.concatenate([rng.uniform(-3, 3, 6), rng.uniform(0.5, 2.0, 5)])
        th, thd, psd = x[1], x[4], x[3]
        want = x[6] * (x[10] * np.cos(th) - x[7] * (thd**2 + psd**2 * np.sin(th) ** 2))
        assert Fz(*x) == pytest.approx(want, rel=1e-12)
    # and the numeric path (Cholesky of N̂) gives the same numbers
    y, yd = rng.uniform(-3, 3, 3), rng.uniform(-3, 3, 3)
    p = s.parameter_values
    out = s.evaluate(y, yd)
    closed = sympy.lambdify(args, G, "numpy")(*y, *yd, p["m"], p["L"], p["A"], p["C"], p["g"])
    np.testing.assert_allclose(out["g"], np.asarray(closed, float).ravel(), rtol=0,
                               atol=reactions_tol(out))


def test_benchmark_script_tiny_case():
    """benchmarks/reactions.py on a 3-body chain: runs, and agrees with Pinocchio."""
    pytest.importorskip("pinocchio")
    from benchmarks import reactions as bench

    (row,) = bench.run([3], states=5, repeat=1)
    # the benchmark's five fixed states are well-conditioned (cond(M) < 300, cond(N̂) < 900):
    # a fixed bound, about 700 times the difference measured there
    assert row["q"] == 12 and row["max_rel_diff"] < 1e-12
    assert row["jourdain_g"] > 0 and row["pinocchio"] > 0


def test_unbalanced_load_on_a_point_mass_has_no_reactions():
    """A torque about the hinge axis on a point mass sitting on the axis: nothing can balance it
    (0 = l_z), so there are no reaction forces; evaluate says so instead of giving numbers."""
    phi, m = jd.symbols("phi m")
    body = jd.Body("bead", "world", jd.Revolute("hinge", phi, "z"), mass=m,
                   inertia=jd.point_mass())
    s = jd.System([phi], [body], [jd.Torque("drive", "bead", (0, 0, 1.5))], parameters={"m": 1.0})
    with pytest.raises(jd.EvaluationError, match="no solution"):
        jd.evaluate_reactions(s, [0.1], [0.0])
    out = s.evaluate([0.1], [0.0])
    assert "g" not in out and "no solution" in out["reactions_error"]
