"""Beam elements of jourdain.elastic (issue 36, item 2) against closed forms.

References, each computed here independently of the elements:
- Euler–Bernoulli cantilever: ω_n = (β_nL)²·√(EI/(ρAL⁴)), β_n the roots of cos β·cosh β = −1
  (brentq).
- Timoshenko cantilever: the clamped-free frequency equation of Han, Benaroya & Wei, "Dynamics
  of transversely vibrating beams using four engineering theories", J. Sound Vib. 225(5), 1999,
  935–988 (below the second spectrum, b²r²s² < 1):
  2 + [b²(r² − s²)² + 2]·cosh(bα)·cos(bβ) − b(r² + s²)/√(1 − b²r²s²)·sinh(bα)·sin(bβ) = 0,
  b² = ρAL⁴ω²/(EI), r² = I/(AL²), s² = EI/(κGAL²),
  (α, β) = (1/√2)·(∓(r² + s²) + √((r² − s²)² + 4/b²))^½; cross-checked against the boundary
  determinant of the Timoshenko equations integrated by a matrix exponential.
- axial and torsional cantilever: ω_n = (2n − 1)π/(2L)·√(E/ρ) and √(G/ρ).
- element matrices: the closed forms of Przemieniecki (1968) / Friswell et al. (2010) §5.4.

Rates: the Hermite element with consistent mass converges in frequency like h⁴; the axial and
torsion elements (linear) like h²; the Timoshenko element's shapes depend on Φ = 12EI/(κGAL²),
which grows like 1/h², so under refinement they tend to linear ones and the rate tends to h²
(the h⁴ of the Hermite element holds while Φ ≪ 1). Orders are measured where the
discretization error is far above the eigensolver's rounding (checked).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import eigh, expm
from scipy.optimize import brentq

from jourdain.elastic import Beam, assemble, constrain, element_matrices, normal_modes
from jourdain.elastic.beam import frame_of_axis
from jourdain.errors import ModelError
from tests.tolerance import EPS, assert_close_eval

E, NU, RHO = 2.1e11, 0.3, 7850.0
G_SHEAR = E / (2 * (1 + NU))


def _roots(f, n: int, step: float = 0.05, start: float = 0.5) -> list[float]:
    out, x = [], start
    while len(out) < n:
        if np.sign(f(x)) != np.sign(f(x + step)):
            out.append(brentq(f, x, x + step, xtol=1e-15, rtol=4 * EPS))
        x += step
    return out


def _plane_frequencies(beam: Beam, names: tuple[str, ...], n: int) -> tuple[np.ndarray, float]:
    """The n lowest frequencies of the cantilever (node 0 clamped) on DOFs ``names`` only, and
    the eigensolver's rounding relative to each λ: c·n·eps·λ_max/λ (a backward-stable solver of
    L⁻¹·K·L⁻ᵀ, M = L·Lᵀ, moves each eigenvalue by a few eps of its norm λ_max)."""
    fe = constrain(assemble(beam), [0])
    keep = [i for i, (_, name) in enumerate(fe.dofs) if name in names]
    K, M = fe.K[np.ix_(keep, keep)], fe.M[np.ix_(keep, keep)]
    lam, _ = normal_modes(K, M, n)
    lam_max = float(eigh(K, M, eigvals_only=True)[-1])
    return np.sqrt(lam), 10 * len(keep) * EPS * lam_max / lam


def _orders(errors: dict[int, np.ndarray], rounding: dict[int, np.ndarray]
            ) -> dict[tuple[int, int], tuple[np.ndarray, np.ndarray]]:
    """Observed orders p = ln(e_a/e_b)/ln(b/a) between successive meshes a < b, and how far
    rounding can move them: (r_a/e_a + r_b/e_b)/ln(b/a), r the rounding bound."""
    ns = sorted(errors)
    return {(a, b): (np.log(errors[a] / errors[b]) / np.log(b / a),
                     (rounding[a] / errors[a] + rounding[b] / errors[b]) / np.log(b / a))
            for a, b in zip(ns[:-1], ns[1:], strict=True)}


def test_beta_roots_are_the_textbook_values() -> None:
    beta = _roots(lambda b: np.cos(b) * np.cosh(b) + 1, 4)
    np.testing.assert_allclose(beta, [1.875104068711961, 4.694091132974175, 7.854757438237613,
                                      10.99554073487547], rtol=1e-13)


def test_element_matrices_match_the_closed_forms() -> None:
    """K, M (translational + rotary) of one bending plane equal Przemieniecki's closed forms;
    axial, torsion; G is skew and couples only the two rotations' planes."""
    h, L = 0.05, 0.1
    beam = Beam(length=1.0, E=E, rho=RHO, A=h * h, I_y=h**4 / 12, I_z=h**4 / 12 * 0.5,
                J=0.141 * h**4, nu=NU, kappa=5 / 6)
    K, M, G = element_matrices(beam, L)
    I = beam.I_z
    p = beam.phi(I, L)
    Kc = E * I / ((1 + p) * L**3) * np.array([
        [12, 6 * L, -12, 6 * L], [6 * L, (4 + p) * L**2, -6 * L, (2 - p) * L**2],
        [-12, -6 * L, 12, -6 * L], [6 * L, (2 - p) * L**2, -6 * L, (4 + p) * L**2]])
    m1, m2, m3 = 312 + 588 * p + 280 * p**2, 44 + 77 * p + 35 * p**2, 108 + 252 * p + 140 * p**2
    m4, m5, m6 = 26 + 63 * p + 35 * p**2, 8 + 14 * p + 7 * p**2, 6 + 14 * p + 7 * p**2
    Mt = RHO * beam.A * L / (840 * (1 + p) ** 2) * np.array([
        [m1, L * m2, m3, -L * m4], [L * m2, L * L * m5, L * m4, -L * L * m6],
        [m3, L * m4, m1, -L * m2], [-L * m4, -L * L * m6, -L * m2, L * L * m5]])
    m8, m9, m10 = 3 - 15 * p, 4 + 5 * p + 10 * p**2, 1 + 5 * p - 5 * p**2
    Mr = RHO * I / (30 * (1 + p) ** 2 * L) * np.array([
        [36, L * m8, -36, L * m8], [L * m8, L * L * m9, -L * m8, -L * L * m10],
        [-36, -L * m8, 36, -L * m8], [L * m8, -L * L * m10, -L * m8, L * L * m9]])
    xy = np.ix_([1, 5, 7, 11], [1, 5, 7, 11])
    # quadrature of 4 points, products of 4-term shape functions: 16 terms per entry
    assert_close_eval(K[xy], Kc, 16, err_msg="K, x-y plane")
    assert_close_eval(M[xy], Mt + Mr, 16, err_msg="M, x-y plane")
    ax = np.ix_([0, 6], [0, 6])
    assert_close_eval(K[ax], E * beam.A / L * np.array([[1, -1], [-1, 1]]), 4)
    assert_close_eval(M[ax], RHO * beam.A * L / 6 * np.array([[2, 1], [1, 2]]), 4)
    tor = np.ix_([3, 9], [3, 9])
    assert_close_eval(K[tor], G_SHEAR * beam.J / L * np.array([[1, -1], [-1, 1]]), 4)
    assert_close_eval(M[tor], RHO * beam.polar * L / 6 * np.array([[2, 1], [1, 2]]), 4)
    assert_close_eval(G, -G.T, 16, scale=float(np.abs(G).max()))
    assert not G[[0, 1, 2, 3, 6, 7, 8, 9]][:, [0, 3, 6, 9]].any()


