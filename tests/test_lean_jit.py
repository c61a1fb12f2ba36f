"""Lean functions (``lambdify(lean=True)``: energies, positions, poses, joint wrenches along a
motion) compiled in-process by SymEngine's LLVM backend and kept on disk.

References: the same matrices compiled as C by the project's compiler (``lean=False``) and
SymEngine's interpreter (``backend="lambda"``, no compilation) at random states."""

import numpy as np
import pytest
import symengine as se

import jourdain as jd
from jourdain import numeric
from jourdain.models import spatial_chain
from jourdain.numeric import compiled as comp
from jourdain.numeric.functions import CompiledFunction, JitFunction
from jourdain.symbolic import SymMatrix

pytestmark = pytest.mark.skipif(
    comp._jit(spatial_chain(1), ("a",), ((1, 1),), [se.Integer(1)], "probe") is None,
    reason="this SymEngine has no LLVM backend")


def _states(system, n, seed):
    rng = np.random.default_rng(seed)
    f = system.f
    return (rng.uniform(-3, 3, (n, f)), rng.uniform(-2, 2, (n, f)), rng.uniform(0, 5, n),
            np.array(list(system.parameter_values.values())))


def _eom(system):
    from jourdain.stages.kinematics import kinematics
    from jourdain.stages.newton_euler import newton_euler
    from jourdain.stages.projection import projection
    return projection(newton_euler(kinematics(system)))


def test_lean_function_by_llvm_equals_c_and_the_interpreter(cache):
    """M and k of a spatial chain (f = 9) as a lean function: LLVM's batch over 200 states
    equals the C library's and SymEngine's interpreter's to round-off of the largest entry; a
    second lambdify reads the kept function from disk (no LLVM compile) and gives the same
    numbers to the bit, and one state through ``__call__`` equals its row of the batch."""
    system = spatial_chain(3)
    eom = _eom(system)
    exprs = {"M": eom.M, "k": eom.k}
    lean = comp.lambdify(system, exprs, lean=True)
    c = comp.lambdify(system, exprs)
    assert isinstance(lean, JitFunction) and not isinstance(c, JitFunction)
    assert isinstance(c, CompiledFunction)
    Y, YD, t, p = _states(system, 200, 1)
    a, b = lean.batch(Y, YD, t, p), c.batch(Y, YD, t, p)
    flat = [e for m in exprs.values() for e in m.entries()]
    ref = se.Lambdify(list(comp.arguments(system)), flat, backend="lambda", real=True)
    X = np.concatenate([Y, YD, t[:, None], np.broadcast_to(p, (200, p.size))], axis=1)
    r = np.asarray(ref(X), dtype=float).reshape(200, -1)
    for name in exprs:
        scale = max(1.0, float(np.abs(b[name]).max()))
        # evaluation orders differ (CSE, fused sums): round-off of a few hundred operations
        tol = 1e3 * np.finfo(float).eps * scale
        assert np.abs(a[name] - b[name]).max() <= tol, name
    assert np.abs(np.concatenate([a[n].reshape(200, -1) for n in exprs], axis=1) - r).max() \
        <= 1e3 * np.finfo(float).eps * max(1.0, float(np.abs(r).max()))
    kept = list((cache).glob("*.llvm"))
    assert len(kept) == 1
    # read back from disk: no LLVM compile
    numeric.clear_cache()
    calls = []
    real = se.Lambdify

    def counting(*args, **kw):
        calls.append(kw.get("backend"))
        return real(*args, **kw)

    comp.se.Lambdify = counting
    try:
        again = comp.lambdify(system, exprs, lean=True)
    finally:
        comp.se.Lambdify = real
    assert "llvm" not in calls
    for name in exprs:
        assert np.array_equal(again.batch(Y, YD, t, p)[name], a[name])
    # no states: an empty batch (a motion that failed at its start)
    assert again.batch(Y[:0], YD[:0], t[:0], p)["M"].shape == (0, system.f, system.f)
    # a single state through __call__ equals the batch's row
    one = lean(Y[7], YD[7], t[7], p, np.zeros(0))
    for name in exprs:
        assert np.array_equal(one[name], a[name][7])


def test_kept_function_is_keyed_by_its_arguments(cache):
    """Two systems whose lean functions print to the same C (the C reads only the parameters it
    uses) but take different argument lists get two kept functions, each called with its own
    arguments."""
    x = jd.symbols("x")

    def pendulum(extra):
        body = jd.Body("m", "world", jd.Prismatic("s", x, "x"), mass=1.0,
                       inertia=jd.point_mass())
        return jd.System([x], [body], [], parameters={"k": 2.0, **extra})

    s1, s2 = pendulum({}), pendulum({"c": 0.5, "d": 1.5})
    e = {"v": SymMatrix.column([se.Symbol("k") * x ** 2])}
    f1, f2 = comp.lambdify(s1, e, lean=True), comp.lambdify(s2, e, lean=True)
    assert f1.key != f2.key
    Y = np.array([[0.5], [2.0]])
    np.testing.assert_allclose(f1.batch(Y, Y, 0.0, [2.0])["v"][:, 0, 0], 2.0 * Y[:, 0] ** 2)
    np.testing.assert_allclose(f2.batch(Y, Y, 0.0, [2.0, 0.5, 1.5])["v"][:, 0, 0],
                               2.0 * Y[:, 0] ** 2)


def test_large_lean_function_is_compiled_c(cache, monkeypatch):
    """Above JIT_MAX_NODES the lean function is C from the compiler (JD_LEAN), not LLVM."""
    system = spatial_chain(2)
    eom = _eom(system)
    monkeypatch.setattr(comp, "JIT_MAX_NODES", 10)
    fn = comp.lambdify(system, {"M": eom.M}, lean=True)
    assert not isinstance(fn, JitFunction)
    assert "#define JD_LEAN 1" in fn.lib_source()
