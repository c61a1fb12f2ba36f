"""The Kane–Ryan–Banerjee spin-up reference (tests/reference/krb_reference.py) checked against
physics that needs no jourdain:

* its assumed modes: the clamped-free eigenfunctions orthogonal, ∫φ_i² = L, φ_i(L) = ±2, the
  modal stiffness EI·β_i⁴·L;
* its linearization about steady spin θ̇ = Ω: the first in-plane bending frequency rises as
  Southwell's ω² = ω₀² + (K₁ − 1)·Ω², K₁ = ∫(L² − x²)/2·φ₁'² dx / ∫φ₁² dx = 1.1933 (the
  flapwise coefficient; in the plane of rotation the centrifugal softening −Ω² is subtracted),
  the linear variant falls as ω² = ω₀² − Ω²; at higher spin the frequencies agree with the
  tabulated rotating-cantilever ones;
* the spin-up: the stiffening variant stays well below 1 m, the linear one diverges.
"""

import math

import numpy as np
import pytest

from tests.reference import krb_reference as krb

#: the reference checks itself; jourdain is not imported, so one pass of make test is enough
pytestmark = pytest.mark.no_jourdain

#: √(EI/(ρA·L⁴)): the frequency unit of the dimensionless tables
UNIT = math.sqrt(krb.EI / (krb.RHO_A * krb.L_BEAM ** 4))


def _omega0() -> float:
    return (krb.cantilever_roots(1)[0] / krb.L_BEAM) ** 2 * math.sqrt(krb.EI / krb.RHO_A)


def test_assumed_modes():
    L = krb.L_BEAM
    x, w = krb._gauss(0.0, L, 96)
    phi = np.array([krb.bending_shape(i, x) for i in range(1, 6)])
    np.testing.assert_allclose((phi * w) @ phi.T, L * np.eye(5), atol=1e-11 * L)
    tips = [krb.bending_shape(i, np.array([L]))[0] for i in range(1, 6)]
    np.testing.assert_allclose(tips, [2, -2, 2, -2, 2], rtol=1e-12)
    d2 = np.array([krb.bending_shape(i, x, 2) for i in range(1, 6)])
    beta = np.array(krb.cantilever_roots(5)) / L
    np.testing.assert_allclose(krb.EI * (d2 * w) @ d2.T, np.diag(krb.EI * beta ** 4 * L),
                               rtol=1e-12, atol=1e-10 * krb.EI * beta[-1] ** 4 * L)
    # the standard roots of 1 + cos z·cosh z = 0
    np.testing.assert_allclose(krb.cantilever_roots(3), [1.8751040687, 4.6940911330,
                                                         7.8547574382], rtol=1e-10)


def test_southwell_coefficient_of_the_first_in_plane_mode():
    L = krb.L_BEAM
    x, w = krb._gauss(0.0, L, 96)
    K1 = (w @ ((L ** 2 - x ** 2) / 2 * krb.bending_shape(1, x, 1) ** 2)
          / (w @ krb.bending_shape(1, x) ** 2))
    assert K1 == pytest.approx(1.1933, abs=1e-4)  # Southwell's first coefficient
    w0 = _omega0()
    assert krb.bending_frequencies(0.0)[0] == pytest.approx(w0, rel=1e-12)
    for spin in (0.1, 0.5):
        stiff = krb.bending_frequencies(spin)[0]
        linear = krb.bending_frequencies(spin, stiffening=False)[0]
        # the Coriolis coupling with the axial mode lowers both by ≈ 1e-4·Ω²
        assert (stiff ** 2 - w0 ** 2) / spin ** 2 == pytest.approx(K1 - 1, abs=5e-4)
        assert (linear ** 2 - w0 ** 2) / spin ** 2 == pytest.approx(-1, abs=5e-4)
    # beyond ω₀ the linear variant's first mode diverges (a real eigenvalue, given as −σ)
    sigma = -krb.bending_frequencies(krb.OMEGA_S, stiffening=False)[0]
    assert sigma == pytest.approx(math.sqrt(krb.OMEGA_S ** 2 - w0 ** 2), rel=1e-3)


@pytest.mark.parametrize(("spin", "flapwise", "rel"), [(1.0, 3.6816, 2e-5), (6.0, 7.3604, 1e-4)])
def test_rotating_frequency_against_the_table(spin, flapwise, rel):
    """The first flapwise frequency of the uniform hub-less rotating cantilever, dimensionless
    (Ω̄ = Ω/UNIT: 1 → 3.6816, 6 → 7.3604; e.g. Hodges & Rutkowski 1981, AIAA J. 19(11)); in
    the plane of rotation ω² = ω_flap² − Ω² (inextensible beam). The Ritz value is an upper
    bound: five modes give it to 1e-5 at Ω̄ = 1, 1e-4 at Ω̄ = 6."""
    ours = krb.bending_frequencies(spin * UNIT)[0] / UNIT
    expected = math.sqrt(flapwise ** 2 - spin ** 2)
    assert expected * (1 - 2e-5) < ours < expected * (1 + rel)


def test_spin_up_stiffening_stays_small_and_linear_diverges():
    t = np.linspace(0.0, 20.0, 401)
    v = krb.krb_tip_deflection(t, rtol=1e-8, atol=1e-10)
    assert np.max(np.abs(v)) < 1.0
    i = int(np.argmin(v))
    # the converged peak (module docstring), on a 50 ms grid
    assert t[i] == pytest.approx(6.75, abs=0.05)
    assert v[i] == pytest.approx(-0.57587, abs=2e-4)
    assert np.max(np.abs(v[t >= krb.T_S])) < 0.01  # only a small vibration after the spin-up
    lin = krb.krb_tip_deflection(t, stiffening=False, n_bending=2, rtol=1e-6, atol=1e-9)
    assert np.nanmax(np.abs(lin)) > krb.L_BEAM
    np.testing.assert_allclose(lin[:41], v[:41], atol=0.02)  # alike while Ω ≪ ω₀ (t ≤ 2 s)
