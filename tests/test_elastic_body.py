"""Elastic bodies in the method (jourdain.elastic.body): the nodal floating frame of reference,
checked against values computed outside it — the invariants of the modal data (another route
to the same integrals), the cantilever's βL roots and the frequency equation with a tip mass,
energy conservation, and the Kane–Ryan–Banerjee spin-up (bounded with geometric stiffening,
diverging without).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.optimize as so
import symengine as se

import jourdain as jd
from jourdain.analysis.floquet import FLOQUET_RTOL
from jourdain.elastic import Beam, assemble, modal_data
from jourdain.elastic.body import ElasticBody, lumped_masses
from jourdain.errors import ModelError
from jourdain.graph.piecewise import diff as pw_diff
from jourdain.models.elastic import spinning_beam

L, E, RHO, A, I = 1.0, 2.1e11, 7850.0, 1e-4, 8.33e-10
BETA_L = np.array([1.875104068711961, 4.694091132974175, 7.854757438237613])


def _skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def _cantilever(n_el: int, n_modes: int, tip_mass: float = 0.0) -> jd.System:
    beam = Beam(length=L, E=E, rho=RHO, A=A, I_y=I, I_z=I, J=2 * I, nu=0.3, n_elements=n_el)
    eb = ElasticBody.beam("b", "world", jd.Fixed("wall"), beam, n_modes, keep=("uy", "rz"),
                          attach={"tip": n_el})
    bodies: list[object] = [eb]
    if tip_mass:
        bodies.append(jd.Body("m", "b_tip", jd.Fixed("glue"), mass=tip_mass, inertia=[0, 0, 0]))
    return jd.System([], bodies, [])


def _frequencies(system: jd.System) -> np.ndarray:
    lin = system.linearize({c: 0 for c in system.coordinate_names})
    m = jd.modes(lin)
    return np.sort(m.natural_frequencies[m.oscillating()])


def test_projected_mass_is_the_modal_invariants() -> None:
    """M = J̄ᵀM̄J̄ of the expanded body on a free joint, at q_e = 0, equals the SID block
    [[m·E, m·c̃ᵀ, C_t], [m·c̃, J, C_r], [C_tᵀ, C_rᵀ, M_e]] that modal_data forms from the
    lumped mass matrix (projections of M on the rigid-body fields): a skewed 3-D beam with
    all six DOFs per node."""
    beam = Beam(length=2.0, E=2e11, rho=7800.0, A=1e-3, I_y=2e-7, I_z=1e-7, J=3e-7, nu=0.3,
                n_elements=6, axis=(1.0, 0.5, 0.2), origin=(0.1, 0.2, 0.3))
    eb = ElasticBody.beam("arm", "world", jd.Free("base", ["x", "y", "z", "a", "b", "c"]),
                          beam, 4)
    system = jd.System(["x", "y", "z", "a", "b", "c"], [eb], [])
    assert system.coordinate_names[6:] == ["arm_q1", "arm_q2", "arm_q3", "arm_q4"]
    assert system.groups == (eb,)
    M = system.evaluate(np.zeros(10), np.zeros(10))["M"]
    fe = assemble(beam)
    m_node = lumped_masses(fe)
    assert m_node.sum() == pytest.approx(7800.0 * 1e-3 * 2.0, rel=1e-14)
    M_lumped = np.diag([m_node[n] if d in ("ux", "uy", "uz") else 0.0 for n, d in fe.dofs])
    md = modal_data(replace(fe, M=M_lumped), eb.modal.Phi, "lumped", ())
    ref = np.block([[md.mass * np.eye(3), _skew(md.mc).T, md.C_t],
                    [_skew(md.mc), md.J, md.C_r],
                    [md.C_t.T, md.C_r.T, md.M_e]])
    scale = np.abs(ref).max()
    assert np.abs(M - ref).max() <= 100 * np.finfo(float).eps * scale


def test_consistent_mass_points_carry_the_fe_invariants() -> None:
    """mass="consistent": the bodies at the elements' Gauss points give, at q_e = 0, the SID
    block that modal_data forms from the *consistent* FE mass matrix (with the sections'
    torsional and rotary inertia), to round-off: the 4-point rule integrates the element's
    mass exactly; Timoshenko elements (shear) on the same skewed 3-D beam, free joint."""
    beam = Beam(length=2.0, E=2e11, rho=7800.0, A=1e-3, I_y=2e-7, I_z=1e-7, J=3e-7, nu=0.3,
                kappa=0.9, n_elements=5, axis=(1.0, 0.5, 0.2), origin=(0.1, 0.2, 0.3))
    eb = ElasticBody.beam("arm", "world", jd.Free("base", ["x", "y", "z", "a", "b", "c"]),
                          beam, 4, mass="consistent")
    system = jd.System(["x", "y", "z", "a", "b", "c"], [eb], [])
    assert np.all(eb.node_mass == 0) and len(eb.points.mass) == 20
    M = system.evaluate(np.zeros(10), np.zeros(10))["M"]
    md = modal_data(assemble(beam), eb.modal.Phi, "consistent", ())
    ref = np.block([[md.mass * np.eye(3), _skew(md.mc).T, md.C_t],
                    [_skew(md.mc), md.J, md.C_r],
                    [md.C_t.T, md.C_r.T, md.M_e]])
    assert np.abs(M - ref).max() <= 100 * np.finfo(float).eps * np.abs(ref).max()
    assert np.allclose(md.M_e, np.eye(4), rtol=0, atol=1e-12)  # the modes are M-normal


def test_consistent_mass_converges_at_the_element_rate() -> None:
    """The cantilever's βL roots with the consistent mass: Hermite elements converge like h⁴
    from above (the error falls by 16 per halving), far below the lumped h²."""
    w0 = BETA_L**2 * np.sqrt(E * I / (RHO * A * L**4))
    errors = []
    for n in (3, 6, 12):
        beam = Beam(length=L, E=E, rho=RHO, A=A, I_y=I, I_z=I, J=2 * I, nu=0.3, n_elements=n,
                    rotary_inertia=False)  # the Euler–Bernoulli beam of the roots
        eb = ElasticBody.beam("b", "world", jd.Fixed("wall"), beam, 3, keep=("uy", "rz"),
                              mass="consistent")
        errors.append((_frequencies(jd.System([], [eb], []))[:3] - w0) / w0)
    assert np.all(np.array(errors) > 0)
    order = np.log2(errors[1] / errors[2])
    assert np.all((order > 3.8) & (order < 4.3)), order
    assert errors[2][0] < 1e-6


def test_cantilever_frequencies_converge_at_the_lumped_rate() -> None:
    """Bending frequencies of the clamped beam (the body on a fixed joint, linearized) against
    β_nL = 1.875104, 4.694091, 7.854757: lumped masses converge like h² (the error falls by
    4 per halving of the elements), from below."""
    w0 = BETA_L**2 * np.sqrt(E * I / (RHO * A * L**4))
    errors = [(_frequencies(_cantilever(n, 3))[:3] - w0) / w0 for n in (10, 20, 40)]
    for e in errors:
        assert np.all(e < 0)
    order = np.log2(np.abs(errors[1]) / np.abs(errors[2]))
    assert np.all((order > 1.9) & (order < 2.1)), order
    assert np.abs(errors[2][0]) < 5e-4


def test_tip_mass_at_an_attachment_frame() -> None:
    """A point mass hung from the tip's attachment frame: the first frequency against the root
    of 1 + cos x·cosh x + μ·x·(cos x·sinh x − sin x·cosh x) = 0 (μ = m_tip/(ρAL) = 0.5),
    within the h² lumping error at 80 elements (≈ 7e-5 from the test above's rate)."""
    mu = 0.5

    def f(x: float) -> float:
        return (1 + np.cos(x) * np.cosh(x)
                + mu * x * (np.cos(x) * np.sinh(x) - np.sin(x) * np.cosh(x)))

    x1 = so.brentq(f, 0.5, BETA_L[0])
    w_ref = x1**2 * np.sqrt(E * I / (RHO * A * L**4))
    w = _frequencies(_cantilever(80, 6, tip_mass=mu * RHO * A * L))[0]
    assert abs(w - w_ref) / w_ref < 2e-4


def test_flexible_pendulum_conserves_energy() -> None:
    """An undamped beam pendulum in gravity (axial and in-plane bending modes, geometric
    stiffening on): the elastic forces have the potential ½·q_eᵀ·K_e·q_e, so the energy is
    conserved to the integrator's tolerance."""
    beam = Beam(length=1.0, E=7e10, rho=2700.0, A=1e-4, I_y=1e-10, I_z=8.33e-11, J=1e-10,
                nu=0.3, n_elements=8)
    eb = ElasticBody.beam("arm", "world", jd.Revolute("pivot", "phi", "z"), beam, 3,
                          keep=("ux", "uy", "rz"))
    system = jd.System(["phi"], [eb], [jd.Gravity((0, -9.81, 0))])
    rtol = 1e-10
    r = system.simulate(t_span=(0, 2), y0=[0.5, 0, 0, 0], yd0=[0, 0, 0, 0], rtol=rtol,
                        atol=1e-12)
    assert r.conservative
    E_tot = np.asarray(r.total_energy)
    scale = np.abs(np.asarray(r.kinetic_energy)).max() + np.abs(E_tot).max()
    assert np.abs(E_tot - E_tot[0]).max() <= 10 * rtol * scale
    # it did bend: the modes moved
    assert np.abs(np.asarray(r.y)[:, 1:]).max() > 1e-7


def _spin_up(stiffening: bool, n_el: int = 10, n_modes: int = 3
             ) -> tuple[ElasticBody, jd.System]:
    """Kane, Ryan & Banerjee (1987): L = 10 m, ρA = 1.2 kg/m, EI = 1.4e4 N·m², spun up to
    Ω_s = 6 rad/s over T_s = 15 s by a prescribed hub angle
    (:func:`jourdain.models.elastic.spinning_beam`)."""
    system = spinning_beam(n_el, n_modes, stiffening)
    return system.groups[0], system


def test_spin_up_bounded_only_with_geometric_stiffening() -> None:
    """The hub outruns the first bending frequency (3.8 rad/s < 6 rad/s): with the
    foreshortening the tip deflection stays below 1 m; the linear modal beam diverges."""
    for stiffening in (True, False):
        eb, system = _spin_up(stiffening)
        r = system.simulate(t_span=(0, 20), y0=[0, 0, 0], yd0=[0, 0, 0], rtol=1e-8)
        tip = np.asarray(r.y) @ eb.modal.Phi_t[-1, 1, :]
        if stiffening:
            assert np.abs(tip).max() < 1.0
            assert np.abs(tip).max() > 0.1  # it did bend back under the spin-up
        else:
            assert np.abs(tip).max() > 100.0


def test_piecewise_time_derivatives() -> None:
    """∂/∂t of max/min/abs on either side of their switching points, against the branch's
    own derivative (a prescribed motion such as Ω·max(t − T, 0))."""
    t = se.Symbol("t")
    e = se.Min(t, 15) ** 2 + 6 * se.Max(t - 15, 0) + se.Abs(se.sin(t))
    d = pw_diff(e, t)
    for tv, ref in ((3.0, 6.0 + np.cos(3.0) * np.sign(np.sin(3.0))),
                    (16.0, 6.0 + np.cos(16.0) * np.sign(np.sin(16.0)))):
        assert float(d.subs({t: tv})) == pytest.approx(ref, rel=1e-14)
    assert "Derivative" not in str(pw_diff(pw_diff(e, t), t))


def test_bad_elastic_body_input_is_named() -> None:
    beam = Beam(length=1.0, E=E, rho=RHO, A=A, I_y=I, I_z=I, J=2 * I, nu=0.3, n_elements=4)
    with pytest.raises(ModelError, match='"b": attachment "tip" at node 9'):
        ElasticBody.beam("b", "world", jd.Fixed("wall"), beam, 2, attach={"tip": 9})
    with pytest.raises(ModelError, match=r"unknown DOF names \['uq'\]"):
        ElasticBody.beam("b", "world", jd.Fixed("wall"), beam, 2, keep=("uy", "uq"))
    eb = ElasticBody.beam("b", "world", jd.Fixed("wall"), beam, 2)
    with pytest.raises(ModelError, match="node_mass must be 5"):
        ElasticBody("b", "world", jd.Fixed("wall"), eb.modal, np.ones(3))
    with pytest.raises(ModelError, match='"b": mass must be "lumped" or "consistent"'):
        ElasticBody.beam("b", "world", jd.Fixed("wall"), beam, 2, mass="diagonal")
    pts = ElasticBody.beam("b", "world", jd.Fixed("wall"), beam, 2, mass="consistent").points
    with pytest.raises(ModelError, match="mass points' Phi_t must be finite, of shape"):
        ElasticBody("b", "world", jd.Fixed("wall"), eb.modal, np.zeros(5),
                    points=replace(pts, Phi_t=pts.Phi_t[:, :, :1]))
    # sections without spin are taken; with spin each must be axisymmetric about its axis
    ElasticBody("b", "world", jd.Fixed("wall"), eb.modal, eb.node_mass,
                node_inertia=np.zeros((5, 3, 3)))
    with pytest.raises(ModelError, match="mass point 0's inertia is not axisymmetric"):
        ElasticBody("b", "world", jd.Fixed("wall"), eb.modal, np.zeros(5), points=pts,
                    spin=((0.0, 1.0, 0.0), se.Symbol("t")))


def test_model_file_elastic_body_equals_the_python_one() -> None:
    """examples/spinning_beam.toml builds the same system as the Python API: equal M, k, q at
    a state, and the file's settings count the elastic coordinates."""
    from pathlib import Path

    model = jd.load_model(Path(__file__).parent.parent / "examples" / "spinning_beam.toml")
    _, ref = _spin_up(True)
    assert model.system.coordinate_names == ref.coordinate_names
    assert len(model.simulation.y0) == 3
    y, yd = np.array([0.01, -0.002, 0.001]), np.array([0.1, 0.0, -0.05])
    a, b = model.system.evaluate(y, yd, t=3.0), ref.evaluate(y, yd, t=3.0)
    for key in ("M", "k", "q"):
        assert np.allclose(a[key], b[key], rtol=1e-13, atol=1e-13 * np.abs(b[key]).max())


def test_model_file_elastic_errors_name_the_line() -> None:
    text = """
[model]
name = "bad"
[bodies.arm]
parent = "world"
mass = 1.0
joint = { type = "revolute", coordinate = "phi", axis = "z" }
elastic = { modes = 2, beam = { length = 1.0, E = 7e10, rho = 2700.0, A = 1e-4, I_y = 1e-10, \
I_z = 1e-10, J = 1e-10, nu = 0.3 } }
[coordinates]
phi = "rad"
"""
    with pytest.raises(jd.ModelFileError, match=r"bad.toml:6: .*elastic: its mass comes from"):
        jd.io.modelfile.loads_model(text, "bad.toml")
    text = text.replace("mass = 1.0\n", "")
    with pytest.raises(jd.ModelFileError, match=r'bad.toml:7: .*expected "lumped" or '
                                                 r'"consistent", got \'diagonal\''):
        jd.io.modelfile.loads_model(text.replace("modes = 2,", 'modes = 2, mass = "diagonal",'),
                                    "bad.toml")
    consistent = jd.io.modelfile.loads_model(
        text.replace("modes = 2,", 'modes = 2, mass = "consistent",'), "bad.toml").system
    assert len(consistent.groups[0].points.mass) == 40  # 10 elements (the default), 4 points
    with pytest.raises(jd.ModelFileError, match=r'expected "normal" or "craig_bampton", '
                                                 r"got 'guyan'"):
        jd.io.modelfile.loads_model(text.replace("modes = 2,", 'modes = 2, reduction = "guyan",'),
                                    "bad.toml")
    cb = jd.io.modelfile.loads_model(text.replace(
        "modes = 2,", 'modes = 2, reduction = "craig_bampton", attach = { tip = 10 },'),
        "bad.toml").system.groups[0]
    assert cb.modal.kinds.count("constraint") == 6 and cb.modal.kinds.count("normal") == 2
    text = text.replace("E = 7e10", "E = -1")
    with pytest.raises(jd.ModelFileError, match=r"Beam: E must be a positive"):
        jd.io.modelfile.loads_model(text, "bad.toml")


def test_hinge_reaction_is_the_momentum_balance() -> None:
    """The hinge of a flexible pendulum (with a tip mass at its attachment frame) carries
    F = Σ m·(r̈_c − g): its reaction from System.evaluate (the sub-tree it carries) against the
    centre of mass's acceleration of the simulated motion (rtol 1e-12), by central differences
    of its interpolated positions with Richardson's step (h = 1e-4 and 5e-5 s; the plain
    differences converge like h²: 1.4e-4 at 3e-4 s, 1.6e-5 at 1e-4 s). The joints inside the
    body have no reactions of their own. Along the motion, Results.g and Results.joint_wrenches
    give the same numbers at the samples (jourdain.analysis.group_reactions)."""
    model = jd.load_model(Path(__file__).parent.parent / "examples" / "flexible_pendulum.toml")
    system = model.system
    r = system.simulate(t_span=(0, 0.6), y0=[0.8, 0, 0, 0], yd0=[0, 0, 0, 0], rtol=1e-12,
                        atol=1e-14)
    values = {se.Symbol(k): v for k, v in system.parameter_values.items()}
    masses = {b.name: float(b.mass.subs(values)) for b in system.bodies
              if float(b.mass.subs(values)) > 0}
    total = sum(masses.values())
    k = int(np.argmin(np.abs(r.t - 0.3)))  # a sample of the run
    t0 = float(r.t[k])

    def acc(h: float) -> np.ndarray:
        ts = np.array([t0 - h, t0, t0 + h])
        com = sum(m * r.positions(n, "com", t=ts) for n, m in masses.items()) / total
        return (com[0] - 2 * com[1] + com[2]) / h**2

    a = (4 * acc(5e-5) - acc(1e-4)) / 3  # Richardson: the h² terms cancel
    F_ref = total * (a - np.array([0.0, -9.81, 0.0]))
    state = r.interpolate([t0])
    ev = system.evaluate(state["y"][0], state["yd"][0], t=t0)
    assert "reactions_note" in ev
    g = dict(zip(ev["g_names"], ev["g"], strict=True))
    assert not any(name.startswith("arm_") for name in g)
    phi = state["y"][0][0]
    S = np.array([[np.cos(phi), -np.sin(phi), 0], [np.sin(phi), np.cos(phi), 0], [0, 0, 1]])
    F = S @ np.array([g["arm.F_x"], g["arm.F_y"], g["arm.F_z"]])  # the joint frame turns
    assert np.abs(F - F_ref).max() <= 1e-6 * np.abs(F_ref).max()
    assert np.abs(ev["joint_wrenches"]["arm"].force_inertial - F_ref).max() <= (
        1e-6 * np.abs(F_ref).max())
    # along the motion: the ordinary joints' g and wrenches at every sample
    assert r.g_names == ev["g_names"] and r.g.shape == (len(r.t), len(ev["g_names"]))
    scale = np.abs(ev["g"]).max()
    assert np.abs(r.g[k] - ev["g"]).max() <= 1e3 * np.finfo(float).eps * scale
    w = r.joint_wrenches
    assert set(w) == {"arm", "tip_mass"}  # the hinge and the tip mass's joint
    assert np.abs(w["arm"].force_inertial[k] - F_ref).max() <= 1e-6 * np.abs(F_ref).max()


def test_body_from_an_imported_fe_model() -> None:
    """The beam's matrices handed over as an imported FE model (SciPy sparse, with node
    coordinates) give the same body as the beam builder: equal M, k, q at a state."""
    import scipy.sparse as sp

    from jourdain.elastic import fe_model

    beam = Beam(length=1.0, E=E, rho=RHO, A=A, I_y=I, I_z=2 * I, J=2 * I, nu=0.3, n_elements=6)
    fe = assemble(beam)
    imported = fe_model(sp.csr_matrix(fe.M), sp.csr_matrix(fe.K), fe.nodes,
                        dofs_per_node=("ux", "uy", "uz", "rx", "ry", "rz"))
    joint = jd.Revolute("pivot", "phi", "z")
    a = ElasticBody.from_fe("b", "world", joint, imported, 4, attach={"tip": 6})
    b = ElasticBody.beam("b", "world", joint, beam, 4, attach={"tip": 6}, stiffening=False)
    y, yd = np.array([0.3, 1e-3, -2e-3, 5e-4, 1e-4]), np.array([0.5, 0.01, 0.0, -0.02, 0.0])
    ea = jd.System(["phi"], [a], [jd.Gravity((0, -9.81, 0))]).evaluate(y, yd)
    eb = jd.System(["phi"], [b], [jd.Gravity((0, -9.81, 0))]).evaluate(y, yd)
    # the sparse shift-invert Lanczos and LAPACK agree on the modes to about eps times the
    # spread of the clamped model's eigenvalues (measured here: 1e-12 … 7e-12 relative)
    free = [i for i, (node, _) in enumerate(fe.dofs) if node != 0]
    lam = sla.eigvalsh(fe.K[np.ix_(free, free)], fe.M[np.ix_(free, free)])
    tol = 10 * np.finfo(float).eps * lam.max() / lam.min()
    for key in ("M", "k", "q"):
        scale = np.abs(eb[key]).max()
        assert np.abs(ea[key] - eb[key]).max() <= tol * scale, key


def test_derivatives_of_a_system_with_an_elastic_body() -> None:
    """jd.derivatives (the forward-mode recursion: the nodes' joints are general) of the
    flexible pendulum against central differences of its own ÿ, within the differences'
    error estimated from two steps (Richardson: |D(h) − D(2h)|·4/3) plus their rounding."""
    model = jd.load_model(Path(__file__).parent.parent / "examples" / "flexible_pendulum.toml")
    d = jd.derivatives(model.system)
    y, yd = np.array([0.3, 1e-3, 2e-3, 0.0]), np.array([0.5, 0.01, 0.0, 0.0])
    fwd = d.forward(y, yd)

    def central(h: float) -> np.ndarray:
        cols = []
        for j in range(len(y)):
            e = np.zeros(len(y))
            e[j] = h
            cols.append((d.forward(y + e, yd).ydd - d.forward(y - e, yd).ydd) / (2 * h))
        return np.column_stack(cols)

    h = 1e-5
    a, b = central(h), central(2 * h)
    scale = np.abs(fwd.ydd).max() + np.abs(fwd.ydd_y).max()
    bound = 4 / 3 * np.abs(a - b) + 10 * np.finfo(float).eps * scale / h
    assert np.all(np.abs(fwd.ydd_y - a) <= bound + 1e-300)


def test_closed_loop_through_an_elastic_body() -> None:
    """A four-bar whose coupler is an elastic beam (axial and in-plane bending modes), closed
    by a revolute joint at the coupler's end attachment frame: the motion stays on the
    manifold (|Φ|, |Φ̇| at the Newton solves' rounding) and the undamped mechanism keeps its
    energy to the integrator's tolerance."""
    from jourdain.model.closing import ClosingJoint

    th1, th2, th3 = jd.symbols("theta1 theta2 theta3")
    a, b, c, d = 0.4, 1.0, 0.8, 1.1
    beam = Beam(length=b, E=7e10, rho=2700.0, A=4e-4, I_y=1e-8, I_z=1e-8, J=2e-8, nu=0.3,
                n_elements=6)
    coupler = ElasticBody.beam("coupler", "crank",
                               jd.Revolute("knee", th2, "z", position=(a, 0, 0)), beam, 2,
                               keep=("ux", "uy", "rz"), attach={"end": 6})
    bodies = [jd.Body("crank", "world", jd.Revolute("ground1", th1, "z"), mass=1.0,
                      com=(a / 2, 0, 0), inertia=jd.rod(1.0, a, "x")),
              coupler,
              jd.Body("rocker", "world", jd.Revolute("ground2", th3, "z", position=(d, 0, 0)),
                      mass=1.5, com=(c / 2, 0, 0), inertia=jd.rod(1.5, c, "x"))]
    tree = jd.System([th1, th2, th3], bodies, [jd.Gravity((0, -9.81, 0))])
    closure = ClosingJoint("closure", "revolute", "coupler_end", "rocker", point_a=(0, 0, 0),
                           point_b=(c, 0, 0), axis="z")
    system = tree.closed_by([closure], independent=["theta1", "coupler_q1", "coupler_q2"])
    rtol = 1e-10
    r = system.simulate((0, 1.0), [0.5, 0.8, 1.9, 0, 0], [1.0, 0, 0, 0, 0], rtol=rtol,
                        atol=1e-12)
    assert max(r.closure_residual) < 1e-9
    assert r.conservative
    E_tot = np.asarray(r.total_energy)
    scale = np.abs(np.asarray(r.kinetic_energy)).max() + np.abs(E_tot).max()
    assert np.abs(E_tot - E_tot[0]).max() <= 10 * rtol * scale
    assert np.abs(np.asarray(r.y)[:, 3:]).max() > 1e-6  # the coupler did bend


def test_floquet_of_a_flexible_pendulum_is_its_eigenvalues() -> None:
    """Floquet on the hanging flexible pendulum (time-invariant: any period T): the
    multipliers from the integrated monodromy matrix equal e^{λT} of the linearization's
    eigenvalues, to the integration's tolerance — the elastic coordinates' fast modes
    (ωT up to 37 rad) included."""
    model = jd.load_model(Path(__file__).parent.parent / "examples" / "flexible_pendulum.toml")
    system = model.system
    eq = jd.find_equilibrium(system, {"phi": -np.pi / 2})
    lin = system.linearize(dict(zip(system.coordinate_names, eq.y, strict=True)))
    T = 0.05
    fl = jd.floquet(lin, T, cyclic=())
    ref = np.exp(jd.modes(lin).eigenvalues * T)
    worst = max(float(np.abs(fl.multipliers - mu).min()) for mu in ref)
    assert len(fl.multipliers) == len(ref) == 8
    assert worst <= 1e3 * FLOQUET_RTOL, worst


@pytest.mark.parametrize("mass", ["lumped", "consistent"])
def test_craig_bampton_body_holds_a_tip_load_exactly(mass: str) -> None:
    """reduction="craig_bampton" with the tip as interface: the static deflection under a tip
    force is the beam's F·L³/(3EI) (exact for Hermite elements) to the solve's rounding,
    where 3 normal modes miss it by ~1e-3; its modes' damping ratio is the one asked."""
    F = 2.0
    ref = F * L**3 / (3 * E * I)
    beam = Beam(length=L, E=E, rho=RHO, A=A, I_y=I, I_z=I, J=2 * I, nu=0.3, n_elements=6)
    out = {}
    for reduction in ("craig_bampton", "normal"):
        eb = ElasticBody.beam("b", "world", jd.Fixed("wall"), beam, 2 if reduction != "normal"
                              else 3, keep=("uy", "rz"), attach={"tip": 6}, stiffening=False,
                              mass=mass, reduction=reduction, damping_ratio=0.02)
        system = jd.System([], [eb], [jd.Force("load", "b_tip", (0, -F, 0))])
        eq = jd.find_equilibrium(system, np.zeros(system.f))
        out[reduction] = -float(eb.modal.Phi_t[6, 1] @ np.asarray(eq.y))
        if reduction == "craig_bampton":
            assert eb.modal.kinds == ("constraint", "constraint", "normal", "normal")
            lin = system.linearize(dict(zip(system.coordinate_names, eq.y, strict=True)))
            md = jd.modes(lin)
            osc = md.oscillating()
            assert np.allclose(md.damping_ratios[osc], 0.02, rtol=1e-8)
    K = eb.modal.K_e
    assert abs(out["craig_bampton"] / ref - 1) <= 1e3 * np.finfo(float).eps * np.linalg.cond(K)
    assert abs(out["normal"] / ref - 1) > 1e-4
