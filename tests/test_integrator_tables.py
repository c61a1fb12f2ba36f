"""The Runge–Kutta coefficients of the compiled integrators (numeric/rk_tables.h) against their
defining conditions, not against another tabulation:

- the order conditions of all rooted trees (Butcher; Hairer, Nørsett & Wanner I, §II.2):
  ``bᵀΦ(t) = 1/γ(t)`` for every tree ``t`` up to the method's order, exactly in rational
  arithmetic for Dormand–Prince 5(4) (every coefficient rational) and to the rounding of the
  published decimals for DOP853; the embedded solutions to their own orders and not beyond;
- Shampine's continuous extension of Dormand–Prince 5(4): order 4 at every θ, exactly;
- Radau IIA: the nodes in closed form, the Runge–Kutta matrix of collocation at them, its
  inverse's eigenvalues and the block form that T gives it, the collocation polynomial;
- the observed orders of every solution of each pair on a nonlinear test problem.
"""

from __future__ import annotations

import math
from fractions import Fraction
from functools import cache

import numpy as np
import pytest

from jourdain.numeric.integrator_c import table_fractions, table_values

T = table_values()
FR = table_fractions()
EPS = np.finfo(float).eps


# --- rooted trees --------------------------------------------------------------------------
@cache
def trees(order: int) -> tuple[tuple, ...]:
    """All rooted trees with ``order`` vertices, each a sorted tuple of its subtrees."""
    if order == 1:
        return ((),)
    out: set[tuple] = set()

    def forests(n: int, max_tree: tuple | None) -> list[tuple]:
        """Multisets of trees with n vertices in all, as sorted tuples (non-increasing)."""
        if n == 0:
            return [()]
        res = []
        for k in range(1, n + 1):
            for t in trees(k):
                if max_tree is not None and _key(t) > _key(max_tree):
                    continue
                for rest in forests(n - k, t):
                    res.append((t, *rest))
        return res

    for f in forests(order - 1, None):
        out.add(tuple(sorted(f, key=_key, reverse=True)))
    return tuple(sorted(out, key=_key))


def _key(t: tuple) -> tuple:
    return (_order(t), tuple(_key(s) for s in t))


def _order(t: tuple) -> int:
    return 1 + sum(_order(s) for s in t)


def _gamma(t: tuple) -> int:
    return _order(t) * math.prod(_gamma(s) for s in t)


def _phi(t: tuple, A, ones):
    """Φ(t): the stage weights of tree t (``A`` a matrix of numbers or Fractions)."""
    v = list(ones)
    for s in t:
        w = _phi(s, A, ones)
        Aw = [sum((A[i][j] * w[j] for j in range(len(w))), start=0 * w[0]) for i in range(len(w))]
        v = [a * b for a, b in zip(v, Aw, strict=True)]
    return v


def test_tree_counts():
    # the numbers of rooted trees (OEIS A000081): 1, 1, 2, 4, 9, 20, 48, 115
    assert [len(trees(n)) for n in range(1, 9)] == [1, 1, 2, 4, 9, 20, 48, 115]


# --- Dormand–Prince 5(4), exact --------------------------------------------------------------
def _dp5():
    a = FR["RK5_A"]
    assert all(x is not None for x in a + FR["RK5_B"] + FR["RK5_C"] + FR["RK5_E"] + FR["RK5_P"])
    A = [a[7 * i:7 * i + 7] for i in range(7)]
    b = FR["RK5_B"] + [Fraction(0)]
    A[6] = list(b)  # the FSAL stage: the new solution
    c = FR["RK5_C"] + [Fraction(1)]
    return A, b, c


def _defect(A, w, n_max: int, theta=Fraction(1)) -> list[tuple[int, object]]:
    """(order, wᵀΦ(t) − θ^|t|/γ(t)) for every tree up to n_max."""
    ones = [Fraction(1)] * len(w)
    out = []
    for n in range(1, n_max + 1):
        for t in trees(n):
            out.append((n, sum(x * y for x, y in zip(w, _phi(t, A, ones), strict=True))
                        - theta ** n / _gamma(t)))
    return out


def test_dormand_prince_54_exact():
    A, b, c = _dp5()
    for i in range(7):  # row sums are the nodes
        assert sum(A[i][:i]) == c[i] and all(x == 0 for x in A[i][i:])
    assert all(d == 0 for _, d in _defect(A, b, 5))          # b: order 5
    assert any(d != 0 for n, d in _defect(A, b, 6) if n == 6)  # and not 6
    b_hat = [x + e for x, e in zip(b, FR["RK5_E"], strict=True)]  # the embedded solution
    assert sum(FR["RK5_E"]) == 0
    assert all(d == 0 for _, d in _defect(A, b_hat, 4))          # order 4
    assert any(d != 0 for n, d in _defect(A, b_hat, 5) if n == 5)  # and not 5


