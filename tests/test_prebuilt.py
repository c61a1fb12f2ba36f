"""The integrator library compiled at install time (setup.py, toolchain.prebuild): found by a
process whose cache is empty, with the numbers of the library compiled into the cache; built by
setup.py without NumPy or SymEngine (a build environment has neither); an install without a
compiler goes on; a prebuilt library that is not private, or one of another key, is not used.
The rest of the suite runs with JOURDAIN_PREBUILT empty (conftest.py)."""

from __future__ import annotations

import json
import os
import runpy
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from jourdain.numeric import integrator_c, toolchain

ROOT = Path(__file__).resolve().parents[1]

#: in a fresh process: the double pendulum simulated, the libraries compiled on the way and
#: where the integrator came from
_CHILD = r"""
import json, sys
import numpy as np
from jourdain.numeric import toolchain
built = []
real = toolchain.compile_shared
def counted(sources, units, out, flags, unit_flags=None):
    built.append(out.stem)
    real(sources, units, out, flags, unit_flags)
toolchain.compile_shared = counted
from jourdain.io import load_model
from jourdain.simulation.problem import integrator_library
system = load_model(sys.argv[1]).system
r = system.simulate((0.0, 2.0), [0.3, -0.2], [0.0, 0.5], rtol=1e-9, atol=1e-9)
np.save(sys.argv[2], np.concatenate([r.t, r.y.ravel(), r.yd.ravel()]))
import threading  # the model's library compiles in a thread while its first run is interpreted
for t in threading.enumerate():
    if t.name.startswith("jourdain-"):
        t.join()
print(json.dumps({"built": built, "integrator": integrator_library()._name}))
"""


def _child(tmp_path: Path, name: str, prebuilt: str) -> tuple[dict, np.ndarray]:
    env = {**os.environ, "JOURDAIN_CACHE": str(tmp_path / f"cache-{name}"),
           "JOURDAIN_PREBUILT": prebuilt}
    out = tmp_path / f"{name}.npy"
    r = subprocess.run([sys.executable, "-c", _CHILD, str(ROOT / "examples/double_pendulum.toml"),
                        str(out)], env=env, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1]), np.load(out)


def test_a_first_run_takes_the_prebuilt_integrator_with_the_same_numbers(tmp_path):
    """Prebuilt into a folder: a process with an empty cache compiles its model and not the
    integrator, loads the integrator from the folder, and simulates to the same bits as a
    process that compiled the integrator into its own cache."""
    pre = tmp_path / "prebuilt"
    so = integrator_c.prebuild(pre)
    key = integrator_c.library_source()[0]
    assert so == pre / f"{key}.so" and (pre / f"{key}.c").exists()
    used, y_pre = _child(tmp_path, "prebuilt", str(pre))
    own, y_own = _child(tmp_path, "own", "")
    assert used["integrator"] == str(so) and key not in used["built"]
    assert key in own["built"] and own["integrator"].startswith(str(tmp_path / "cache-own"))
    assert len(used["built"]) == len(own["built"]) - 1  # the model's libraries, in both
    assert y_pre.tobytes() == y_own.tobytes()


def test_prebuild_replaces_an_earlier_version_and_keeps_other_files(tmp_path):
    pre = tmp_path / "prebuilt"
    pre.mkdir()
    (pre / "0123abcd.so").write_bytes(b"an earlier version")
    (pre / "0123abcd.c").write_text("/* its source */")
    (pre / "0123abcd.so.sha256").write_text("its seal\n")
    (pre / "README").write_text("not ours to delete")
    so = integrator_c.prebuild(pre)
    assert sorted(p.name for p in pre.iterdir()) == sorted([so.name, so.stem + ".c",
                                                           so.name + ".sha256", "README"])


