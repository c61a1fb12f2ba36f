"""The written-out LDLᵀ solve of the integrator's right-hand side (numeric/integrator_ldl.py):
ÿ = M⁻¹(q − k) against LAPACK's solve (numpy.linalg.solve) on random symmetric positive
definite matrices of known condition, and its refusals (indefinite M, NaN)."""

import ctypes

import numpy as np
import pytest

from jourdain.numeric.integrator_ldl import WRITTEN_OUT_MAX_F, ldl_source
from jourdain.numeric.toolchain import build, compiler, content_key

try:
    compiler()
    HAVE_CC = True
except Exception:  # noqa: BLE001 - no compiler: the compiled tests are skipped
    HAVE_CC = False

pytestmark = pytest.mark.skipif(not HAVE_CC, reason="no C compiler")

WRAPPER = """
int solve(const double *M, const double *k, const double *q, double *ydd) {
    double L[1];
    return jd_solve_mkq(M, k, q, ydd, L);
}
"""


def _solver(f: int):
    src = "#include <math.h>\n" + ldl_source(f) + WRAPPER
    lib = build(content_key("test_integrator_ldl", src), src)
    vp = ctypes.c_void_p
    lib.solve.argtypes = [vp, vp, vp, vp]
    lib.solve.restype = ctypes.c_int

    def solve(M: np.ndarray, k: np.ndarray, q: np.ndarray) -> tuple[int, np.ndarray]:
        M, k, q = (np.ascontiguousarray(a, dtype=float) for a in (M, k, q))
        ydd = np.full(f, np.nan)
        r = lib.solve(M.ctypes.data, k.ctypes.data, q.ctypes.data, ydd.ctypes.data)
        return r, ydd
    return solve


def _spd(rng: np.random.Generator, f: int, cond: float) -> np.ndarray:
    """A random symmetric positive definite matrix with condition number ``cond``."""
    Q, _ = np.linalg.qr(rng.standard_normal((f, f)))
    d = np.geomspace(1.0, 1.0 / cond, f)
    return (Q * d) @ Q.T


@pytest.mark.parametrize("f", range(1, WRITTEN_OUT_MAX_F + 1))
def test_solve_matches_lapack(f):
    solve = _solver(f)
    rng = np.random.default_rng(f)
    for cond in (1.0, 1e3, 1e6):
        M = _spd(rng, f, cond) * 7.5
        k, q = rng.standard_normal(f), rng.standard_normal(f)
        r, ydd = solve(M, k, q)
        ref = np.linalg.solve(M, q - k)
        assert r == 0
        # backward-stable solves of a system of condition c differ by about c·eps·|x|
        # (LDLᵀ without pivoting is backward stable for positive definite M)
        tol = 20 * f * cond * np.finfo(float).eps * np.abs(ref).max()
        assert np.abs(ydd - ref).max() <= tol, (f, cond)


@pytest.mark.parametrize("f", [1, 2, 5, WRITTEN_OUT_MAX_F])
def test_refusals(f):
    solve = _solver(f)
    rng = np.random.default_rng(100 + f)
    M = _spd(rng, f, 10.0)
    k, q = np.zeros(f), np.ones(f)
    bad = M.copy()
    bad[f - 1, f - 1] = -1.0  # not positive definite: the last pivot is negative
    assert solve(bad, k, q)[0] == 1
    bad = M.copy()
    bad[f - 1, 0] = bad[0, f - 1] = np.nan
    assert solve(bad, k, q)[0] == 2
    q_nan = q.copy()
    q_nan[0] = np.inf
    assert solve(M, k, q_nan)[0] == 2


def test_large_f_left_to_the_loop():
    assert ldl_source(WRITTEN_OUT_MAX_F + 1) == ""
    assert ldl_source(0) == ""


@pytest.mark.parametrize("n", [1, 4, 9])  # f = 2, 5, 10: the written-out solve in the loop
def test_the_loop_accelerations_are_lapacks(n):
    """ÿ that the C loop computed with the written-out solve (jd_accel, kept as the results'
    ydd) against LAPACK's solve of the same M, k, q at the same states."""
    from jourdain import numeric
    from jourdain.models import n_link_pendulum_on_cart

    s = n_link_pendulum_on_cart(n)
    assert s.f <= WRITTEN_OUT_MAX_F
    y0 = np.concatenate([[0.0], np.linspace(np.pi + 0.3, np.pi - 0.3, n)])
    res = s.simulate((0, 2.0), y0, np.zeros(n + 1), inputs={"F": 0.5}, rtol=1e-9, atol=1e-9)
    fn = numeric.mkq_function(s)
    out = fn.batch(res.y, res.yd, res.t, numeric.parameter_vector(s, None), res.u)
    M, k, q = out["M"], out["k"][:, :, 0], out["q"][:, :, 0]
    ref = np.linalg.solve(M, (q - k)[:, :, None])[:, :, 0]
    cond = np.linalg.cond(M)
    tol = 20 * s.f * cond[:, None] * np.finfo(float).eps * np.abs(ref).max(axis=1, keepdims=True)
    assert np.all(np.abs(res.ydd - ref) <= tol)
