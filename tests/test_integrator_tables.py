"""The Runge–Kutta coefficients of the compiled integrators (numeric/rk_tables.h): order
conditions of the published methods, and equality with SciPy's tabulation of the same methods."""

import numpy as np
import pytest

from jourdain.numeric.integrator_c import table_values

T = table_values()


def _order_conditions(A: np.ndarray, b: np.ndarray, c: np.ndarray, order: int) -> float:
    """Largest violation of the order conditions up to ``order`` (trees of order ≤ 5)."""
    e = np.ones_like(c)
    conds = [(b @ e, 1.0), (b @ c, 1 / 2)]
    if order >= 3:
        conds += [(b @ c**2, 1 / 3), (b @ A @ c, 1 / 6)]
    if order >= 4:
        conds += [(b @ c**3, 1 / 4), (b @ (c * (A @ c)), 1 / 8), (b @ A @ c**2, 1 / 12),
                  (b @ A @ A @ c, 1 / 24)]
    if order >= 5:
        conds += [(b @ c**4, 1 / 5), (b @ (c**2 * (A @ c)), 1 / 10),
                  (b @ ((A @ c) ** 2), 1 / 20), (b @ (c * (A @ c**2)), 1 / 15),
                  (b @ (c * (A @ A @ c)), 1 / 30), (b @ A @ c**3, 1 / 20),
                  (b @ A @ (c * (A @ c)), 1 / 40), (b @ A @ A @ c**2, 1 / 60),
                  (b @ A @ A @ A @ c, 1 / 120)]
    return max(abs(x - y) for x, y in conds)


def test_dormand_prince_54_order_conditions():
    A = T["RK5_A"].reshape(7, 7)[:6, :6]
    b, c = T["RK5_B"], T["RK5_C"]
    assert np.allclose(A.sum(axis=1), c, atol=1e-15)  # row sums are the nodes
    assert _order_conditions(A, b, c, 5) < 1e-14
    # the embedded error estimate is the difference of the 5th- and 4th-order weights: its
    # weights sum to zero (both solutions are consistent)
    assert abs(T["RK5_E"].sum()) < 1e-15


def test_dop853_order_conditions():
    A = T["RK8_A"].reshape(16, 16)[:12, :12]
    b, c = T["RK8_B"], T["RK8_C"][:12]
    assert np.allclose(A.sum(axis=1), c, atol=1e-14)
    assert _order_conditions(A, b, c, 5) < 1e-13


def test_radau_nodes():
    c = T["RADAU_C"]
    s6 = np.sqrt(6.0)
    np.testing.assert_allclose(c, [(4 - s6) / 10, (4 + s6) / 10, 1.0], rtol=0, atol=1e-16)


def test_tables_equal_scipys_tabulation():
    """SciPy tabulates the same methods in private modules (may move between releases)."""
    try:
        from scipy.integrate._ivp import dop853_coefficients as d8
        from scipy.integrate._ivp import radau as rd
        from scipy.integrate._ivp.rk import RK45
    except ImportError as exc:  # pragma: no cover - depends on the SciPy release
        pytest.skip(f"SciPy's private tables moved: {exc}")
    A5 = np.zeros((7, 7))
    A5[:6, :5] = RK45.A
    pairs = {"RK5_A": A5, "RK5_B": RK45.B, "RK5_C": RK45.C, "RK5_E": RK45.E, "RK5_P": RK45.P,
             "RK8_A": d8.A, "RK8_B": d8.B, "RK8_C": d8.C, "RK8_E3": d8.E3, "RK8_E5": d8.E5,
             "RK8_D": d8.D, "RADAU_C": rd.C, "RADAU_T": rd.T, "RADAU_TI": rd.TI,
             "RADAU_E": rd.E, "RADAU_P": rd.P}
    for name, ref in pairs.items():
        assert np.array_equal(T[name], np.asarray(ref, dtype=float).reshape(-1)), name
