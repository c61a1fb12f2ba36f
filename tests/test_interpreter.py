"""The first run interpreted while the model compiles (numeric/interpreter.py): the interpreter
reads the generated C and must give the compiled library's numbers to the bit (M, k, q, ÿ, the
solve's failures, whole motions), switch to the library once built, and give up (the caller
then compiles) on what it cannot read exactly."""

from __future__ import annotations

import ctypes
import time

import numpy as np
import pytest
import symengine as se

import jourdain as jd
from jourdain.models import n_link_pendulum_on_cart, spatial_chain
from jourdain.numeric import compiled, first_run, parameter_vector, toolchain
from jourdain.numeric.ccode import HEADER, argument_names, function_source
from jourdain.numeric.integrator_c import integrator_library
from jourdain.numeric.interpreter import (
    FirstFunction,
    Interpreted,
    Unreadable,
    program,
)
from jourdain.numeric.toolchain import build, content_key


@pytest.fixture
def fresh_cache(tmp_path, monkeypatch):
    """An empty library cache (the prebuilt integrator still found), nothing memoized."""
    monkeypatch.setenv("JOURDAIN_CACHE", str(tmp_path))
    monkeypatch.setattr(toolchain, "_loaded", {})  # libraries loaded by earlier tests
    compiled.clear_cache()
    yield tmp_path
    compiled.clear_cache()


def _wait(fn: FirstFunction, limit: float = 300.0) -> None:
    t0 = time.monotonic()
    while not fn.compiled and time.monotonic() - t0 < limit:
        time.sleep(0.02)
    assert fn.compiled, "the model's library was not built in the background"


