"""Code compiled for this machine (``-march=native``, numeric/toolchain.py): the same numbers,
bit for bit, as the portable build, a cache key that names the processor, and portable code
where the native build fails. The optimization levels (``JOURDAIN_OPTIMIZE``, which the suite
sets to 1): the same numbers, bit for bit, as the default -O2/-O3 build."""

from __future__ import annotations

import ctypes
import math

import numpy as np
import pytest

from jourdain import numeric
from jourdain.errors import JourdainError
from jourdain.models import n_link_pendulum_on_cart
from jourdain.numeric import toolchain
from jourdain.simulation import problem

native = pytest.mark.skipif(toolchain.native_target() is None,
                            reason="the compiler here does not take -march=native")


def _run(monkeypatch, native_on: bool, optimize: str | None = None):
    monkeypatch.setenv("JOURDAIN_NATIVE", "1" if native_on else "0")
    if optimize is None:
        monkeypatch.delenv("JOURDAIN_OPTIMIZE", raising=False)
    else:
        monkeypatch.setenv("JOURDAIN_OPTIMIZE", optimize)
    numeric.clear_cache()
    problem.integrator_library.cache_clear()
    s = n_link_pendulum_on_cart(5)
    y0 = np.concatenate([[0.0], np.linspace(math.pi + 0.3, math.pi - 0.3, 5)])
    r = s.simulate((0.0, 2.0), y0, np.zeros(6), inputs={"F": 0.0}, rtol=1e-9, atol=1e-9)
    y = np.random.default_rng(3).normal(size=(8, 2, 6))
    mats = [s.evaluate(a, b, inputs={"F": 0.5}) for a, b in y]
    return r, mats


def _same(a, b) -> bool:
    """Equal to the bit (NaN equal to NaN), through dicts, lists and arrays."""
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, str):
        return a == b
    if hasattr(a, "force_inertial"):  # a JointWrench
        return all(_same(getattr(a, k), getattr(b, k))
                   for k in ("joint", "force", "torque", "force_inertial", "torque_inertial"))
    x, y = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return x.shape == y.shape and x.tobytes() == y.tobytes()


@native
def test_native_build_gives_the_portable_numbers_bit_for_bit(monkeypatch):
    """The native library may use AVX-512 and FMA hardware, but with -ffp-contract=off every
    operation is rounded as the source writes it: the same trajectory, evaluation counts and
    matrices as the baseline build, to the last bit (the reference: the portable build)."""
    try:
        r_nat, m_nat = _run(monkeypatch, True)
        r_por, m_por = _run(monkeypatch, False)
    finally:
        monkeypatch.undo()
        numeric.clear_cache()
        problem.integrator_library.cache_clear()
    _assert_same_runs((r_nat, m_nat), (r_por, m_por))


def _assert_same_runs(one, other) -> None:
    (r_a, m_a), (r_b, m_b) = one, other
    assert r_a.nfev == r_b.nfev and r_a.n_accepted == r_b.n_accepted
    assert np.array_equal(r_a.t, r_b.t)
    assert np.array_equal(r_a.y, r_b.y) and np.array_equal(r_a.yd, r_b.yd)
    for a, b in zip(m_a, m_b, strict=True):
        assert a.keys() == b.keys() and {"M", "k", "q"} <= a.keys()
        for name in a:
            assert _same(a[name], b[name]), name


def test_optimization_levels_give_the_same_numbers_bit_for_bit(monkeypatch):
    """-O0 and -O1 (JOURDAIN_OPTIMIZE) against the default -O2, with the integrator's -O3
    kernels: no flag lets the compiler reorder or contract arithmetic, so the trajectory, the
    step counts and the matrices are the same to the last bit; each level has its own keys."""
    native_on = toolchain.native_target() is not None
    try:
        keys = {}
        runs = {}
        for level in (None, "1", "0"):
            runs[level] = _run(monkeypatch, native_on, level)
            keys[level] = toolchain.content_key("same source")
    finally:
        monkeypatch.undo()
        numeric.clear_cache()
        problem.integrator_library.cache_clear()
    assert len(set(keys.values())) == 3
    _assert_same_runs(runs["1"], runs[None])
    _assert_same_runs(runs["0"], runs[None])


def test_an_unknown_optimization_level_is_refused(monkeypatch):
    monkeypatch.setenv("JOURDAIN_OPTIMIZE", "fast")
    with pytest.raises(JourdainError, match="JOURDAIN_OPTIMIZE='fast'"):
        toolchain.content_key("any source")


