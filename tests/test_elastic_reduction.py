"""Reduction and modal data of jourdain.elastic (issue 36, item 2): Craig–Bampton, free modes
with static correction, modal truncation, and the invariants m, m·c, J, C_t, C_r, M_e, K_e.

References: the full FE model's own eigenvalues and static solutions (a reduction is a
Rayleigh–Ritz projection of it: frequencies from above, statics exact where the basis holds
the static shapes), the free-free Euler–Bernoulli roots of cos β·cosh β = 1 (brentq), the
closed-form mass, first moment and inertia tensor of a straight beam, and the analytic
cantilever mode's ∫ρA·φ dx (quad).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.integrate import quad
from scipy.linalg import eigh
from scipy.optimize import brentq

from jourdain.elastic import (
    Beam,
    assemble,
    constrain,
    craig_bampton,
    free_modes,
    modal_truncation,
    normal_modes,
)
from jourdain.elastic.beam import FEModel, frame_of_axis
from jourdain.errors import ModelError
from tests.tolerance import EPS, assert_close_eval, assert_close_solved

E, NU, RHO = 2.1e11, 0.3, 7850.0


def _beam(n: int = 40, **kw: object) -> Beam:
    args: dict = dict(length=2.0, E=E, rho=RHO, A=1e-3, I_y=2e-7, I_z=1e-7, J=2.5e-7, nu=NU,
                      kappa=0.85, n_elements=n)
    args.update(kw)
    return Beam(**args)


def _eig_tol(fe: FEModel, lam: np.ndarray) -> np.ndarray:
    """Rounding of generalized eigenvalues λ of (K, M), relative: c·n·eps·λ_max/λ."""
    lam_max = float(eigh(fe.dense("K"), fe.dense("M"), eigvals_only=True)[-1])
    return 10 * fe.n * EPS * lam_max / lam


def test_craig_bampton_frequencies_from_above_converging_with_modes() -> None:
    fe = assemble(_beam())
    sub = constrain(fe, [0])
    lam_full, _ = normal_modes(sub.K, sub.M, 10)
    full = np.sqrt(lam_full)
    slack = _eig_tol(sub, lam_full)
    errs = []
    for n_modes in (4, 8, 16, 32):
        cb = craig_bampton(fe, [40, 20], n_modes, fixed=[0])
        assert cb.n_q == 12 + n_modes and cb.kinds[:12] == ("constraint",) * 12
        err = cb.omega[:10] / full - 1
        # Rayleigh–Ritz: never below the full model's (up to rounding of both eigensolves)
        assert np.all(err > -slack)
        errs.append(err)
    errs_a = np.array(errs)
    # more fixed-interface modes, smaller errors (modes 1–6: all below the 4th kept mode)
    assert np.all(np.diff(errs_a[:, :6], axis=0) < 0)
    # 32 modes kept: the lowest six modes within 2e-5, all ten within 5e-4
    assert np.all(errs_a[-1, :6] < 2e-5) and np.all(errs_a[-1] < 5e-4)


def test_craig_bampton_static_tip_load_is_exact() -> None:
    """A load at the interface: the constraint modes hold the static solution exactly."""
    fe = assemble(_beam(n=20))
    sub = constrain(fe, [0])
    f = np.zeros(sub.n)
    for name, value in (("uy", 1e3), ("uz", -2e3), ("ux", 5e4), ("rx", 30.0)):
        f[sub.index(20, name)] = value
    u_full = np.linalg.solve(sub.K, f)
    cb = craig_bampton(fe, [20], 3, fixed=[0])
    keep = [fe.dofs.index(d) for d in sub.dofs]
    Phi = cb.Phi[keep]
    q = np.linalg.solve(cb.K_e, Phi.T @ f)
    assert_close_solved(Phi @ q, u_full, [sub.K, cb.K_e, cb.K_e[:6, :6]])
    assert not cb.Phi[fe.node_dofs(0)].any(), "the clamped node does not move"


def test_free_free_modes_six_rigid_and_the_textbook_elastic_ones() -> None:
    L, A, I = 2.0, 1e-3, 1e-7
    fe = assemble(_beam(n=40, I_y=I, I_z=I, J=2 * I, kappa=None, rotary_inertia=False))
    md = modal_truncation(fe, 12)
    lam, tol = md.omega**2, _eig_tol(fe, np.full(12, 1.0))
    assert np.all(lam[:6] <= tol[:6]), "six rigid-body modes at zero"
    assert lam[6] > 1e4 * tol[6]
    beta = [brentq(lambda b: np.cos(b) * np.cosh(b) - 1, x - 0.5, x + 0.5, xtol=1e-15)
            for x in (4.73, 7.85)]
    exact = np.array(beta) ** 2 * np.sqrt(E * I / (RHO * A * L**4))
    # two bending planes with equal I: each frequency twice, from above, within the h⁴ error
    # of 40 elements (measured 1.4e-7 and 1.0e-6)
    err = md.omega[6:10] / np.repeat(exact, 2) - 1
    assert np.all(err > 0) and np.all(err < [3e-7, 3e-7, 2e-6, 2e-6])
    # free modes: the elastic ones only, and they carry no momentum (C_t = C_r = 0)
    fm = free_modes(fe, 4)
    np.testing.assert_allclose(fm.omega, md.omega[6:10], rtol=1e-10)
    # an eigenvector's rounding leans towards the rigid modes by ≤ c·n·eps·λ_max/λ_7 (its
    # error over the gap to them); C_t, C_r of a unit-mass-normalized mode are ≤ √m·(1, |c|)
    lean = _eig_tol(fe, md.omega[6:7] ** 2)[0]
    assert np.abs(fm.C_t).max() < lean * np.sqrt(fm.mass)
    assert np.abs(fm.C_r).max() < lean * np.sqrt(fm.mass) * np.abs(fe.nodes).max()


def test_free_modes_static_correction_holds_the_inertia_relief_response() -> None:
    """The basis with a correction at the tip contains the elastic response to a tip load
    with inertia relief, Σ_elastic φ·φᵀ·f/ω² over *all* modes of the full model."""
    fe = assemble(_beam(n=16))
    lam, Phi = eigh(fe.dense("K"), fe.dense("M"))
    f = np.zeros(fe.n)
    f[fe.index(16, "uy")] = 1.0
    x_ref = Phi[:, 6:] @ ((Phi[:, 6:].T @ f) / lam[6:])
    md = free_modes(fe, 4, correction=[(16, "uy")])
    coef, *_ = np.linalg.lstsq(md.Phi, x_ref, rcond=None)
    residual = np.abs(md.Phi @ coef - x_ref).max()
    # x_ref carries the full eigensolve's error: c·n·eps·λ_max/λ_7 relative
    assert residual <= 10 * fe.n * EPS * lam[-1] / lam[6] * np.abs(x_ref).max()
    # without the correction it is not in the span (the kept modes miss the rest)
    plain = free_modes(fe, 4)
    coef, *_ = np.linalg.lstsq(plain.Phi, x_ref, rcond=None)
    assert np.abs(plain.Phi @ coef - x_ref).max() > 1e-3 * np.abs(x_ref).max()
    # the Ritz basis is M- and K-orthogonal, and its lowest frequencies are the free modes'
    off = md.M_e - np.diag(np.diag(md.M_e))
    assert np.abs(off).max() < 1e-9 * np.abs(md.M_e).max()
    np.testing.assert_allclose(md.omega[:4], plain.omega, rtol=1e-8)


def test_invariants_of_an_oblique_offset_beam_equal_the_closed_forms() -> None:
    """m, m·c and J about the frame origin of a beam along an oblique axis from an offset
    origin: exact for the consistent mass (the section's rotary inertia included)."""
    axis, origin = np.array([1.0, 2.0, -0.5]), np.array([0.3, -0.2, 0.1])
    beam = _beam(n=7, axis=tuple(axis), origin=tuple(origin))
    md = modal_truncation(assemble(beam), 5, fixed=[0])
    L, rho, A = beam.length, beam.rho, beam.A
    e = axis / np.linalg.norm(axis)
    m = rho * A * L
    mc = m * (origin + e * L / 2)
    P = L * np.outer(origin, origin) + L**2 / 2 * (np.outer(origin, e) + np.outer(e, origin)) \
        + L**3 / 3 * np.outer(e, e)  # ∫ p·pᵀ dx
    R = frame_of_axis(tuple(axis))
    J = rho * A * (np.trace(P) * np.eye(3) - P) \
        + rho * L * R @ np.diag([beam.polar, beam.I_y, beam.I_z]) @ R.T
    n_terms = 2 * md.Phi.shape[0]
    assert_close_eval(md.mass, m, n_terms)
    assert_close_eval(md.mc, mc, n_terms, scale=m * np.abs(md.nodes).max())
    assert_close_eval(md.J, J, n_terms, scale=m * np.abs(md.nodes).max() ** 2)
    np.testing.assert_allclose(md.center_of_mass, mc / m, rtol=1e-13)
    # the constrained node's mass is counted (the frame carries it), its modal rows are zero
    assert not md.Phi[[i for i, d in enumerate(md.dofs) if d[0] == 0]].any()


def test_cantilever_first_moment_of_the_first_mode() -> None:
    """C_t of the first bending mode against ∫ρA·φ₁ dx of the analytic mass-normalized mode."""
    L, A, I = 2.0, 1e-3, 1e-7
    beam = _beam(n=40, I_y=I, I_z=0.5 * I, J=I, kappa=None, rotary_inertia=False)
    md = modal_truncation(assemble(beam), 1, fixed=[0])  # the lowest: bending about z (u_y)
    b = brentq(lambda x: np.cos(x) * np.cosh(x) + 1, 1.5, 2.5, xtol=1e-15)
    s = (np.cosh(b) + np.cos(b)) / (np.sinh(b) + np.sin(b))

    def phi(x: float) -> float:
        z = b * x / L
        return np.cosh(z) - np.cos(z) - s * (np.sinh(z) - np.sin(z))

    norm = np.sqrt(RHO * A * quad(lambda x: phi(x) ** 2, 0, L, epsabs=0, epsrel=1e-12)[0])
    ref = RHO * A * quad(phi, 0, L, epsabs=0, epsrel=1e-12)[0] / norm
    ct = md.C_t[:, 0]
    assert abs(ct[0]) < 1e-9 * abs(ref) and abs(ct[2]) < 1e-9 * abs(ref)
    # the FE mode's shape error at 40 elements: measured 2e-9 relative; bound 1e-7
    np.testing.assert_allclose(abs(ct[1]), abs(ref), rtol=1e-7)
    # C_r about z: ∫ρA·x·φ₁ dx
    ref_r = RHO * A * quad(lambda x: x * phi(x), 0, L, epsabs=0, epsrel=1e-12)[0] / norm
    np.testing.assert_allclose(abs(md.C_r[2, 0]), abs(ref_r), rtol=1e-7)


def test_sparse_and_dense_reductions_agree() -> None:
    dense, sparse = assemble(_beam(n=30)), assemble(_beam(n=30), sparse=True)
    for fn in (lambda fe: craig_bampton(fe, [30], 6, fixed=[0]),
               lambda fe: modal_truncation(fe, 6, fixed=[0]),
               lambda fe: free_modes(fe, 6, correction=[(30, "uy")])):
        a, b = fn(dense), fn(sparse)
        np.testing.assert_allclose(b.omega, a.omega, rtol=1e-8)
        np.testing.assert_allclose(b.mass, a.mass, rtol=1e-13)
        np.testing.assert_allclose(b.J, a.J, rtol=1e-12)
    assert sp.issparse(sparse.K)


def test_reduction_errors_name_what_is_wrong() -> None:
    fe = assemble(_beam(n=4))
    with pytest.raises(ModelError, match="node 9 has no DOFs"):
        craig_bampton(fe, [9], 2, fixed=[0])
    with pytest.raises(ModelError, match="node 4 has no DOF 'uw'"):
        craig_bampton(fe, [(4, "uw")], 2, fixed=[0])
    with pytest.raises(ModelError, match="fixed-interface modes asked"):
        craig_bampton(fe, [4], 40, fixed=[0])
    with pytest.raises(ModelError, match="modes of a model with"):
        modal_truncation(fe, 31)


def test_free_modes_of_a_pinned_body_skip_its_three_rotations() -> None:
    """Translations held at the middle node: the three rotations about it are the rigid
    modes (combinations of the frame's fields about the origin), the elastic modes follow."""
    fe = assemble(_beam(n=10))
    pin = [(5, "ux"), (5, "uy"), (5, "uz")]
    full = modal_truncation(fe, 10, fixed=pin)
    tol = _eig_tol(constrain(fe, pin), np.ones(10))
    assert np.all(full.omega[:3] ** 2 <= tol[:3]) and full.omega[3] ** 2 > 1e4 * tol[3]
    fm = free_modes(fe, 4, fixed=pin, correction=[(10, "uy")])
    np.testing.assert_allclose(fm.omega[:4], full.omega[3:7], rtol=1e-9)