def _states(f: int, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    return rng.uniform(-3, 3, (n, f)), rng.uniform(-5, 5, (n, f))


@pytest.mark.parametrize("model", [n_link_pendulum_on_cart(1), n_link_pendulum_on_cart(4),
                                   n_link_pendulum_on_cart(11), spatial_chain(2)],
                         ids=["cart1", "cart4", "cart11", "chain2"])
def test_first_run_is_the_compiled_run_to_the_bit(fresh_cache, model):
    """f = 2 and 5 (the written-out solve), 12 (the solve's loop) and a spatial chain: the
    interpreted first run and the compiled run after it agree to the bit, in the motion, in
    ÿ and in M, k, q at random states."""
    first = first_run.run_function(model)
    assert isinstance(first, FirstFunction)
    f = model.f
    y0, yd0 = np.linspace(0.1, 0.5, f), np.linspace(-0.3, 0.2, f)
    inputs = {u: 0.25 for u in model.input_names}
    r1 = model.simulate((0.0, 1.5), y0, yd0, inputs=inputs)
    _wait(first)
    final = first_run.run_function(model)
    assert final is first.compiled[0] and not isinstance(final, FirstFunction)
    r2 = model.simulate((0.0, 1.5), y0, yd0, inputs=inputs)
    assert r1.t.size > 20
    for a, b in ((r1.t, r2.t), (r1.y, r2.y), (r1.yd, r2.yd), (r1.ydd, r2.ydd)):
        assert np.array_equal(a, b)
    Y, YD = _states(f, 50, 3)
    p, u = parameter_vector(model, None), np.full(len(model.inputs), 0.7)
    a, b = first.batch(Y, YD, 0.4, p, u), final.batch(Y, YD, 0.4, p, u)
    assert all(np.array_equal(a[k], b[k]) for k in ("M", "k", "q"))
    # M symmetric, as the compiled jd_fn writes it (the mirrors copied)
    assert np.array_equal(a["M"], np.swapaxes(a["M"], 1, 2))


def _accel(fn, model, y, yd, u):
    """ÿ, the power and the status of the integrator's right-hand side of ``fn``."""
    f = model.f
    ydd, power = np.empty(f), np.empty(1)
    p = parameter_vector(model, None)
    args = (y.ctypes.data, yd.ctypes.data, ctypes.c_double(0.2), p.ctypes.data,
            u.ctypes.data, ydd.ctypes.data, power.ctypes.data)
    if fn.ctx_address is not None:
        proto = ctypes.CFUNCTYPE(ctypes.c_int, *([ctypes.c_void_p] * 3), ctypes.c_double,
                                 *([ctypes.c_void_p] * 4))
        status = proto(fn.accel_ctx_address)(fn.ctx_address, *args)
    else:
        proto = ctypes.CFUNCTYPE(ctypes.c_int, *([ctypes.c_void_p] * 2), ctypes.c_double,
                                 *([ctypes.c_void_p] * 4))
        status = proto(fn.accel_address)(*args)
    return ydd, power[0], status


@pytest.mark.parametrize("n", [3, 10])
def test_right_hand_side_and_its_failures_to_the_bit(fresh_cache, n):
    """The integrator's ÿ and power at random states, and the solve's verdicts: 1 where M is
    not positive definite (a negative mass), 2 where a state is NaN, as the compiled one."""
    model = n_link_pendulum_on_cart(n)
    first = first_run.run_function(model)
    final = compiled.mkq_function(model)
    assert isinstance(first, FirstFunction) and not isinstance(final, FirstFunction)
    Y, YD = _states(model.f, 40, 7)
    u = np.array([0.3])
    for y, yd in zip(Y, YD, strict=True):
        a, b = _accel(first, model, y, yd, u), _accel(final, model, y, yd, u)
        assert a[2] == b[2] == 0
        assert np.array_equal(a[0], b[0]) and a[1] == b[1]
    y = Y[0].copy()
    y[1] = np.nan
    assert _accel(first, model, y, YD[0], u)[2] == _accel(final, model, y, YD[0], u)[2] == 2


def test_a_non_physical_mass_matrix_fails_alike(fresh_cache):
    """A negative link mass: M is not positive definite; both say 1, or both give the same ÿ."""
    model = n_link_pendulum_on_cart(4)
    first = first_run.run_function(model)
    final = compiled.mkq_function(model)
    Y, YD = _states(model.f, 30, 11)
    names = [k for k, _ in model.parameters]
    p = parameter_vector(model, None)
    p[names.index(next(k for k in names if k.startswith("m")))] = -5.0
    u = np.array([0.0])
    verdicts = set()
    for y, yd in zip(Y, YD, strict=True):
        out = []
        for fn in (first, final):
            ydd, power = np.empty(model.f), np.empty(1)
            args = (y.ctypes.data, yd.ctypes.data, ctypes.c_double(0.0), p.ctypes.data,
                    u.ctypes.data, ydd.ctypes.data, power.ctypes.data)
            if fn.ctx_address is not None:
                st = ctypes.CFUNCTYPE(ctypes.c_int, *([ctypes.c_void_p] * 3), ctypes.c_double,
                                      *([ctypes.c_void_p] * 4))(fn.accel_ctx_address)(
                    fn.ctx_address, *args)
            else:
                st = ctypes.CFUNCTYPE(ctypes.c_int, *([ctypes.c_void_p] * 2), ctypes.c_double,
                                      *([ctypes.c_void_p] * 4))(fn.accel_address)(*args)
            out.append((st, ydd.tobytes() if st == 0 else b""))
        assert out[0] == out[1]
        verdicts.add(out[0][0])
    assert 1 in verdicts


def _compiled_and_interpreted(exprs, syms, n_sym):
    """``exprs`` (the first n_sym² a symmetric matrix) as the generated jd_fn, compiled and
    read by the interpreter."""
    y, yd, t, p, u = syms
    names = argument_names(y, yd, t, p, u)
    body = function_source("jd_fn", exprs, names, whole=True, symmetric=n_sym)
    source = HEADER + body
    lib = build(content_key("interpreter-test", source), source)
    lib.jd_fn.argtypes = [ctypes.c_void_p] * 2 + [ctypes.c_double] + [ctypes.c_void_p] * 3
    prog = program(source, "jd_fn", len(y), len(p), len(u), len(exprs))
    return lib, Interpreted(prog, True)


def test_every_construct_of_the_generated_code_to_the_bit(fresh_cache):
    """Functions, powers, signs, quotients, sums of angles, negative and rational constants,
    repeated outputs: jd_fn compiled and interpreted at random arguments, bit for bit."""
    y = se.symbols("q0 q1 q2")
    yd = se.symbols("w0 w1 w2")
    t = se.Symbol("t")
    p = se.symbols("a b")
    u = (se.Symbol("F"),)
    a, b = p
    q0, q1, q2 = y
    m01 = a * se.cos(q0 - q1) + se.Rational(3, 7) * b
    exprs = [a + b * se.sin(q0) ** 2, m01, m01, se.sqrt(a) * se.cos(q0 + q1 - q2) + 2,
             se.exp(yd[0] * t) - se.log(a) / b, se.atan2(q1, q2) * se.Abs(yd[1]) ** se.Rational(3, 2),
             (q0 ** -3) * se.sign(yd[2]) - 2.5 * q1 ** 5 + 1 / se.sqrt(b + q2 ** 2),
             se.Max(q0, q1, yd[0]) * se.Min(u[0], t) + se.tanh(q2) * se.atan(q1) * -1,
             se.floor(q0) + se.ceiling(yd[1]) + se.erf(q2) + se.sinh(q0) * se.cosh(q1) + se.tan(q2)
             + se.asin(se.sin(q1) / 2) + se.acos(se.cos(q2) / 3) + se.asinh(q0)
             + se.acosh(2 + q1 ** 2) + se.atanh(se.tanh(q0) / 2) + se.sin(2 * q0) * se.cos(q1 / 3),
             -q0 * q1 * yd[2], se.Integer(0), se.Float(-0.0) + q2, se.sin(q0 - q1 - q2) ** 7]
    lib, interp = _compiled_and_interpreted(exprs, (y, yd, t, p, u), 2)
    il = integrator_library()
    rng = np.random.default_rng(5)
    for _ in range(200):
        Y, YD = rng.uniform(-2, 2, 3), rng.uniform(-2, 2, 3)
        P, U = rng.uniform(0.1, 3, 2), rng.uniform(-1, 1, 1)
        tt = float(rng.uniform(0, 2))
        ref, got = np.empty(len(exprs)), np.empty(len(exprs))
        args = (Y.ctypes.data, YD.ctypes.data, ctypes.c_double(tt), P.ctypes.data,
                U.ctypes.data)
        lib.jd_fn(*args, ref.ctypes.data)
        il.jd_interp_fn(interp.address, *args, got.ctypes.data)
        assert ref.tobytes() == got.tobytes()


@pytest.mark.parametrize("source, why", [
    ("static void jd_fn_upper(a) {\n    out[0] = sin(1.0);\n}\n\nvoid jd_fn(a) {\n}\n",
     "sin of a constant"),
    ("static void jd_fn_upper(a) {\n    out[0] = y[0] % 2.0;\n}\n\nvoid jd_fn(a) {\n}\n",
     "unknown characters"),
    ("static void jd_fn_upper(a) {\n    for (;;) x = 1;\n}\n\nvoid jd_fn(a) {\n}\n",
     "unknown statement"),
    ("static void jd_fn_upper(a) {\n    out[0] = y[7];\n}\n\nvoid jd_fn(a) {\n}\n",
     "out of range"),
    ("static void jd_fn_upper(a) {\n    out[0] = hypot(y[0], y[1]);\n}\n\nvoid jd_fn(a) {\n}\n",
     "unknown function"),
])
def test_what_the_reader_cannot_read_exactly_it_refuses(source, why):
    with pytest.raises(Unreadable, match=why):
        program(source, "jd_fn", 2, 0, 0, 1)


def test_c_precedence_and_folding():
    """``(-a*b)`` is (−a)·b, ``a - b*c`` is a − (b·c), ``(3.0/7.0)`` the exact quotient,
    ``-0.0`` and ``0.0`` two constants."""
    src = ("static void jd_fn_upper(a) {\n"
           "    const double x0 = (-y[0]*y[1]);\n"
           "    out[0] = x0 - y[0]*y[1] + (3.0/7.0);\n"
           "    out[1] = -0.0;\n    out[2] = 0.0;\n    out[3] = jd_powi(y[1], -3);\n"
           "}\n\nvoid jd_fn(a) {\n    jd_fn_upper(y, yd, t, p, u, out);\n}\n")
    prog = program(src, "jd_fn", 2, 0, 0, 4)
    interp = Interpreted(prog, True)
    il = integrator_library()
    y, z = np.array([0.1, 0.7]), np.zeros(2)
    out = np.empty(4)
    il.jd_interp_fn(interp.address, y.ctypes.data, z.ctypes.data, ctypes.c_double(0.0),
                    z.ctypes.data, z.ctypes.data, out.ctypes.data)
    assert out[0] == (-0.1) * 0.7 - 0.1 * 0.7 + 3.0 / 7.0
    assert np.signbit(out[1]) and not np.signbit(out[2])
    assert out[3] == 1.0 / (0.7 * (0.7 * 0.7))  # jd_powi's square-and-multiply


def test_an_unreadable_model_waits_for_the_compiler(fresh_cache, monkeypatch):
    """Where the reader gives up, the first run takes the compiled library, as before."""
    def refuse(*args, **kwargs):
        raise Unreadable("refused for the test")

    monkeypatch.setattr(first_run, "program", refuse)
    model = n_link_pendulum_on_cart(2)
    fn = first_run.run_function(model)
    assert not isinstance(fn, FirstFunction) and fn is compiled.mkq_function(model)


def test_a_cached_library_is_taken_at_once(fresh_cache):
    """With the library in the cache (another process built it), no interpreter."""
    model = n_link_pendulum_on_cart(3)
    compiled.mkq_function(model)
    compiled.clear_cache()
    assert not isinstance(first_run.run_function(model), FirstFunction)


@pytest.mark.parametrize("model", [jd.models.planar_chain(40), spatial_chain(8)],
                         ids=["planar", "spatial"])
def test_recursion_paths_run_first_on_their_build_at_O0(fresh_cache, monkeypatch, model):
    """Where its engine sized at run time is not taken (tests/test_runtime_engine.py), a model
    on a recursion runs first on its units compiled at -O0 (where no JOURDAIN_OPTIMIZE level is
    set) while the optimized library compiles: the same motion to the bit, then the
    library."""
    from jourdain.numeric.functions import ProvisionalFunction

    monkeypatch.setattr(first_run, "FIRST_RUN_RUNTIME", False)
    monkeypatch.setenv("JOURDAIN_OPTIMIZE", "1")  # a short compile already: no first build
    assert not isinstance(first_run.run_function(model), ProvisionalFunction)
    compiled.clear_cache()
    monkeypatch.setattr(toolchain, "_loaded", {})
    monkeypatch.setenv("JOURDAIN_CACHE", str(fresh_cache / "again"))
    monkeypatch.delenv("JOURDAIN_OPTIMIZE")
    first = first_run.run_function(model)
    assert isinstance(first, ProvisionalFunction) and not isinstance(first, FirstFunction)
    f = model.f
    y0, yd0 = np.linspace(-0.3, 0.3, f), np.linspace(0.2, -0.1, f)
    r1 = model.simulate((0.0, 0.5), y0, yd0)
    _wait(first)
    final = first_run.run_function(model)
    assert final is first.compiled[0] and final.key != first.key
    r2 = model.simulate((0.0, 0.5), y0, yd0)
    assert r1.t.size > 5 and r1.y.tobytes() == r2.y.tobytes()
    assert r1.ydd.tobytes() == r2.ydd.tobytes()



def test_a_child_forked_during_the_build_compiles_for_itself(fresh_cache):
    """The thread that builds is not in a forked child: there run_function takes the compiled
    library (built by the child or found on disk) and gives the first run's numbers."""
    import os
    import warnings

    model = n_link_pendulum_on_cart(2)
    first = first_run.run_function(model)
    assert isinstance(first, FirstFunction)
    y0, yd0 = np.array([0.0, 0.4, -0.2]), np.zeros(3)
    ref = model.simulate((0.0, 1.0), y0, yd0, inputs={"F": 0.0}).y[-1]
    read, write = os.pipe()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)  # fork with a thread running
        pid = os.fork()
    if pid == 0:  # the child: one line, then out without the parent's handlers
        code = 1
        try:
            fn = first_run.run_function(model)
            y = model.simulate((0.0, 1.0), y0, yd0, inputs={"F": 0.0}).y[-1]
            ok = not isinstance(fn, FirstFunction) and y.tobytes() == ref.tobytes()
            os.write(write, b"ok" if ok else b"bad")
            code = 0
        finally:
            os._exit(code)
    os.close(write)
    answer = os.read(read, 16)
    os.close(read)
    _, status = os.waitpid(pid, 0)
    assert answer == b"ok" and os.waitstatus_to_exitcode(status) == 0


