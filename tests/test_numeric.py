"""Compiled evaluation (generated C): against SymEngine's own evaluator, batched against
single-state calls, the on-disk cache, and bad input."""

import numpy as np
import pytest
import symengine as se

import jourdain as jd
from jourdain import numeric
from jourdain.models import n_link_pendulum_on_cart, spatial_chain
from jourdain.numeric import ccode
from jourdain.numeric import toolchain as build
from jourdain.symbolic import SymMatrix


def _reference(system, exprs, y, yd, t, p, u):
    """SymEngine's own (non-compiled) evaluator on the same expressions."""
    args = list(numeric.arguments(system))
    fn = se.Lambdify(args, exprs, backend="lambda", cse=False, real=True)
    return np.asarray(fn(np.concatenate([y, yd, [t], p, u])), dtype=float).reshape(-1)


@pytest.mark.parametrize("model", [lambda: n_link_pendulum_on_cart(3), lambda: spatial_chain(3)])
def test_generated_code_against_symengine(model, rng):
    s = model()
    eom = s.equations_of_motion()
    fn = numeric.lambdify(s, {"M": eom.M, "k": eom.k, "q": eom.q})
    exprs = [*eom.M.entries(), *eom.k.entries(), *eom.q.entries()]
    p0 = numeric.parameter_vector(s, None)
    for _ in range(3):
        y, yd = rng.uniform(-2, 2, s.f), rng.uniform(-2, 2, s.f)
        p = p0 * rng.uniform(0.5, 1.5, p0.size)  # new parameter values, same library
        u = rng.uniform(-1, 1, len(s.inputs))
        got = fn(y, yd, 0.3, p, u)
        flat = np.concatenate([got["M"].ravel(), got["k"].ravel(), got["q"].ravel()])
        np.testing.assert_allclose(flat, _reference(s, exprs, y, yd, 0.3, p, u), rtol=1e-12,
                                   atol=1e-12)


def test_sign_flipped_subexpressions_stay_distinct():
    """SymEngine's hash of a sum ignores its overall sign (hash(a-b) == hash(b-a)); the graph
    CSE must not merge such nodes, also deep inside products."""
    x, y, c = se.symbols("x y c")
    assert hash(x - y) == hash(y - x)  # the trap this test is about
    exprs = [x - y, y - x, (x - y) * c, (y - x) * c, se.sin((x - y) * c) + se.cos((y - x) * c)]
    names = {"x": "y[0]", "y": "y[1]", "c": "p[0]"}
    src = ccode.HEADER + ccode.function_source("jd_fn", exprs, names)
    lib = build.build(build.content_key("test-sign", src), src)
    import ctypes

    out = np.zeros(5)
    yv, ydv, pv, uv = np.array([2.0, 0.5]), np.zeros(2), np.array([3.0]), np.zeros(1)
    lib.jd_fn.argtypes = [ctypes.c_void_p] * 2 + [ctypes.c_double] + [ctypes.c_void_p] * 3
    lib.jd_fn(yv.ctypes.data, ydv.ctypes.data, 0.0, pv.ctypes.data, uv.ctypes.data,
              out.ctypes.data)
    np.testing.assert_allclose(out, [1.5, -1.5, 4.5, -4.5, np.sin(4.5) + np.cos(-4.5)],
                               rtol=1e-15)


def test_large_functions_are_split_into_parts(monkeypatch, rng):
    """Above SPLIT_ABOVE temporaries the body is split into parts sharing an array; the
    numbers are the same."""
    s = spatial_chain(3)
    eom = s.equations_of_motion()
    mats = {"M": eom.M, "k": eom.k}
    whole = numeric.lambdify(s, mats)
    monkeypatch.setattr(ccode, "SPLIT_ABOVE", 5)
    monkeypatch.setattr(ccode, "PART", 7)
    monkeypatch.setattr(numeric.compiled, "_GENERATOR_VERSION", "split-test")  # a new cache key
    parts = numeric.lambdify(s, mats)
    assert parts.key != whole.key
    assert "_part3(" in (numeric.cache_dir() / f"{parts.key}.c").read_text()
    p = numeric.parameter_vector(s, None)
    Y, YD = rng.uniform(-2, 2, (5, s.f)), rng.uniform(-2, 2, (5, s.f))
    a, b = whole.batch(Y, YD, 0.0, p), parts.batch(Y, YD, 0.0, p)
    np.testing.assert_allclose(b["M"], a["M"], rtol=1e-13, atol=1e-14)
    np.testing.assert_allclose(b["k"], a["k"], rtol=1e-13, atol=1e-14)


def test_batch_equals_single_state(rng):
    s = n_link_pendulum_on_cart(4)
    fn = numeric.mkq_function(s)
    n = 50
    Y, YD = rng.uniform(-3, 3, (n, s.f)), rng.uniform(-3, 3, (n, s.f))
    T = rng.uniform(0, 1, n)
    P = numeric.parameter_vector(s, None) * rng.uniform(0.5, 2, (n, 1))  # per-state parameters
    U = rng.uniform(-5, 5, (n, 1))
    batch = fn.batch(Y, YD, T, P, U)
    for i in range(n):
        one = fn(Y[i], YD[i], T[i], P[i], U[i])
        for name in ("M", "k", "q"):
            np.testing.assert_array_equal(batch[name][i], one[name])
    shared = fn.batch(Y, YD, 0.0, P[0], U[0])
    np.testing.assert_array_equal(shared["M"][7], fn(Y[7], YD[7], 0.0, P[0], U[0])["M"])


