"""Sums formed from the smaller sums they contain (jourdain.graph.shared_sums, used by the code
generator), and the integrator's M, k, q: one function, M's upper triangle for its solve."""

import ctypes
import math

import numpy as np
import symengine as se

from jourdain import numeric
from jourdain.graph import Graph, shared_sums
from jourdain.models import n_link_pendulum_on_cart
from jourdain.numeric import ccode, compiled
from jourdain.numeric import toolchain as build
from jourdain.simulation.problem import _Setup, integrator_library


def _run(src: str, n_out: int, y: np.ndarray, p: np.ndarray,
         yd: np.ndarray | None = None) -> np.ndarray:
    lib = build.build(build.content_key("test-shared-sums", src), src)
    lib.jd_fn.argtypes = [ctypes.c_void_p] * 2 + [ctypes.c_double] + [ctypes.c_void_p] * 3
    out = np.full(n_out, np.nan)
    yd = np.zeros(len(y)) if yd is None else yd
    u = np.zeros(1)
    lib.jd_fn(y.ctypes.data, yd.ctypes.data, 0.0, p.ctypes.data, u.ctypes.data,
              out.ctypes.data)
    return out


def _rounding_scale(e: se.Basic, values: dict[str, float], memo: dict) -> tuple[float, int]:
    """(Σ|terms| evaluated through the whole expression tree, the number of additions in it):
    any order of the additions leaves the result within additions·eps·Σ|terms| of the exact
    value (to first order), whatever order the code takes."""
    if e in memo:
        return memo[e]
    tn = type(e).__name__
    if tn == "Symbol":
        r = (abs(values[str(e)]), 0)
    elif e.is_Number:
        r = (abs(float(e)), 0)
    elif tn in ("sin", "cos"):
        r = (1.0, _rounding_scale(e.args[0], values, memo)[1] + 2)  # the addition theorem
    else:
        parts = [_rounding_scale(a, values, memo) for a in e.args]
        n = sum(c for _, c in parts)
        if tn == "Add":
            r = (sum(v for v, _ in parts), n + len(parts) - 1)
        elif tn == "Mul":
            r = (math.prod(v for v, _ in parts), n)
        elif tn == "Pow" and e.args[1].is_Integer:
            r = (parts[0][0] ** int(e.args[1]), n)
        else:
            raise AssertionError(f"no scale for {tn}")
    memo[e] = r
    return r


def test_nested_sums_are_built_on_each_other_with_exact_numbers():
    """Suffix sums S_k = x_k + … + x_7 (as a chain's sums over the bodies below each joint),
    one of them under a product and one with a parameter and a coefficient among its terms:
    each is formed from the next smaller one, 7 additions for the chain instead of 28, and on
    small integers (exact in double) every output equals Python's integer sum."""
    x = se.symbols("x0:8")
    a = se.Symbol("a")
    sums = [se.Add(*x[k:]) for k in range(7)]
    exprs = [*sums, a * sums[3], sums[5] + a + 2 * x[0], x[0] + x[1] + x[2] + x[7]]
    names = {f"x{i}": f"y[{i}]" for i in range(8)} | {"a": "p[0]"}
    g = Graph(exprs).merged()
    sub = shared_sums(g)
    ids = g.root_ids
    # each suffix sum of 3 or more terms builds on the next smaller one
    assert [sub.get(ids[k]) for k in range(7)] == [*ids[1:7], None]
    # S_5 + a + 2·x0 builds on S_5; x0 + x1 + x2 + x7 contains no other sum
    assert sub[ids[8]] == ids[5] and ids[9] not in sub
    src = ccode.HEADER + ccode.function_source("jd_fn", exprs, names)
    plain_src = ccode.HEADER + _unshared(exprs, names)
    body, plain_body = (s.split("void jd_fn_batch")[0] for s in (src, plain_src))
    assert body.count(" + ") < plain_body.count(" + ") - 15
    y = np.array([3.0, -7.0, 11.0, 2.0, -5.0, 13.0, 1.0, 4.0])
    p = np.array([-6.0])
    xi = [int(v) for v in y]
    want = [sum(xi[k:]) for k in range(7)]
    want += [-6 * want[3], want[5] - 6 + 2 * xi[0], xi[0] + xi[1] + xi[2] + xi[7]]
    for code in (src, plain_src):
        got = _run(code, len(exprs), y, p)
        assert got.tolist() == [float(w) for w in want]


def _unshared(exprs, names) -> str:
    old = ccode.SHARE_SUMS
    ccode.SHARE_SUMS = False
    try:
        return ccode.function_source("jd_fn", exprs, names)
    finally:
        ccode.SHARE_SUMS = old