def test_a_long_first_run_takes_the_library_when_it_is_built(fresh_cache):
    """The run's C loop returns every 1 024 steps; from the call after the build the problem
    takes the library's right-hand side. The whole motion is the compiled run's to the bit,
    and the problem then points at the library."""
    from jourdain.simulation.problem import _Setup

    model = n_link_pendulum_on_cart(4)
    first = first_run.run_function(model)
    assert isinstance(first, FirstFunction)
    y0, yd0 = np.array([0.0, 2.0, 2.2, 2.4, 2.6]), np.zeros(5)
    r1 = model.simulate((0.0, 60.0), y0, yd0, inputs={"F": 0.0})
    setup = _Setup(model, first, parameter_vector(model, None), {"F": 0.0}, (), 1, 1e-6,
                   np.full(11, 1e-6), np.inf, 0.0)
    assert setup.problem.accel is None and setup.problem.accel_ctx
    _wait(first)
    setup.take_compiled()
    assert setup.problem.accel == first.compiled[0].accel_address and setup.pending is None
    r2 = model.simulate((0.0, 60.0), y0, yd0, inputs={"F": 0.0})
    assert r1.nfev == r2.nfev and r1.t.size > 2 * 1024  # the loop returned twice at least
    assert r1.y.tobytes() == r2.y.tobytes() and r1.ydd.tobytes() == r2.ydd.tobytes()