@native
def test_the_key_names_the_processor(monkeypatch):
    """A cache shared by two machines never hands one a library built for the other: the key
    holds what -march=native means here, and the portable build has keys of its own."""
    k_native = toolchain.content_key("same source")
    target = toolchain.native_target()
    assert "-march=" in target or "target-cpu" in target
    monkeypatch.setattr(toolchain, "_native_target", lambda cc: "-march=some-other-cpu -mavx2")
    assert toolchain.content_key("same source") != k_native
    monkeypatch.setenv("JOURDAIN_NATIVE", "0")
    assert toolchain.native_target() is None and toolchain.host_flags() == ()
    k_portable = toolchain.content_key("same source")
    assert k_portable not in (k_native, toolchain.content_key("other source"))


def test_a_failing_native_build_falls_back_to_portable_code(monkeypatch, tmp_path):
    """Where the compiler knows the flag but the build fails (say, an assembler older than the
    instruction set), the library is built portable and works; later builds skip the flag."""
    monkeypatch.setenv("JOURDAIN_CACHE", str(tmp_path))
    monkeypatch.setattr(toolchain, "_native_failed", set())
    monkeypatch.setattr(toolchain, "NATIVE_FLAGS", ("-mno-such-instruction-set-xyz",))
    monkeypatch.setattr(toolchain, "_native_target", lambda cc: "-march=fake")
    assert toolchain.host_flags() == ("-mno-such-instruction-set-xyz",)
    src = "double jd_twice(double x) { return 2.0 * x; }\n"
    lib = toolchain.build(toolchain.content_key("fallback test", src), src)
    lib.jd_twice.restype = ctypes.c_double
    lib.jd_twice.argtypes = [ctypes.c_double]
    assert lib.jd_twice(21.0) == 42.0
    assert toolchain.compiler() in toolchain._native_failed
    assert toolchain.host_flags() == ()


def test_a_source_that_does_not_compile_leaves_native_code_on(monkeypatch, tmp_path):
    """The retry without the flag tells a flag at fault from a source at fault: where the
    portable build fails too, the compiler's error is raised and native code stays on."""
    monkeypatch.setenv("JOURDAIN_CACHE", str(tmp_path))
    monkeypatch.setattr(toolchain, "_native_failed", set())
    monkeypatch.setattr(toolchain, "NATIVE_FLAGS", ("-O2",))
    monkeypatch.setattr(toolchain, "_native_target", lambda cc: "-march=fake")
    src = "double jd_broken(double x) { return 2.0 * ; }\n"
    with pytest.raises(toolchain.CompilerError, match="jd_broken|expected expression"):
        toolchain.build(toolchain.content_key("broken source", src), src)
    assert toolchain._native_failed == set()
    assert toolchain.host_flags() == ("-O2",)


#: lanes that add and subtract what the source writes as a product and a sum: GCC 12.2 -O2
#: with -march=native on an AVX-512 machine (and -march=skylake-avx512) vectorized x[20] and
#: x[21] into one vfmaddsub despite -ffp-contract=off (reduced from random_tree(70, seed=3)'s
#: per-joint code, whose ÿ then differed from the -O0 build's at 15 of 200 states)
FUSABLE = """
void jd_probe(double *x) {
    x[10] = (-0.4721937725576087*x[0]);
    x[11] = ((0.16217774529983747*x[1]) + x[10]);
    x[20] = ((-0.16217774529983747*x[1]) + x[10]);
    x[21] = ((0.36829466850378856*x[0]) + x[2]);
}
"""


def test_no_fused_multiply_add_where_the_vectorizer_pairs_lanes(cache):
    """Every product and sum rounded apart, as the source writes them (numeric/toolchain.py's
    NO_FUSED), against Python's own float arithmetic, which never fuses: a fused lane differs
    in the last bit at about a third of the random inputs."""
    lib = toolchain.build(toolchain.content_key("fused lanes", FUSABLE), FUSABLE)
    probe = lib.jd_probe
    probe.argtypes, probe.restype = [ctypes.c_void_p], None
    x = np.zeros(32)
    wrong = []
    for a, b, c in np.random.default_rng(1).uniform(-10.0, 10.0, (500, 3)).tolist():
        x[:3] = a, b, c
        probe(x.ctypes.data)
        x10 = -0.4721937725576087 * a
        want = [x10, 0.16217774529983747 * b + x10, -0.16217774529983747 * b + x10,
                0.36829466850378856 * a + c]
        if [x[10], x[11], x[20], x[21]] != want:
            wrong.append((a, b, c))
    assert not wrong, f"{len(wrong)} of 500 inputs fused, e.g. {wrong[0]} ({toolchain.host_flags()})"
