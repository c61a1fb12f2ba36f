import numpy as np

from jourdain.models import double_pendulum


def test_double_pendulum_mass_matrix_closed_form():
    """M of two uniform rods (relative angle phi2), derived by hand with Lagrange's equations."""
    s = double_pendulum()
    p = s.parameter_values
    m1, m2, l1, l2 = p["m1"], p["m2"], p["l1"], p["l2"]
    phi2 = -0.4
    M = s.evaluate([0.3, phi2], [0.0, 0.0])["M"]
    I1, I2 = m1 * l1**2 / 12, m2 * l2**2 / 12
    c = np.cos(phi2)
    M22 = m2 * l2**2 / 4 + I2
    M12 = M22 + m2 * l1 * l2 * c / 2
    M11 = m1 * l1**2 / 4 + I1 + m2 * l1**2 + M22 + m2 * l1 * l2 * c
    np.testing.assert_allclose(M, [[M11, M12], [M12, M22]], rtol=1e-12)