def test_cache_is_keyed_by_content_and_safe_to_delete(cache, monkeypatch):
    s = n_link_pendulum_on_cart(2)
    fn = numeric.mkq_function(s)
    files = sorted(p.name for p in cache.iterdir())
    assert f"{fn.key}.so" in files and f"{fn.key}.c" in files
    # a later session finds the library without compiling again
    numeric.clear_cache()
    build._loaded.clear()

    def no_compiler(*a, **k):
        raise AssertionError("compiled again although the library is cached")

    monkeypatch.setattr(build.subprocess, "run", no_compiler)
    fn2 = numeric.mkq_function(s)
    assert fn2.key == fn.key
    # a different model gets a different key; deleting the cache forces a rebuild
    monkeypatch.undo()
    monkeypatch.setenv("JOURDAIN_CACHE", str(cache))
    assert numeric.mkq_function(n_link_pendulum_on_cart(3)).key != fn.key
    numeric.clear_cache(disk=True)
    build._loaded.clear()
    assert not any(cache.iterdir())
    fn3 = numeric.mkq_function(s)
    y = np.full(s.f, 0.4)
    np.testing.assert_array_equal(fn3(y, y, 0, numeric.parameter_vector(s, None), [0.0])["M"],
                                  fn(y, y, 0, numeric.parameter_vector(s, None), [0.0])["M"])


def test_threads_building_one_library_compile_it_once(cache, monkeypatch):
    """Threads asking for the same library at once (a study's threads, a background build and
    the simulation waiting for it): one compiles, the others wait and load that library."""
    import threading

    compiles: list[str] = []
    real = build.compile_shared

    def counted(sources, units, out, flags, unit_flags=None):  # noqa: ANN001, ANN202
        compiles.append(out.name)
        return real(sources, units, out, flags, unit_flags)

    monkeypatch.setattr(build, "compile_shared", counted)
    src = "double jd_twice(double x) { return 2.0 * x; }\n"
    key = build.content_key("test-threads", src)
    barrier = threading.Barrier(4)
    libs: list[object] = []

    def ask() -> None:
        barrier.wait()
        libs.append(build.build(key, src))

    threads = [threading.Thread(target=ask) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert compiles == [f"{key}.so"] and len(libs) == 4
    assert all(lib is libs[0] for lib in libs)


def test_models_that_differ_in_a_sign_get_their_own_code(cache):
    """SymEngine hashes k*(x - x0) and k*(x0 - x) alike; the cache must not mix them up (a
    user flipping a sign in a model must not get the old library)."""
    x, k, x0 = se.symbols("x k x0")
    body = jd.Body("slider", "world", jd.Prismatic("rail", x, "x"), mass=1.0,
                   inertia=jd.point_mass())
    pull = {"k": 3.0, "x0": 0.5}
    a = jd.System([x], [body], [jd.GeneralizedForce("spring", x, -k * (x - x0))], parameters=pull)
    b = jd.System([x], [body], [jd.GeneralizedForce("spring", x, -k * (x0 - x))], parameters=pull)
    assert hash(a.equations_of_motion().q[0]) == hash(b.equations_of_motion().q[0])
    qa = a.evaluate([2.0], [0.0])["q"]
    qb = b.evaluate([2.0], [0.0])["q"]
    np.testing.assert_allclose(qa, [-4.5])
    np.testing.assert_allclose(qb, [4.5])


def test_evaluate_errors():
    s = n_link_pendulum_on_cart(2)
    with pytest.raises(jd.EvaluationError, match="NaN"):
        s.evaluate([0, np.nan, 0], [0, 0, 0], inputs={"F": 0})
    with pytest.raises(jd.EvaluationError, match="inputs contain NaN"):
        s.evaluate([0, 0, 0], [0, 0, 0], inputs={"F": float("nan")})
    with pytest.raises(jd.EvaluationError, match="3 entries"):
        s.evaluate([0, 0], [0, 0, 0], inputs={"F": 0})
    with pytest.raises(jd.EvaluationError, match='unknown parameter'):
        s.evaluate([0, 0, 0], [0, 0, 0], parameters={"mass": 1}, inputs={"F": 0})
    fn = numeric.mkq_function(s)
    with pytest.raises(jd.EvaluationError, match="shape"):
        fn.batch(np.zeros((4, 3)), np.zeros((4, 2)))
    z = se.Symbol("zeta")
    with pytest.raises(jd.EvaluationError, match='"zeta"'):
        numeric.lambdify(s, {"bad": SymMatrix.column([z * s.y[0]])})


def test_without_a_compiler_evaluation_falls_back(monkeypatch, rng):
    """No cc: SymEngine's Lambdify gives the same numbers (slower); simulation says it needs a
    compiler."""
    s = n_link_pendulum_on_cart(2)
    eom = s.equations_of_motion()
    compiled = numeric.lambdify(s, {"M": eom.M, "k": eom.k})
    monkeypatch.setenv("CC", "no-such-compiler-jourdain")
    with pytest.warns(RuntimeWarning, match="no C compiler"):
        interp = numeric.lambdify(s, {"M": eom.M, "k": eom.k})
    assert isinstance(interp, numeric.InterpretedFunction)
    p = numeric.parameter_vector(s, None)
    Y, YD = rng.uniform(-2, 2, (4, s.f)), rng.uniform(-2, 2, (4, s.f))
    a, b = compiled.batch(Y, YD, 0.0, p, [1.0]), interp.batch(Y, YD, 0.0, p, [1.0])
    np.testing.assert_allclose(b["M"], a["M"], rtol=1e-12, atol=1e-13)
    np.testing.assert_allclose(b["k"], a["k"], rtol=1e-12, atol=1e-13)
    with pytest.raises(build.CompilerError, match="needs a C compiler"):
        _ = interp.address