def test_euler_bernoulli_cantilever_converges_like_h4() -> None:
    L, A, I = 2.0, 1e-3, 1e-7
    beta = np.array(_roots(lambda b: np.cos(b) * np.cosh(b) + 1, 4))
    exact = beta**2 * np.sqrt(E * I / (RHO * A * L**4))
    errors, rounding = {}, {}
    for n in (4, 8, 16, 32):
        beam = Beam(length=L, E=E, rho=RHO, A=A, I_y=I, I_z=I, J=2 * I, nu=NU, n_elements=n,
                    rotary_inertia=False)
        w, rounding[n] = _plane_frequencies(beam, ("uy", "rz"), 4)
        errors[n] = w / exact - 1
        assert np.all(errors[n] > 0), "consistent mass: frequencies from above (Rayleigh–Ritz)"
    # the pairs in the asymptotic range: mode 1 from 4 elements, modes 2–4 from 8; the low
    # modes on finer meshes (errors 1e-7, 1e-8) are left out where the rounding bound,
    # c·n·eps·λ_max/λ, reaches the error (a worst case: the orders measured there are 3.99)
    for (a, b), (p, unc) in _orders(errors, rounding).items():
        modes = {4: [0], 8: [1, 2, 3], 16: [2, 3]}[a]
        assert np.all(unc[modes] < 0.1)
        np.testing.assert_array_less(np.abs(p[modes] - 4.0), 0.15 + unc[modes],
                                     err_msg=f"order between {a} and {b} elements")
    assert np.all(errors[32] < 1e-5)


