"""The rotor layer without ROSS: an overhung disc on a (nearly) massless cantilever shaft
against its closed-form whirl frequencies, and the shaft's gyroscopic matrix against the
rotary mass it shares its shape functions with.

Overhung disc (Friswell et al., *Dynamics of Rotating Machines*, §3.6; Lalanne & Ferraris,
*Rotordynamics Prediction in Engineering*): with the cantilever's exact tip stiffness
k = EI/L³·[[12, −6L], [−6L, 4L²]] (deflection, slope) and a disc m, I_d, I_p at the tip, the
whirl frequencies at spin Ω are the positive roots of
(k₁₁ − mω²)·(k₂₂ − I_dω² ± I_pΩω) − k₁₂² = 0 (forward and backward whirl).
"""

from __future__ import annotations

import numpy as np

from jourdain.elastic import Beam, element_matrices
from jourdain.elastic.rotor import Disc, campbell, rotor
from tests.tolerance import EPS

E, NU = 2.1e11, 0.3


def _closed_form(k: np.ndarray, m: float, Id: float, Ip: float, speed: float) -> np.ndarray:
    k11, k12, k22 = k[0, 0], k[0, 1], k[1, 1]
    out = []
    for s in (1.0, -1.0):
        coeffs = [m * Id, -s * m * Ip * speed, -(k11 * Id + k22 * m), s * k11 * Ip * speed,
                  k11 * k22 - k12 * k12]
        r = np.roots(coeffs)
        out += [x.real for x in r if abs(x.imag) < 1e-9 * abs(x) and x.real > 0]
    return np.sort(out)


def test_overhung_disc_whirl_frequencies() -> None:
    L, r0 = 0.4, 0.02
    A, I = np.pi * r0**2, np.pi * r0**4 / 4
    m, Id, Ip = 10.0, 0.05, 0.09
    # a shaft 1e-9 as dense as steel: its mass moves the frequencies by ~1e-10 relative
    shaft = Beam(length=L, E=E, rho=7850e-9, A=A, I_y=I, I_z=I, J=2 * I, nu=NU, n_elements=1,
                 axis=(0.0, 0.0, 1.0))
    r = rotor(shaft, [Disc(1, m, Id, Ip)])
    tip = [r.fe.index(1, name) for name in ("ux", "uy", "rx", "ry")]  # node 0 clamped
    k = E * I / L**3 * np.array([[12, -6 * L], [-6 * L, 4 * L * L]])
    shaft_mass = 7850e-9 * A * L
    for speed in (0.0, 500.0, 2000.0, 8000.0):
        ours = campbell(r, [speed], 4, tip)[0]
        ref = _closed_form(k, m, Id, Ip, speed)
        assert len(ref) == 4
        # the shaft's mass (relative m_shaft/m) plus the solves' rounding
        rtol = 10 * shaft_mass / m + 10 * 8 * EPS * np.linalg.cond(r.M[np.ix_(tip, tip)])
        np.testing.assert_allclose(ours, ref, rtol=rtol, err_msg=f"speed {speed}")
    # the split: forward up, backward down, and the forward conical mode stiffened past Ω·Ip/Id
    w0, w1 = campbell(r, [0.0], 4, tip)[0], campbell(r, [8000.0], 4, tip)[0]
    assert w1[0] < w0[0] and w1[-1] > w0[-1] and w1[-1] > 8000.0 * Ip / Id


def test_gyroscopic_matrix_is_the_spin_energys() -> None:
    """G of one element from the spin coupling of the kinetic energy,
    T_g = −Ω·ρI_p·∫θ_y·θ̇_z dx, whose Lagrange terms give G = ρI_p·∫(N_θyᵀN_θz − N_θzᵀN_θy):
    its (x–z, x–y) block is −(I_p/I)·S·R_z with R_z = ρI·∫N_ψᵀN_ψ the rotary mass of the x–y
    plane (read from M with and without rotary inertia) and S = diag(1, −1, 1, −1) the mirror
    θ_y = −u_z'. (The ROSS comparison, where installed, pins the same sign.)"""
    h = 0.05
    beam = Beam(length=1.0, E=E, rho=7850.0, A=h * h, I_y=h**4 / 12, I_z=h**4 / 12,
                J=0.141 * h**4, nu=NU, kappa=5 / 6)
    L = 0.2
    _, M, G = element_matrices(beam, L)
    _, M0, _ = element_matrices(Beam(**{**beam.__dict__, "rotary_inertia": False}), L)
    # rotary parts of the two planes: ρI·∫N_θᵀN_θ; for equal I_y = I_z they are mirror images
    Rz = (M - M0)[np.ix_([1, 5, 7, 11], [1, 5, 7, 11])]
    Ry = (M - M0)[np.ix_([2, 4, 8, 10], [2, 4, 8, 10])]
    sign = np.array([1.0, -1.0, 1.0, -1.0])
    np.testing.assert_allclose(Ry, sign[:, None] * Rz * sign[None, :], rtol=1e-13)
    # G couples only (u_z, θ_y) with (u_y, θ_z); its block is I_p/I·(rotary mass) up to the
    # mirror: G[xz, xy] = −(I_p/I)·S·R_z with S = diag(1, −1, 1, −1)
    block = G[np.ix_([2, 4, 8, 10], [1, 5, 7, 11])]
    expected = (beam.polar / beam.I_z) * (-sign[:, None] * Rz)
    np.testing.assert_allclose(block, expected, rtol=1e-12, atol=1e-15 * np.abs(Rz).max())
