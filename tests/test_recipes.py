"""Warm starts without the derivation (numeric/recipes.py) and the native target asked once per
machine (numeric/native.py): a recipe serves only the very model it was made of, under the same
code and settings, and a warm start gives the cold start's numbers to the bit."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import symengine as se

from jourdain.models import n_link_pendulum_on_cart, spatial_chain
from jourdain.numeric import compiled, cost, first_run, native, parameter_vector, toolchain
from jourdain.numeric.recipes import code_stamp, fingerprint

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture
def fresh_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("JOURDAIN_CACHE", str(tmp_path))
    monkeypatch.setattr(toolchain, "_loaded", {})
    compiled.clear_cache()
    yield tmp_path
    compiled.clear_cache()


def _refuse(*_a, **_k):
    raise AssertionError("derived on a warm start")


_refuse.cache_clear = lambda: None  # type: ignore[attr-defined]  # as the memo it stands for


def _values(fn, model) -> dict:
    rng = np.random.default_rng(5)
    f = model.f
    Y, YD = rng.uniform(-2, 2, (20, f)), rng.uniform(-2, 2, (20, f))
    return fn.batch(Y, YD, 0.3, parameter_vector(model, None), np.zeros(len(model.inputs)))


@pytest.mark.parametrize("make", [lambda: n_link_pendulum_on_cart(2), lambda: spatial_chain(8)],
                         ids=["symbolic", "spatial"])
def test_a_warm_start_derives_nothing(fresh_cache, monkeypatch, make):
    """The same model built anew in a process whose memos are empty finds its library through
    its recipe: no path chosen, nothing derived or generated; the same numbers to the bit."""
    cold = compiled.mkq_function(make())
    assert list(fresh_cache.glob("*.recipe"))
    compiled.clear_cache()
    model = make()  # new objects, the same description
    for where in (compiled, first_run):
        monkeypatch.setattr(where, "evaluation_path", _refuse)
    monkeypatch.setattr(first_run, "_interpreted", _refuse)
    warm = first_run.run_function(model)
    assert type(warm) is type(cold) and warm.key == cold.key
    assert warm.n_bodies == cold.n_bodies
    a, b = _values(cold, model), _values(warm, model)
    assert all(a[k].tobytes() == b[k].tobytes() for k in ("M", "k", "q"))
    assert compiled.mkq_function(model).key == cold.key


def test_a_recipe_names_only_what_is_there_and_what_it_was_made_for(fresh_cache, monkeypatch):
    """A recipe whose library is gone, or a recipe file of another key, is passed over: the
    model is derived and built again. Other settings of the cost model give another key."""
    model = n_link_pendulum_on_cart(2)
    key = compiled.mkq_function(model).key
    (recipe,) = fresh_cache.glob("*.recipe")
    for p in fresh_cache.glob(f"{key}.so*"):
        p.unlink()
    compiled.clear_cache()
    monkeypatch.setattr(toolchain, "_loaded", {})
    assert compiled.cached_mkq(model) is None
    assert compiled.mkq_function(model).key == key  # built again, and the recipe kept
    # a sound recipe file copied under another key is not taken
    other = fresh_cache / ("0" * 32 + ".recipe")
    other.write_bytes(recipe.read_bytes())
    Path(f"{other}.sha256").write_bytes(Path(f"{recipe}.sha256").read_bytes())
    assert json.loads(recipe.read_bytes())["recipe"] == recipe.stem
    from jourdain.numeric.recipes import load_recipe

    assert load_recipe("0" * 32) is None and load_recipe(recipe.stem) is not None
    # another setting of the cost model: another recipe, another path
    compiled.clear_cache()
    monkeypatch.setattr(cost, "SYMBOLIC_MAX_F", 0)
    assert compiled.mkq_function(model).key != key


def test_fingerprints_are_exact():
    """What orders the generated code tells fingerprints apart (the order of a difference, the
    last bit of a float); what cannot be written exactly gives none."""
    x, x0, k = se.symbols("x x0 k")
    assert fingerprint((k * (x - x0),)) != fingerprint((k * (x0 - x),))
    assert fingerprint((0.1,)) != fingerprint((float(np.nextafter(0.1, 1.0)),))
    assert fingerprint((se.RealDouble(0.1) * x,)) != fingerprint(
        (se.RealDouble(float(np.nextafter(0.1, 1.0))) * x,))
    assert fingerprint((x + 1,)) == fingerprint((se.Symbol("x") + 1,))
    assert fingerprint(("a", 1)) != fingerprint(("a", "1"))
    assert fingerprint((se.Dummy("x"),)) is None
    assert fingerprint((object(),)) is None and fingerprint((len,)) is None
    a = n_link_pendulum_on_cart(3)
    assert fingerprint(a) == fingerprint(n_link_pendulum_on_cart(3))
    assert fingerprint(a) != fingerprint(n_link_pendulum_on_cart(4))


def test_the_code_stamp_sees_an_edit(tmp_path):
    """A changed file of the package (its size or time of change) changes the stamp."""
    from jourdain.numeric.recipes import _stat_tree

    (tmp_path / "sub").mkdir()
    src = tmp_path / "sub" / "m.py"
    src.write_text("A = 1\n")
    before: list[str] = []
    _stat_tree(str(tmp_path), before)
    os.utime(src, ns=(1, 2))
    after: list[str] = []
    _stat_tree(str(tmp_path), after)
    assert before != after and len(after) == 1
    assert code_stamp() == code_stamp()


CHILD = """
import json, sys
import numpy as np
from jourdain.models import n_link_pendulum_on_cart
from jourdain.numeric import cost
m = n_link_pendulum_on_cart(2)
r = m.simulate((0.0, 0.3), np.full(3, 0.2), np.zeros(3), inputs={u: 0.0 for u in m.input_names})
print(json.dumps({"y": r.y[-1].tobytes().hex(), "derived": cost.evaluation_path.cache_info().currsize}))
"""


@pytest.mark.own_hash_seeds
def test_a_warm_start_in_another_process_gives_the_same_bits(tmp_path):
    """A cold process (which keeps the recipe once its library is built) and a warm one under
    another hash seed: the same motion to the bit, and the warm one derives nothing."""
    out = []
    for seed in ("1", "2"):
        env = {**os.environ, "JOURDAIN_CACHE": str(tmp_path), "PYTHONHASHSEED": seed,
               "PYTHONPATH": str(ROOT / "src")}
        r = subprocess.run([sys.executable, "-c", CHILD], env=env, capture_output=True,
                           text=True, timeout=300, check=True)
        out.append(json.loads(r.stdout.strip().splitlines()[-1]))
    assert out[0]["y"] == out[1]["y"]
    assert out[0]["derived"] == 1 and out[1]["derived"] == 0


CPUINFO = """processor\t: {n}
vendor_id\t: AuthenticAMD
model name\t: AMD EPYC
cpu MHz\t\t: {mhz}
flags\t\t: fpu sse2 {extra}