@pytest.mark.parametrize("theta", [Fraction(1, 7), Fraction(1, 3), Fraction(1, 2),
                                   Fraction(5, 6), Fraction(1)])
def test_dormand_prince_54_continuous_extension_exact(theta):
    A, b, _ = _dp5()
    P = [FR["RK5_P"][4 * j:4 * j + 4] for j in range(7)]
    b_theta = [sum(P[j][k] * theta ** (k + 1) for k in range(4)) for j in range(7)]
    assert all(d == 0 for _, d in _defect(A, b_theta, 4, theta))
    if theta == 1:
        assert b_theta == b


# --- DOP853, to the rounding of the published decimals ---------------------------------------
def _dop853():
    A = T["RK8_A"].reshape(16, 16)
    c = T["RK8_C"]
    b = np.concatenate([T["RK8_B"], [0.0]])
    return A[:13, :13], b, c[:13]


def _float_defects(A, w, n_max):
    """Largest |wᵀΦ(t) − 1/γ(t)| per order, and the rounding scale of each (the same sum with
    |A| and |w|: the size of the terms that cancel)."""
    ones = np.ones(len(w))
    Aa, wa = np.abs(A), np.abs(w)
    out = {}
    for n in range(1, n_max + 1):
        worst = 0.0
        for t in trees(n):
            phi = np.array(_phi(t, A.tolist(), ones))
            scale = wa @ np.array(_phi(t, Aa.tolist(), ones))
            # every coefficient carries a relative rounding of eps/2, a tree of n vertices
            # multiplies n of them: the residual of an exact condition is below n·eps·scale
            worst = max(worst, abs(w @ phi - 1 / _gamma(t)) / (n * EPS * scale))
        out[n] = worst
    return out


def test_dop853_order_conditions():
    A, b, c = _dop853()
    np.testing.assert_array_equal(np.tril(A, -1), A)
    assert np.all(np.abs(A.sum(axis=1) - c) <= 4 * EPS * np.abs(A).sum(axis=1))
    Afull = T["RK8_A"].reshape(16, 16)  # the dense-output stages are consistent too
    assert np.all(np.abs(Afull.sum(axis=1) - T["RK8_C"]) <= 4 * EPS * np.abs(Afull).sum(axis=1))
    np.testing.assert_array_equal(A[12, :12], T["RK8_B"])  # FSAL: stage 13 is the solution
    d = _float_defects(A, b, 9)
    assert all(d[n] <= 1.0 for n in range(1, 9)), d   # order 8 to the rounding
    assert d[9] > 1e3                                  # and not 9
    for E, order in ((T["RK8_E5"], 5), (T["RK8_E3"], 3)):
        d = _float_defects(A, b - E, order + 1)
        assert all(d[n] <= 1.0 for n in range(1, order + 1)), (order, d)
        assert d[order + 1] > 1e3, (order, d)


def test_dop853_rational_entries():
    """The nodes and coefficients written as quotients are the published rationals; the four
    irrational nodes are the closed forms in √6 to the rounding."""
    fr = FR["RK8_C"]
    assert fr[5:] == [Fraction(1, 3), Fraction(1, 4), Fraction(4, 13), Fraction(127, 195),
                      Fraction(3, 5), Fraction(6, 7), 1, 1, Fraction(1, 10), Fraction(1, 5),
                      Fraction(7, 9)]
    s6 = math.sqrt(6.0)
    c4 = (6 - s6) / 30
    np.testing.assert_allclose(T["RK8_C"][1:5], [4 * c4 / 9, 2 * c4 / 3, c4, (6 + s6) / 30],
                               rtol=4 * EPS, atol=0)


# --- Radau IIA ---------------------------------------------------------------------------------
def _radau_matrix(c: np.ndarray) -> np.ndarray:
    """Collocation at c: a_ij = ∫₀^{c_i} ℓ_j(τ) dτ with ℓ_j the Lagrange polynomials."""
    A = np.zeros((3, 3))
    for j in range(3):
        others = [c[m] for m in range(3) if m != j]
        lj = np.poly1d(np.poly(others)) / np.prod([c[j] - o for o in others])
        Lj = np.polyint(lj)
        A[:, j] = Lj(c) - Lj(0.0)
    return A


