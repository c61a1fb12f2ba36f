"""Bricard's orthogonal 6R linkage, the overconstrained mechanism of the IFToMM multibody
benchmark A04 (M. González, D. Dopico, U. Lugrís, J. Cuadrado, "A benchmarking system for MBS
simulation software", Multibody Syst. Dyn. 16 (2006) 179–190; geometry as in the library's
A04 specification and its public re-implementations): six equal links of length L on six
revolute joints, every joint axis perpendicular to both links it joins, so the twist between
consecutive axes is ±90° and the offsets are zero. At rest in the benchmark's initial
configuration the joints sit on the corners of a unit cube, (0,0,0) → (L,0,0) → (L,−L,0) →
(L,−L,L) → (0,−L,L) → (0,0,L) → back, the last link (from (0,0,L) to the origin) fixed; gravity
along −y. Grübler–Kutzbach: 6·5 − 6·5 = 0 degrees of freedom; the linkage moves with one.

jourdain's tree: links 1..5 hinged in a row, coordinates q1..q5 measured from the cube
configuration; one revolute closing joint J6 between link 5's end and the ground at (0,0,L).

Closed-form reference (the motion through the cube configuration is Bricard's
threefold-symmetric one, opposite joints turning alike: Bricard, Leçons de cinématique II (1927);
Chen & You, Motion Structures (2011), ch. 6, the threefold-symmetric Bricard linkage). In
Denavit–Hartenberg form, ``T_i = Rz(θ_i)·Tx(L)·Rx(α_i)`` with α alternating ±90°; with
θ1 = θ3 = θ5 = a and θ2 = θ4 = θ6 = b the loop closes iff ``(T(a, +90°)·T(b, −90°))³ = I``. The
rotation of that pair is ``Rz(a)·Rx(90°)·Rz(b)·Rx(−90°) = Rz(a)·Ry(−b)``, whose cube is the
identity (and it is not) only as a rotation by 120°: trace ``cos a·cos b + cos a + cos b = 0``.
The tree's coordinates are ``q_i = 90° − θ_i``, hence

    q3 = q5 = q1,   q4 = q2,   sin q1 + sin q2 + sin q1·sin q2 = 0  ⇔  (1 + sin q1)(1 + sin q2) = 1.

(Derived here; the cited sources state the symmetric motion but the formula itself was not
found in a retrievable public text. test_closed_form_closes_the_loop verifies it by the loop's
own kinematics in NumPy, without jourdain.)
"""

import numpy as np

from tests.tolerance import EPS

P = {"L": 1.0, "m": 1.0, "g": 9.81}
#: (parent, joint axis, joint point in the parent's frame / L, the link from its joint / L)
LINKS = [("world", "y", (0, 0, 0), (1, 0, 0)),
         ("link1", "z", (1, 0, 0), (0, -1, 0)),
         ("link2", "x", (0, -1, 0), (0, 0, 1)),
         ("link3", "y", (0, 0, 1), (-1, 0, 0)),
         ("link4", "z", (-1, 0, 0), (0, 1, 0))]
#: jourdain's Newton stop on the rows it solves (jourdain.loops, unit-free since 97c48d3):
#: |Φ_i| ≤ NEWTON_TOL·w_i, w_i = Σ_j |∂Φ_i/∂z_j|·|z_j|, or a rounding plateau
NEWTON_TOL = 1e-13


def newton_bound(api, z, n_rows):
    """What Newton's stop leaves in |Φ| at each state ``z``: NEWTON_TOL·(max_i w_i + 1), the
    1 covering its rounding-plateau exit (terms counted at least one unit: L = 1 here), times
    the rows, as an overconstrained loop's redundant row, which Newton does not solve, is a
    combination of the others."""
    w = np.array([(np.abs(api["constraints"](zi)[1]) @ np.abs(zi)).max() for zi in z])
    return n_rows * NEWTON_TOL * (w + 1)


def bricard_tree():
    """The open tree of uniform slender rods (mass m, length L) under gravity along −y."""
    import jourdain as jd

    q = jd.symbols("q1:6")
    L, m, g = jd.symbols("L m g")
    bodies = []
    for i, (parent, axis, pos, along) in enumerate(LINKS):
        rod_axis = "xyz"[int(np.flatnonzero(along)[0])]
        bodies.append(jd.Body(f"link{i + 1}", parent,
                              jd.Revolute(f"J{i + 1}", q[i], axis,
                                          position=tuple(L * c for c in pos)),
                              mass=m, com=tuple(L * c / 2 for c in along),
                              inertia=jd.rod(m, L, rod_axis)))
    return jd.System(list(q), bodies, [jd.Gravity((0, -g, 0))], parameters=P, name="Bricard")


