"""The recursions' first runs on their engines sized at run time (numeric/runtime_engine.py):
nothing compiled before the first number, and the compiled library's numbers to the bit (M, k,
q, ÿ, the power and the verdicts of the right-hand side, whole motions), planar and spatial,
with and without the articulated bodies; where the per-joint code cannot be read, the -O0
build as before."""

from __future__ import annotations

import ctypes

import numpy as np
import pytest

import jourdain as jd
from jourdain.models import n_link_pendulum_on_cart, spatial_chain
from jourdain.numeric import compiled, first_run, parameter_vector, toolchain
from jourdain.numeric.functions import ProvisionalFunction
from jourdain.numeric.integrator_c import integrator_library
from jourdain.numeric.interpreter import Unreadable
from jourdain.numeric.runtime_engine import RuntimeFunction, runtime_function


@pytest.fixture
def fresh_cache(tmp_path, monkeypatch):
    """An empty library cache (the integrator's library at hand), nothing memoized; the model's background build held back: ``jobs`` gets it, ``compiles`` the
    compiler's runs from then on."""
    monkeypatch.setenv("JOURDAIN_CACHE", str(tmp_path))
    monkeypatch.setattr(toolchain, "_loaded", {})
    compiled.clear_cache()
    integrator_library()  # at hand before the spy (prebuilt at install; in the tests built once)
    jobs: list = []
    compiles: list = []
    real = toolchain._compile
    monkeypatch.setattr(first_run, "build_soon", lambda fn, *a, **k: jobs.append((fn, a)))
    monkeypatch.setattr(toolchain, "_compile", lambda *a, **k: compiles.append(a) or real(*a, **k))
    yield jobs, compiles
    compiled.clear_cache()