def _timoshenko_reference(L: float, A: float, I: float, kappa: float, n: int) -> np.ndarray:
    r2, s2 = I / (A * L * L), E * I / (kappa * G_SHEAR * A * L * L)

    def han(b: float) -> float:
        root = np.sqrt((r2 - s2) ** 2 + 4 / b**2)
        al, be = np.sqrt(0.5 * (root - (r2 + s2))), np.sqrt(0.5 * (root + (r2 + s2)))
        return (2 + (b * b * (r2 - s2) ** 2 + 2) * np.cosh(b * al) * np.cos(b * be)
                - b * (r2 + s2) / np.sqrt(1 - b * b * r2 * s2) * np.sinh(b * al)
                * np.sin(b * be))

    b = np.array(_roots(han, n, step=0.01))
    assert np.all(b * b * r2 * s2 < 1)
    return b * np.sqrt(E * I / (RHO * A * L**4))


def _timoshenko_determinant(w: float, L: float, A: float, I: float, kappa: float) -> float:
    """Clamped-free boundary determinant of EIψ'' + κGA(v' − ψ) + ρIω²ψ = 0,
    κGA(v'' − ψ') + ρAω²v = 0, state (v, v', ψ, ψ')."""
    kga = kappa * G_SHEAR * A
    a = np.zeros((4, 4))
    a[0, 1] = a[2, 3] = a[1, 3] = 1.0
    a[1, 0] = -RHO * A * w * w / kga
    a[3, 1] = -kga / (E * I)
    a[3, 2] = (kga - RHO * I * w * w) / (E * I)
    T = expm(a * L)
    return float(np.linalg.det([[T[3, 1], T[3, 3]], [T[1, 1] - T[2, 1], T[1, 3] - T[2, 3]]]))


def test_timoshenko_cantilever_against_its_frequency_equation() -> None:
    L, h, kappa = 1.0, 0.1, 5 / 6  # L/h = 10: shear and rotary inertia matter (~4 % on mode 2)
    A, I = h * h, h**4 / 12
    ref = _timoshenko_reference(L, A, I, kappa, 4)
    # the textbook equation and the equations' own boundary determinant agree
    for w in ref:
        d = [_timoshenko_determinant(w * (1 + s), L, A, I, kappa) for s in (-1e-9, 1e-9)]
        assert d[0] * d[1] < 0, f"no root of the boundary determinant at {w}"
    eb = np.array(_roots(lambda b: np.cos(b) * np.cosh(b) + 1, 4)) ** 2 * np.sqrt(
        E * I / (RHO * A * L**4))
    assert np.all(ref < eb) and ref[1] / eb[1] < 0.97
    errors, rounding = {}, {}
    for n in (8, 16, 32, 64):
        beam = Beam(length=L, E=E, rho=RHO, A=A, I_y=I, I_z=I, J=0.141 * h**4, nu=NU,
                    kappa=kappa, n_elements=n)
        w, rounding[n] = _plane_frequencies(beam, ("uz", "ry"), 4)
        errors[n] = w / ref - 1
        assert np.all(errors[n] > 0)
    orders = _orders(errors, rounding)
    # Φ = 12EI/(κGAh²) of the elements: 0.5 at 8 elements … 32 at 64: the rate tends to 2
    # (mode 1 at 64 elements, error 1.3e-6, is within reach of the rounding bound: left out)
    for pair, atol, modes in (((16, 32), 0.1, [0, 1, 2, 3]), ((32, 64), 0.03, [1, 2, 3])):
        p, unc = orders[pair]
        assert np.all(unc[modes] < 0.3)
        np.testing.assert_array_less(np.abs(p - 2.0)[modes], atol + unc[modes],
                                     err_msg=f"order {pair}")
    assert np.all(errors[64] < 3e-4)