# --- jourdain's closed-system API (the only place in this file that names it) -----------------
def _loop_api(independent=("q1",)):
    """The tree closed by the revolute joint J6 (link 5's end on the ground point (0, 0, L),
    axis x in both), and the numbers used below."""
    import jourdain as jd
    from jourdain.loops import LoopEvaluator
    from jourdain.loops.closed_loop import constraint_function
    from jourdain.numeric import parameter_vector

    L = jd.symbols("L")
    J6 = jd.ClosingJoint("J6", "revolute", "link5", "world", point_a=(0, L, 0),
                         point_b=(0, 0, L), axis="x")
    system = bricard_tree().closed_by([J6], independent=independent)
    con, p = constraint_function(system), parameter_vector(system.tree, None)

    def constraints(z):
        out = con.split(con.raw(np.ascontiguousarray(z, dtype=float), np.zeros(system.f), 0.0,
                                p, np.zeros(0)))
        return out["Phi"][:, 0], out["Phi_z"]

    def rank(z):  # jourdain's rank of Φ_y (the one `jourdain check` reports)
        return LoopEvaluator(system, z).rank(z)

    def simulate(z0, zd0, t_end, rtol, samples):
        r = system.simulate((0.0, t_end), z0, zd0, rtol=rtol, atol=rtol * 1e-2,
                            t_eval=np.linspace(0.0, t_end, samples))
        return {"status": r.status, "t": r.t, "z": r.y, "zd": r.yd, "Phi": r.Phi,
                "partitions": r.constraints.partitions}

    return {"n": system.f, "grubler": system.grubler(), "constraints": constraints,
            "rank": rank, "simulate": simulate}


# --- the loop's kinematics and energy in NumPy (independent of jourdain) ---------------------
def _rotation(axis, angle):
    k = np.eye(3)["xyz".index(axis)]
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def chain(z, zd):
    """Link 5's end point and x axis (inertial), and the kinetic and potential energy."""
    L, m, g = P["L"], P["m"], P["g"]
    R, o, w, v = np.eye(3), np.zeros(3), np.zeros(3), np.zeros(3)
    frames = {"world": (R, o, w, v)}
    T = V = 0.0
    for i, (parent, axis, pos, along) in enumerate(LINKS):
        Rp, op, wp, vp = frames[parent]
        o = op + Rp @ (L * np.array(pos, dtype=float))
        v = vp + np.cross(wp, o - op)
        R = Rp @ _rotation(axis, z[i])
        w = wp + R @ np.eye(3)["xyz".index(axis)] * zd[i]
        frames[f"link{i + 1}"] = (R, o, w, v)
        c = R @ (L * np.array(along, dtype=float) / 2)
        vc = v + np.cross(w, c)
        wb = R.T @ w  # slender rod: m·L²/12 about the two axes across it
        across = np.ones(3) - np.abs(np.array(along, dtype=float))
        T += 0.5 * m * vc @ vc + 0.5 * m * L ** 2 / 12 * (across * wb) @ wb
        V += m * g * (o + c)[1]
    R5, o5, _, _ = frames["link5"]
    return o5 + R5 @ np.array([0.0, L, 0.0]), R5[:, 0], T, V


def closed_form_q2(q1):
    """q2 of the threefold-symmetric motion: (1 + sin q1)(1 + sin q2) = 1, the branch through
    the cube configuration (|q2| ≤ 90°)."""
    return np.arcsin(1.0 / (1.0 + np.sin(q1)) - 1.0)


def assert_on_closed_form(api, z, Phi):
    """The states ``z`` (with their residuals ``Phi``) lie on the closed form: a configuration
    is at most about ‖Φ_z⁺‖·|Φ| from the exact manifold (first order; 10 times that allowed),
    so q3 − q1, q5 − q1, q4 − q2 are within that distance and the relation
    (1 + sin q1)(1 + sin q2) − 1, whose gradient is at most 4 in size, within 4 times it."""
    dist = 10 * max(np.linalg.norm(np.linalg.pinv(api["constraints"](zi)[1], rcond=1e-8), 2)
                    for zi in z) * max(np.abs(Phi).max(), EPS)
    assert np.abs(z[:, 2] - z[:, 0]).max() <= dist
    assert np.abs(z[:, 4] - z[:, 0]).max() <= dist
    assert np.abs(z[:, 3] - z[:, 1]).max() <= dist
    relation = (1 + np.sin(z[:, 0])) * (1 + np.sin(z[:, 1])) - 1
    assert np.abs(relation).max() <= 4 * dist + 10 * EPS, np.abs(relation).max()