def _states(f: int, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    return rng.uniform(-3, 3, (n, f)), rng.uniform(-5, 5, (n, f))


def _accel(fn, model, y, yd, u, p=None):
    """ÿ, the power and the status of the integrator's right-hand side of ``fn``."""
    f = model.f
    ydd, power = np.empty(f), np.empty(1)
    p = parameter_vector(model, None) if p is None else p
    args = (y.ctypes.data, yd.ctypes.data, ctypes.c_double(0.2), p.ctypes.data,
            u.ctypes.data, ydd.ctypes.data, power.ctypes.data)
    vp = ctypes.c_void_p
    if fn.ctx_address is not None:
        proto = ctypes.CFUNCTYPE(ctypes.c_int, vp, vp, vp, ctypes.c_double, vp, vp, vp, vp)
        status = proto(fn.accel_ctx_address)(fn.ctx_address, *args)
    else:
        proto = ctypes.CFUNCTYPE(ctypes.c_int, vp, vp, ctypes.c_double, vp, vp, vp, vp)
        status = proto(fn.accel_address)(*args)
    return ydd, power[0], status


def _same_at_states(first, final, model, seed: int = 5) -> None:
    """M, k, q of a batch, and ÿ, the power and the status at each state, to the bit."""
    Y, YD = _states(model.f, 12, seed)
    p, u = parameter_vector(model, None), np.full(len(model.inputs), 0.3)
    a, b = first.batch(Y, YD, 0.4, p, u), final.batch(Y, YD, 0.4, p, u)
    assert all(a[k].tobytes() == b[k].tobytes() for k in ("M", "k", "q"))
    for y, yd in zip(Y, YD, strict=True):
        r, s = _accel(first, model, y, yd, u), _accel(final, model, y, yd, u)
        assert r[2] == s[2] == 0 and r[0].tobytes() == s[0].tobytes() and r[1] == s[1]
    y = Y[0].copy()
    y[-1] = np.nan  # a failure: the same verdict (2, NaN; the articulated bodies say 1)
    r, s = _accel(first, model, y, YD[0], u), _accel(final, model, y, YD[0], u)
    assert r[2] == s[2] != 0


@pytest.mark.parametrize("model, aba", [
    (n_link_pendulum_on_cart(31), False),  # planar, coordinates shared: M, k, q, the loop
    (jd.models.planar_chain(12), True),    # planar, articulated bodies
    (spatial_chain(8), True),              # spatial: revolute, universal, spherical joints
], ids=["cart31", "planar12", "chain8"])
def test_first_run_compiles_nothing_and_is_the_library_to_the_bit(fresh_cache, model, aba):
    """The first run takes the engine sized at run time with no compiler run before its
    numbers; its motion and its M, k, q, ÿ at random states are the library's to the bit,
    and so is the key it names the library by."""
    jobs, compiles = fresh_cache
    first = first_run.run_function(model)
    assert isinstance(first, RuntimeFunction) and first.aba is aba
    f = model.f
    y0, yd0 = np.linspace(-0.3, 0.3, f), np.linspace(0.2, -0.1, f)
    inputs = {u: 0.25 for u in model.input_names}
    r1 = model.simulate((0.0, 0.4), y0, yd0, inputs=inputs)
    assert not compiles and len(jobs) == 1
    build, args = jobs[0]
    build(*args)  # the library, built here instead of in the thread
    final = first_run.run_function(model)
    assert final is first.compiled[0] and final.key == first.key
    r2 = model.simulate((0.0, 0.4), y0, yd0, inputs=inputs)
    assert r1.t.size > 5 and r1.t.tobytes() == r2.t.tobytes()
    assert r1.y.tobytes() == r2.y.tobytes() and r1.ydd.tobytes() == r2.ydd.tobytes()
    _same_at_states(first, final, model)


@pytest.mark.parametrize("planar", [True, False], ids=["planar", "spatial"])
def test_the_solves_without_articulated_bodies(fresh_cache, planar):
    """Coordinates shared between joints (the cart's absolute angles), on either engine: the
    planar library's solve written out (f = 5), the spatial one's loop of ldl_solve.h."""
    model = n_link_pendulum_on_cart(4)
    units = compiled.recursion_units(model, planar)
    final = (compiled.planar_function if planar else compiled.dynamics_function)(model)
    first = runtime_function(model, planar, units, final.key, compiled.arguments(model),
                             integrator_library())
    assert not first.aba and first.context.struct.written_out == planar
    _same_at_states(first, final, model, seed=11)


def test_a_non_physical_model_fails_alike(fresh_cache):
    """Negative masses: the articulated bodies' D not positive definite, 1 in both."""
    model = jd.models.planar_chain(3)
    final = compiled.planar_function(model)
    first = runtime_function(model, True, compiled.recursion_units(model, True), final.key,
                             compiled.arguments(model), integrator_library())
    p = -np.abs(parameter_vector(model, None))
    u = np.zeros(max(len(model.inputs), 1))
    verdicts = []
    for y, yd in zip(*_states(model.f, 10, 2), strict=True):
        r, s = _accel(first, model, y, yd, u, p), _accel(final, model, y, yd, u, p)
        assert r[2] == s[2] and (r[2] or r[0].tobytes() == s[0].tobytes())
        verdicts.append(r[2])
    assert 1 in verdicts


def test_what_it_cannot_read_runs_first_on_the_O0_build(fresh_cache, monkeypatch):
    """Per-joint code the interpreter does not read: the first run takes the -O0 build, as
    before (tests/test_interpreter.py runs it to the library's bits)."""
    jobs, compiles = fresh_cache

    def unreadable(*args, **kwargs):
        raise Unreadable("for the test")

    monkeypatch.setattr(first_run, "runtime_function", unreadable)
    monkeypatch.delenv("JOURDAIN_OPTIMIZE", raising=False)  # (which would take no -O0 build)
    model = jd.models.planar_chain(12)
    first = first_run.run_function(model)
    assert type(first) is ProvisionalFunction
    units = compiled.recursion_units(model, True)
    assert compiles and first.key != compiled.library_key(units, ((), compiled.ENGINE_FLAGS))