@pytest.mark.parametrize(("name", "speed"), [("ux", np.sqrt(E / RHO)),
                                             ("rx", np.sqrt(G_SHEAR / RHO))])
def test_axial_and_torsional_cantilever(name: str, speed: float) -> None:
    L, r = 1.5, 0.02
    A, I = np.pi * r * r, np.pi * r**4 / 4
    exact = (2 * np.arange(1, 4) - 1) * np.pi / (2 * L) * speed
    errors, rounding = {}, {}
    for n in (8, 16, 32, 64):
        beam = Beam(length=L, E=E, rho=RHO, A=A, I_y=I, I_z=I, J=2 * I, nu=NU, n_elements=n)
        w, rounding[n] = _plane_frequencies(beam, (name,), 3)
        errors[n] = w / exact - 1
    for p, unc in _orders(errors, rounding).values():
        assert np.all(unc < 0.01)
        np.testing.assert_array_less(np.abs(p - 2.0), 0.02 + unc)
    assert np.all(errors[64] < 1e-3)


def test_orientation_does_not_change_the_frequencies() -> None:
    """The same beam along x and along an oblique axis from an offset origin: equal spectra,
    and the oblique model is the rotated one (K·Γ = 0 for its rigid motions)."""
    kw = dict(length=1.0, E=E, rho=RHO, A=1e-3, I_y=2e-7, I_z=1e-7, J=2.5e-7, nu=NU,
              kappa=0.85, n_elements=6)
    a = assemble(Beam(**kw))  # type: ignore[arg-type]
    b = assemble(Beam(**kw, axis=(1.0, 2.0, -0.5), origin=(0.3, -0.2, 0.1)))  # type: ignore[arg-type]
    la, _ = normal_modes(a.K, a.M, 20)
    lb, _ = normal_modes(b.K, b.M, 20)
    scale = la.max()
    np.testing.assert_allclose(lb[6:], la[6:], rtol=1e-9)
    assert np.abs(la[:6]).max() < 1e-9 * scale and np.abs(lb[:6]).max() < 1e-9 * scale
    R = frame_of_axis((1.0, 2.0, -0.5))
    np.testing.assert_allclose(R.T @ R, np.eye(3), atol=4 * EPS)
    assert np.linalg.det(R) > 0


def test_assemble_sparse_equals_dense() -> None:
    beam = Beam(length=1.0, E=E, rho=RHO, A=1e-3, I_y=2e-7, I_z=1e-7, J=2.5e-7, G=G_SHEAR,
                n_elements=5)
    d, s = assemble(beam), assemble(beam, sparse=True)
    for name in ("M", "K", "G"):
        np.testing.assert_array_equal(s.dense(name), d.dense(name))
    assert len(d.nodes) == 6 and d.dofs[6] == (1, "ux")


@pytest.mark.parametrize(("change", "match"), [
    ({"E": -1.0}, "E must be a positive"), ({"A": float("nan")}, "A must be"),
    ({"nu": None}, "exactly one of G"), ({"G": 8e10}, "exactly one of G"),
    ({"nu": 0.7}, "nu must lie"), ({"kappa": 0.0}, "kappa must be"),
    ({"n_elements": 0}, "n_elements"), ({"axis": (0.0, 0.0, 0.0)}, "axis must be"),
    ({"up": (2.0, 0.0, 0.0)}, "along the axis"),
])
def test_beam_rejects_bad_data(change: dict, match: str) -> None:
    kw = dict(length=1.0, E=E, rho=RHO, A=1e-3, I_y=2e-7, I_z=1e-7, J=2.5e-7, nu=NU)
    kw.update(change)
    with pytest.raises(ModelError, match=match):
        Beam(**kw)  # type: ignore[arg-type]
