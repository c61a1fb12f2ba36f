"""The integrator library in two translation units (numeric/integrator_c.py: UNITS): the step
loops at -O2, the kernels at -O3, compiled in parallel with flags of their own; the same numbers
as the whole source compiled as one unit; the kernels not exported; and the build started in a
thread ahead of the first simulation (``jourdain run``)."""

from __future__ import annotations

import ctypes
import math
import threading

import numpy as np
import pytest

from jourdain import numeric
from jourdain.models import n_link_pendulum_on_cart
from jourdain.numeric import integrator_c, toolchain
from jourdain.simulation import problem


@pytest.fixture
def fresh_cache(monkeypatch, tmp_path):
    monkeypatch.setenv("JOURDAIN_CACHE", str(tmp_path))
    monkeypatch.setattr(toolchain, "_loaded", {})  # libraries this process loaded before
    numeric.clear_cache()
    problem.integrator_library.cache_clear()
    yield tmp_path
    numeric.clear_cache()
    problem.integrator_library.cache_clear()


def test_each_unit_is_compiled_with_its_own_flags(fresh_cache):
    """Two units, one function each, returning a macro that only the unit's own flags define:
    each returns its own value (flags given to the wrong unit, or to none, would not compile
    or would swap them)."""
    units = ["int jd_a(void) { return VALUE; }\n", "int jd_b(void) { return VALUE; }\n"]
    key = toolchain.content_key("unit flags test", *units)
    lib = toolchain.build(key, units, unit_flags=[("-DVALUE=17",), ("-DVALUE=42",)])
    assert (lib.jd_a(), lib.jd_b()) == (17, 42)


def test_the_units_follow_their_table():
    """The kernels' unit defines JD_KERNELS (the definitions) and is the one at -O3; the step
    loops' unit declares the kernels and holds the entry points; the interpreter and the
    recursions sized at run time (planar, spatial) follow."""
    (main, main_flags), (kernels, kernel_flags), (interp, interp_flags), *engines = \
        integrator_c.units()
    assert main_flags == () and kernel_flags == ("-O3",) and interp_flags == ()
    assert "int jd_interp_accel(" in interp and "int jd_interp_accel(" not in main
    assert [text.split("\n", 1)[0] for text, _ in engines] == [
        "#define JD_RT_PLANAR 1", "#define JD_RT_PLANAR 0"]
    assert kernels.startswith("#define JD_KERNELS 1") and "JD_KERNELS 1" not in main
    assert "int jd_integrate(" in main and "int jd_integrate(" not in kernels
    assert "int stage_sum(" in main and "int stage_sum(" in kernels  # declared; defined


def _runs() -> list[tuple[np.ndarray, np.ndarray, int]]:
    s = n_link_pendulum_on_cart(4)
    y0 = np.concatenate([[0.0], np.linspace(math.pi + 0.3, math.pi - 0.3, 4)])
    out = []
    for method in ("DOP853", "RK45", "Radau"):
        r = s.simulate((0.0, 2.0), y0, np.zeros(5), inputs={"F": 0.0}, rtol=1e-7, atol=1e-7,
                       method=method)
        out.append((r.y, r.yd, r.nfev))
    return out


def test_two_units_give_the_numbers_of_one_unit_bit_for_bit(fresh_cache, monkeypatch):
    """The reference: the whole source as one translation unit at -O2 (the kernels defined
    and inlined where the compiler likes). The two-unit library (kernels vectorized at -O3,
    called across units) must give the same trajectories and evaluation counts to the last
    bit for the explicit methods and Radau IIA: vectorizing reorders no sum."""
    two = _runs()
    (main, _), _, *rest = integrator_c.units()  # the interpreter and the engines as they are
    monkeypatch.setattr(integrator_c, "units",
                        lambda: (("#define JD_KERNELS 1\n" + main, ()), *rest))
    problem.integrator_library.cache_clear()
    one = _runs()
    for (y2, yd2, n2), (y1, yd1, n1) in zip(two, one, strict=True):
        assert n2 == n1
        assert y2.tobytes() == y1.tobytes() and yd2.tobytes() == yd1.tobytes()


def test_the_kernels_are_not_exported(fresh_cache):
    lib = problem.integrator_library()
    assert callable(lib.jd_integrate) and callable(lib.jd_rhs)
    for name in ("stage_sum", "lu_real", "radau_residual", "error_sums8"):
        with pytest.raises(AttributeError):
            getattr(lib, name)


def test_a_build_started_ahead_is_the_one_the_simulation_uses(fresh_cache, monkeypatch):
    """build_integrator_soon compiles in a thread; integrator_library() called meanwhile waits
    for that build instead of compiling again: one compiler run, and a working library."""
    calls: list[str] = []
    real = toolchain.compile_shared

    def counted(sources, units, out, flags, unit_flags=None):
        calls.append(out.name)
        real(sources, units, out, flags, unit_flags)

    monkeypatch.setattr(toolchain, "compile_shared", counted)
    problem.build_integrator_soon()
    lib = problem.integrator_library()
    for t in threading.enumerate():
        if t.name == "jourdain-integrator-build":
            t.join()
    assert len(calls) == 1
    assert isinstance(lib, ctypes.CDLL) and lib is problem.integrator_library()
    problem.build_integrator_soon()  # built: nothing started
    assert not any(t.name == "jourdain-integrator-build" for t in threading.enumerate())


def test_a_failing_build_ahead_leaves_the_error_to_the_caller(fresh_cache, monkeypatch):
    """The thread swallows the compiler's failure; the caller's own integrator_library()
    builds again and raises the error, naming the source."""
    monkeypatch.setattr(integrator_c, "units", lambda: (("this is not C\n", ()),))
    problem.build_integrator_soon()
    for t in threading.enumerate():
        if t.name == "jourdain-integrator-build":
            t.join()
    with pytest.raises(toolchain.CompilerError, match="compiling"):
        problem.integrator_library()


def _build_in_child(key: str, source: str) -> int:
    return int(toolchain.build(key, source).jd_seven())


def test_a_child_forked_during_a_build_builds_for_itself(fresh_cache):
    """A build's lock held by a thread of the parent (build_soon) at a fork: the child has no
    such thread, so it must not wait for that lock (it would forever); it builds itself."""
    import multiprocessing

    source = "int jd_seven(void) { return 7; }\n"
    key = toolchain.content_key("fork test", source)
    with toolchain.build_lock(key), multiprocessing.get_context("fork").Pool(1) as pool:
        # as if mid-build
        assert pool.apply_async(_build_in_child, (key, source)).get(timeout=120) == 7