def test_budget_bounds_the_search_and_the_result_is_a_function_of_it():
    """No work allowed: no sum is rewritten; the same budget: the same rewriting, every time."""
    x = se.symbols("x0:6")
    exprs = [se.Add(*x[k:]) for k in range(5)]
    g = Graph(exprs).merged()
    assert shared_sums(g, budget=0) == {}
    full = shared_sums(g)
    assert len(full) == 4
    assert shared_sums(Graph(exprs).merged()) == full
    # a growing budget rewrites more sums, smallest first, each as with no limit
    seen = [shared_sums(g, budget=b) for b in range(0, 200)]
    sizes = [len(r) for r in seen]
    assert sizes == sorted(sizes) and sizes[-1] == 4 and len(set(sizes)) == 5
    assert all(set(r.items()) <= set(full.items()) for r in seen)


def test_pendulum_code_has_fewer_additions_and_the_same_numbers():
    """The 12-link pendulum on a cart: its M, k, q with sums built on each other need far
    fewer additions, and agree with the term-by-term code to the rounding of the additions
    (each within additions·eps·Σ|terms| of the exact value, :func:`_rounding_scale`)."""
    s = n_link_pendulum_on_cart(12)
    eom = s.equations_of_motion()
    exprs = [*eom.M.entries(), *eom.k.entries(), *eom.q.entries()]
    names = ccode.argument_names(s.y, s.yd, s.t, s.parameter_symbols, s.inputs)
    shared = ccode.function_source("jd_fn", exprs, names, whole=True)
    plain = _unshared(exprs, names)
    n_shared, n_plain = (c.split("void jd_fn_batch")[0].count(" + ") for c in (shared, plain))
    assert n_shared < 0.6 * n_plain
    rng = np.random.default_rng(5)
    p = numeric.parameter_vector(s, None)
    names_p = [str(x) for x in s.parameter_symbols]
    for _ in range(3):
        y, yd = rng.uniform(-3, 3, s.f), rng.uniform(-2, 2, s.f)
        got = _run(ccode.HEADER + shared, len(exprs), y, p, yd)
        ref = _run(ccode.HEADER + plain, len(exprs), y, p, yd)
        values = dict(zip(map(str, s.y), y, strict=True)) | dict(
            zip(map(str, s.yd), yd, strict=True)) | dict(zip(names_p, p, strict=True))
        values["F"] = 0.0
        memo: dict = {}
        for i, e in enumerate(exprs):
            scale, adds = _rounding_scale(e, values, memo)
            assert abs(got[i] - ref[i]) <= 2 * adds * np.finfo(float).eps * scale, i
        assert not np.array_equal(got, ref)  # the sums did change their order


def test_integrator_mkq_is_one_function_and_its_solve_reads_the_upper_triangle(monkeypatch,
                                                                                 rng):
    """mkq_function's code is never split into parts (SPLIT_ABOVE forced down), jd_fn fills
    M's lower triangle with the upper one's numbers, and the integrator's right-hand side
    (jd_accel: LDLᵀ of the upper triangle that jd_fn_upper leaves) is ÿ = M⁻¹(q − k) to the
    solve's backward error (cond(M)·eps)."""
    monkeypatch.setattr(ccode, "SPLIT_ABOVE", 5)
    monkeypatch.setattr(compiled, "_GENERATOR_VERSION", "whole-test")  # a new cache key
    numeric.clear_cache()
    try:
        for n in (3, 12):  # the written-out solve (f ≤ 10) and the loop
            s = n_link_pendulum_on_cart(n)
            fn = numeric.mkq_function(s)
            src = (numeric.cache_dir() / f"{fn.key}.c").read_text()
            assert "_part0(" not in src and "jd_fn_upper(" in src
            p = numeric.parameter_vector(s, None)
            setup = _Setup(s, fn, p, {"F": 0.7}, (), 1, 1e-8, np.full(2 * s.f + 1, 1e-8),
                           math.inf, 0.0)
            lib = integrator_library()
            for _ in range(5):
                y, yd = rng.uniform(-3, 3, s.f), rng.uniform(-2, 2, s.f)
                out = fn(y, yd, 0.0, p, [0.7])
                M, k, q = out["M"], out["k"][:, 0], out["q"][:, 0]
                assert np.array_equal(M, M.T)
                x = np.concatenate([y, yd, [0.0]])
                dx, fail = np.empty_like(x), np.zeros(x.size + 1)
                assert lib.jd_rhs(ctypes.byref(setup.problem), 0.0, x.ctypes.data,
                                  dx.ctypes.data, fail.ctypes.data) == 0
                ydd = np.linalg.solve(M, q - k)
                bound = 10 * s.f * np.linalg.cond(M) * np.finfo(float).eps
                assert np.abs(dx[s.f:2 * s.f] - ydd).max() <= bound * np.abs(ydd).max()
                np.testing.assert_array_equal(dx[:s.f], yd)
    finally:
        numeric.clear_cache()