def test_a_failed_build_is_reported_and_the_runs_go_on(fresh_cache, monkeypatch):
    """The thread's compiler fails: a run after it warns once, naming the model and the error,
    and runs stay interpreted, with the library's numbers (compared once it can be built)."""
    import warnings

    from jourdain.numeric.toolchain import CompilerError

    def broken(system):
        raise CompilerError("the compiler crashed (for the test)")

    model = n_link_pendulum_on_cart(2)
    y0, yd0 = np.array([0.0, 0.4, -0.2]), np.zeros(3)
    with monkeypatch.context() as mp, warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mp.setattr(first_run, "mkq_function", broken)
        first = first_run.run_function(model)
        assert isinstance(first, FirstFunction)
        t0 = time.monotonic()
        while not first.failed and time.monotonic() - t0 < 60:
            time.sleep(0.01)
        r1 = model.simulate((0.0, 1.0), y0, yd0, inputs={"F": 0.0})
        model.simulate((0.0, 1.0), y0, yd0, inputs={"F": 0.0})
    said = [str(w.message) for w in caught if issubclass(w.category, RuntimeWarning)]
    assert len(said) == 1 and "pendulum" in said[0] and "crashed" in said[0]
    assert "interpreted or compiled at -O0" in said[0]
    lib = compiled.mkq_function(model)
    assert not isinstance(lib, FirstFunction)
    Y, YD = _states(3, 20, 1)
    p = parameter_vector(model, None)
    a, b = first.batch(Y, YD, 0.0, p, [0.1]), lib.batch(Y, YD, 0.0, p, [0.1])
    assert all(np.array_equal(a[k], b[k]) for k in a) and np.isfinite(r1.y).all()
