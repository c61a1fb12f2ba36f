"""jd_sincos_n (numeric/sincos.h), the sin and cos of every generated function, against mpmath at
200 bits: within one ulp everywhere, also next to multiples of π/2 where the argument reduction
loses digits if done naively; libm's for arguments beyond its range, inf and NaN."""

from __future__ import annotations

import ctypes
import re

import mpmath
import numpy as np
import pytest
import symengine as se

from jourdain.numeric import ccode, toolchain


def _sincos_library(lean: bool):
    source = ("#define JD_LEAN 1\n" if lean else "") + ccode.HEADER + r"""
void jd_sincos_array(const double *x, long n, double *s, double *c) {
    jd_sincos_n(x, (int)n, s, c);
}
"""
    lib = toolchain.build(toolchain.content_key("sincos-test", source), source)
    lib.jd_sincos_array.restype = None
    lib.jd_sincos_array.argtypes = [ctypes.c_void_p, ctypes.c_long, ctypes.c_void_p,
                                    ctypes.c_void_p]

    def run(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        x = np.ascontiguousarray(x, dtype=float)
        s, c = np.empty_like(x), np.empty_like(x)
        lib.jd_sincos_array(x.ctypes.data, len(x), s.ctypes.data, c.ctypes.data)
        return s, c

    return run


@pytest.fixture(scope="module")
def sincos():
    return _sincos_library(lean=False)


def _ulp_errors(x: np.ndarray, got: np.ndarray, fn) -> np.ndarray:
    """|got − fn(x)| in units of the last place of the exact value (mpmath, 200 bits)."""
    with mpmath.workprec(200):
        out = np.empty(len(x))
        for i, (xi, gi) in enumerate(zip(x, got, strict=True)):
            ref = fn(mpmath.mpf(float(xi)))
            out[i] = float(abs(mpmath.mpf(float(gi)) - ref) / np.spacing(abs(float(ref))))
    return out


def test_within_one_ulp_of_the_exact_values(sincos):
    rng = np.random.default_rng(7)
    k = rng.integers(-600_000, 600_000, 300)
    near = k * (np.pi / 2)  # the doubles closest to multiples of π/2: heavy cancellation
    x = np.concatenate([
        rng.uniform(-4.0, 4.0, 1500),           # angles of a mechanism
        rng.uniform(-1.0e6, 1.0e6, 500),        # angles of a rotor after many turns
        10.0 ** rng.uniform(-300, 0, 200) * rng.choice([-1.0, 1.0], 200),
        near, np.nextafter(near, np.inf), np.nextafter(near, -np.inf),
        [np.pi, -np.pi, np.pi / 2, np.pi / 4, 3 * np.pi / 4, 1.0e6, -1.0e6, 5e-324, 1e-8],
    ])
    s, c = sincos(x)
    es, ec = _ulp_errors(x, s, mpmath.sin), _ulp_errors(x, c, mpmath.cos)
    assert es.max() < 1.0, f"sin({x[es.argmax()]!r}) is {es.max():.2f} ulp off"
    assert ec.max() < 1.0, f"cos({x[ec.argmax()]!r}) is {ec.max():.2f} ulp off"


def test_zero_infinity_nan_and_large_arguments(sincos):
    x = np.array([0.0, -0.0, np.inf, -np.inf, np.nan, 1.0e6 + 1.0, -3.0e7, 1.0e300])
    s, c = sincos(x)
    assert s[0] == 0.0 and not np.signbit(s[0]) and c[0] == 1.0
    assert s[1] == 0.0 and np.signbit(s[1]) and c[1] == 1.0  # sin(−0) = −0
    assert np.isnan(s[2:5]).all() and np.isnan(c[2:5]).all()
    big = x[5:]  # beyond the reduction's range: libm's own values
    es, ec = _ulp_errors(big, s[5:], mpmath.sin), _ulp_errors(big, c[5:], mpmath.cos)
    assert es.max() < 1.0 and ec.max() < 1.0


def test_generated_code_takes_every_pair_in_one_call():
    """sin/cos of coordinates, parameters and their sums and differences: one jd_sincos_n call
    at the top of the function, no libm call per pair."""
    q1, q2, a = se.symbols("q1 q2 a")
    names = {"q1": "y[0]", "q2": "y[1]", "a": "p[0]"}
    src = ccode.function_source("jd_fn", [se.sin(q1 - q2) * se.cos(a), se.cos(q1 + q2),
                                          se.sin(q1 * q2)], names)
    assert src.count("jd_sincos_n(") == 1
    assert sorted(re.findall(r"jd_a\[\d\] = (\w+\[\d\]);", src)) == ["p[0]", "y[0]", "y[1]"]
    assert "sin(y[" not in src and "cos(y[" not in src
    assert "sin((y[0]*y[1]))" in src  # a product's sine stays a libm call


def test_lean_code_gives_the_same_numbers_bit_for_bit(sincos):
    """JD_LEAN (lambdify's lean: the loop not vectorized, a shorter compile) computes the
    same operations in the same order: every sine and cosine equal to the bit to those of the
    vectorized loop, next to multiples of π/2, tiny, large, beyond the range, inf and NaN."""
    rng = np.random.default_rng(11)
    k = np.arange(-40, 41) * (np.pi / 2)
    x = np.concatenate([rng.uniform(-4, 4, 4001), rng.uniform(-1e6, 1e6, 2001),
                        k, np.nextafter(k, np.inf), np.nextafter(k, -np.inf),
                        [0.0, -0.0, 1e-300, -5e-324, 1e-8, 2e6, -3e7, np.inf, -np.inf,
                         np.nan]])
    lean = _sincos_library(lean=True)
    (s1, c1), (s2, c2) = sincos(x), lean(x)
    assert s1.tobytes() == s2.tobytes() and c1.tobytes() == c2.tobytes()