processor\t: 1
flags\t\t: other
"""


def test_the_native_target_is_asked_once_per_processor_and_compiler(tmp_path, monkeypatch):
    """Kept in the cache under the compiler and the processor's identity (not its clock, not
    the core): asked again for another processor or with no cache; None never kept."""
    info = tmp_path / "cpuinfo"
    info.write_text(CPUINFO.format(n=0, mhz="2596.1", extra="avx2"))
    identity_of = native.cpu_identity
    a = identity_of(str(info))
    info.write_text(CPUINFO.format(n=0, mhz="3100.0", extra="avx2"))
    assert identity_of(str(info)) == a and a is not None and "other" not in a
    asked: list[str] = []
    answer: list[str | None] = ["-march=znver3 -mavx2"]

    def ask(cc, flags):
        asked.append(cc)
        return answer[0]

    monkeypatch.setattr(native, "ask_target", ask)
    monkeypatch.setattr(native, "cpu_identity", lambda path="": native_identity[0])
    native_identity = [a]
    cc, folder = sys.executable, tmp_path / "cache"
    folder.mkdir(mode=0o700)
    for _ in range(3):
        assert native.native_target_of(cc, ("-march=native",), folder) == answer[0]
    assert len(asked) == 1
    info.write_text(CPUINFO.format(n=0, mhz="2596.1", extra="avx512f"))
    native_identity[0] = identity_of(str(info))
    assert native.native_target_of(cc, ("-march=native",), folder) == answer[0]
    assert len(asked) == 2
    assert native.native_target_of(cc, ("-march=native",), None) == answer[0]
    assert len(asked) == 3
    answer[0] = None
    native_identity[0] = "another processor"
    for _ in range(2):
        assert native.native_target_of(cc, ("-march=native",), folder) is None
    assert len(asked) == 5