def test_closed_form_closes_the_loop():
    """The reference itself, checked without jourdain: along the symmetric motion from the
    closed form (q1 over its whole range, sin q1 ≥ −1/2) link 5's end lands on the ground
    point (0, 0, L) with its x axis along the ground's, to the rounding of 5 rotations."""
    for q1 in np.linspace(-np.pi / 6 + 1e-3, 7 * np.pi / 6 - 1e-3, 13):
        q2 = closed_form_q2(q1)
        end, axis, _, _ = chain(np.array([q1, q2, q1, q2, q1]), np.zeros(5))
        assert np.abs(end - [0, 0, P["L"]]).max() <= 100 * EPS * P["L"], (q1, end)
        assert np.abs(axis - [1, 0, 0]).max() <= 100 * EPS, (q1, axis)


def test_grubler_zero_but_mobility_one():
    """Grübler's count is 0, yet Φ_z (5 rows of the closing revolute joint, 5 coordinates) has
    rank 4 at the assembled cube configuration and at configurations of the closed form: one
    degree of freedom, one constraint row redundant."""
    api = _loop_api()
    assert api["grubler"] == 0
    assert api["n"] == 5
    for q1 in (0.0, 0.4, 1.5, 3.0):
        q2 = closed_form_q2(q1)
        z = np.array([q1, q2, q1, q2, q1])
        Phi, Phi_z = api["constraints"](z)
        assert np.abs(Phi).max() <= 100 * EPS
        assert api["rank"](z) == 4, q1
        assert np.linalg.matrix_rank(Phi_z) == 4


def test_motion_stays_on_the_manifold_and_follows_the_closed_form():
    """From the cube configuration with q̇1 = 3 rad/s under gravity, 3 s on the manifold
    (q1 independent; the partition changes once where q1 stops being a good choice).

    * |Φ|: within what Newton's stop leaves (:func:`newton_bound`; measured 3.1e-13, 0.975 of
      NEWTON_TOL·w_i on its row; 4.0e-13, on the redundant row, with the former absolute stop
      1e-13·(1 + max|z|)).
    * The closed form (:func:`assert_on_closed_form`): bounded by the distance from the
      manifold, ‖Φ_z⁺‖·|Φ|, whatever the integration error (which moves the state along the
      manifold, not off it).
    * Energy, computed in NumPy from the states (not jourdain's T and V), is conserved to the
      integration: at most 10·rtol of the largest kinetic energy (measured 0.28·rtol at rtol
      1e-10 and 0.6·rtol at 1e-12; 1.4·rtol at 1e-10 in a variant whose rounding kept q1
      independent throughout).
    """
    api = _loop_api()
    rtol = 1e-10
    r = api["simulate"](np.zeros(5), np.array([3.0, 0, 0, 0, 0]), 3.0, rtol, 301)
    assert r["status"] == "finished"
    z, zd, Phi = r["z"], r["zd"], r["Phi"]
    # q1 swings from near its lower limit −30° (sin q1 ≥ −1/2) to beyond 180°
    assert z[:, 0].max() > 3.5 and z[:, 0].min() < -0.5
    assert np.all(np.abs(Phi) <= newton_bound(api, z, 5)[:, None]), np.abs(Phi).max()
    assert_on_closed_form(api, z, Phi)

    energies = np.array([chain(a, b)[2:] for a, b in zip(z, zd, strict=True)])
    E = energies.sum(axis=1)
    assert np.abs(E - E[0]).max() <= 10 * rtol * energies[:, 0].max(), np.abs(E - E[0]).max()


def test_automatic_partition_from_rest():
    """Released at rest in the cube configuration with the partition left to jourdain (it
    picks the independent coordinate by pivoting), the linkage falls along the same
    closed-form motion, on the manifold by the same rules."""
    api = _loop_api(independent=None)
    r = api["simulate"](np.zeros(5), np.zeros(5), 1.0, 1e-10, 101)
    assert r["status"] == "finished"
    z, Phi = r["z"], r["Phi"]
    assert np.abs(z[-1]).max() > 0.1  # it moved
    assert np.all(np.abs(Phi) <= newton_bound(api, z, 5)[:, None]), np.abs(Phi).max()
    assert_on_closed_form(api, z, Phi)