def test_a_prebuilt_library_that_is_not_private_or_switched_off_is_not_loaded(tmp_path,
                                                                               monkeypatch):
    pre = tmp_path / "prebuilt"
    so = integrator_c.prebuild(pre)
    key = so.stem
    monkeypatch.setattr(toolchain, "_loaded", {})
    monkeypatch.setenv("JOURDAIN_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("JOURDAIN_PREBUILT", str(pre))
    so.chmod(0o777)  # writable by all: could be anyone's code
    assert toolchain.cached_library(key) is None
    so.chmod(0o700)
    monkeypatch.setenv("JOURDAIN_PREBUILT", "")
    assert toolchain.prebuilt_dir() is None and toolchain.cached_library(key) is None
    monkeypatch.setenv("JOURDAIN_PREBUILT", str(pre))
    assert toolchain.cached_library(key)._name == str(so)
    monkeypatch.delenv("JOURDAIN_PREBUILT")
    assert toolchain.prebuilt_dir() == Path(toolchain.__file__).with_name("prebuilt")


def test_setup_py_builds_it_without_numpy_or_symengine(tmp_path):
    """What pip runs in its isolated build environment: setup.py's build step loads the
    toolchain and the integrator's source without jourdain's package imports."""
    code = ("import sys, runpy; from pathlib import Path\n"
            "for m in ('numpy', 'symengine', 'sympy', 'scipy'): sys.modules[m] = None\n"
            f"ns = runpy.run_path({str(ROOT / 'setup.py')!r}, run_name='jourdain_setup')\n"
            "print(ns['prebuild_integrator'](Path(sys.argv[1])))\n")
    r = subprocess.run([sys.executable, "-c", code, str(tmp_path)], capture_output=True,
                       text=True, timeout=300, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    key = integrator_c.library_source()[0]
    assert Path(r.stdout.strip()) == tmp_path / f"{key}.so"


def test_an_install_without_a_compiler_goes_on(tmp_path, monkeypatch, capsys):
    """No compiler at install time: the build step says so and the install continues (the
    library is compiled at its first use, as before)."""
    from setuptools.dist import Distribution

    ns = runpy.run_path(str(ROOT / "setup.py"), run_name="jourdain_setup")
    monkeypatch.setenv("CC", str(tmp_path / "no-such-cc"))
    cmd = ns["build_integrator"](Distribution())
    cmd.initialize_options()
    cmd.build_lib = str(tmp_path / "lib")
    cmd.run()
    assert "not compiled at install time" in capsys.readouterr().err
    assert cmd.get_outputs() == []
    assert not list((tmp_path / "lib").rglob("*.so"))


@pytest.mark.parametrize("editable", [False, True])
def test_the_build_step_writes_where_the_install_takes_it(tmp_path, editable):
    """A wheel takes build_lib's tree; an editable install the source tree (the editable
    finder maps the package there), where toolchain.prebuilt_dir() looks."""
    from setuptools.dist import Distribution

    if editable and ROOT / "src" not in Path(toolchain.__file__).parents:
        pytest.skip("jourdain is not installed in editable mode from this checkout")
    ns = runpy.run_path(str(ROOT / "setup.py"), run_name="jourdain_setup")
    cmd = ns["build_integrator"](Distribution())
    cmd.initialize_options()
    cmd.build_lib = str(tmp_path / "lib")
    cmd.editable_mode = editable
    want = (Path(toolchain.__file__).with_name("prebuilt") if editable
            else tmp_path / "lib" / "jourdain" / "numeric" / "prebuilt")
    assert cmd._dest() == want


def test_a_wheel_with_the_library_is_tagged_for_its_platform(tmp_path):
    """A wheel that carries the compiled integrator is not pure Python: its tag names the
    interpreter, ABI and platform (py3-none-any would let pip install it on any machine)."""
    ns = runpy.run_path(str(ROOT / "setup.py"), run_name="jourdain_setup")
    dist = ns["MachineCodeDistribution"]({"name": "jourdain", "version": "0"})
    cmd = dist.get_command_obj("bdist_wheel")
    cmd.bdist_dir = str(tmp_path)
    cmd.ensure_finalized()
    impl, abi, plat = cmd.get_tag()
    assert impl.startswith("cp") and abi != "none" and plat != "any"