def test_radau_iia():
    c = T["RADAU_C"]
    s6 = math.sqrt(6.0)
    np.testing.assert_allclose(c, [(4 - s6) / 10, (4 + s6) / 10, 1.0], rtol=2 * EPS, atol=0)
    A = _radau_matrix(c)
    # Radau IIA: b = the last row of A (stiffly accurate); order 5 on the trees up to 5
    ones = np.ones(3)
    for n in range(1, 6):
        for t in trees(n):
            assert abs(A[2] @ np.array(_phi(t, A.tolist(), ones)) - 1 / _gamma(t)) < 1e-14
    Ainv = np.linalg.inv(A)
    mu_r, (a, b) = T["RADAU_MU_REAL"][0], T["RADAU_MU_CPLX"]
    np.testing.assert_allclose(mu_r, 3 + 3 ** (2 / 3) - 3 ** (1 / 3), rtol=4 * EPS)
    np.testing.assert_allclose(a + 1j * b, 3 + (3 ** (1 / 3) - 3 ** (2 / 3)) / 2
                               - 0.5j * (3 ** (5 / 6) + 3 ** (7 / 6)), rtol=4 * EPS)
    eig = np.sort_complex(np.linalg.eigvals(Ainv))
    np.testing.assert_allclose(eig, np.sort_complex([mu_r, a + 1j * b, a - 1j * b]), rtol=1e-13)
    Tm, TI = T["RADAU_T"].reshape(3, 3), T["RADAU_TI"].reshape(3, 3)
    np.testing.assert_allclose(Tm @ TI, np.eye(3), atol=1e-14)
    # T⁻¹ A⁻¹ T is the real block form: μ_r, and the 2×2 block of a ± ib
    np.testing.assert_allclose(TI @ Ainv @ Tm, [[mu_r, 0, 0], [0, a, -b], [0, b, a]],
                               atol=1e-13)
    # the error weights (Hairer & Wanner II, IV.8) and the collocation polynomial through the
    # stage values: Σ_k P[j, k] c_m^(k+1) = δ_jm
    np.testing.assert_allclose(T["RADAU_E"], np.array([-13 - 7 * s6, -13 + 7 * s6, -1]) / 3,
                               rtol=4 * EPS)
    V = np.array([[cm ** (k + 1) for k in range(3)] for cm in c])
    np.testing.assert_allclose(T["RADAU_P"].reshape(3, 3) @ V.T, np.eye(3), atol=1e-13)


# --- observed orders on a test problem ---------------------------------------------------------
def _integrate(A, w, c, n_steps, t_end=2.0):
    """Global error at ``t_end`` of y' = cos t·(1 − y²), y(0) = 0 (exact tanh(sin t)), with
    ``n_steps`` fixed steps of the weights ``w``."""
    h, y, t = t_end / n_steps, 0.0, 0.0
    s = len(w)
    for _ in range(n_steps):
        k = np.zeros(s)
        for i in range(s):
            yi = y + h * (A[i, :i] @ k[:i])
            k[i] = math.cos(t + c[i] * h) * (1.0 - yi * yi)
        y, t = y + h * (w @ k), t + h
    return abs(y - math.tanh(math.sin(t_end)))


@pytest.mark.parametrize("pair, weights, order", [
    ("RK5", "b", 5), ("RK5", "b_hat", 4),
    ("RK8", "b", 8), ("RK8", "b5", 5), ("RK8", "b3", 3)])
def test_observed_orders(pair, weights, order):
    """Halving the step divides the global error by at least about 2^order (the exact order
    conditions above say that it is not more in general)."""
    if pair == "RK5":
        A = T["RK5_A"].reshape(7, 7).copy()
        b = np.concatenate([T["RK5_B"], [0.0]])
        A[6, :6] = T["RK5_B"]
        c = np.concatenate([T["RK5_C"], [1.0]])
        w = {"b": b, "b_hat": b + T["RK5_E"]}[weights]
    else:
        A, b, c = _dop853()
        w = {"b": b, "b5": b - T["RK8_E5"], "b3": b - T["RK8_E3"]}[weights]
    n = 8 if order >= 8 else 16
    e1, e2 = _integrate(A, w, c, n), _integrate(A, w, c, 2 * n)
    # the rounding of 2n steps is about 2n·eps; the finer error must stand well above it
    assert e2 > 20 * (2 * n) * EPS, (e1, e2)
    observed = math.log2(e1 / e2)
    assert observed > order - 0.3, (pair, weights, observed)
