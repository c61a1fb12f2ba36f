"""Faults of the compile cache (issue 33, items 1, 2, 8 and 11), on a real model: the double
pendulum simulated through the Python API and through ``jourdain simulate``, each in a process
of its own (a damaged library must not take pytest down with it) whose ``JOURDAIN_CACHE`` is a
copy of the cache of a clean run, then damaged:

- (a) the libraries and compiled functions of another model (the same pendulum with the first
  rod's centre of mass moved: the same interface, other numbers) put under this model's keys,
  once the files alone and once with whatever the cache keeps beside them (its checksums);
- (b) every compiled file cut to half its size;
- (c) bytes flipped in the machine code of every library (and in every compiled function);
- (d) a read-only cache folder.

Every run must exit 0 with the numbers of the clean run, bit for bit, and leave no damaged file
in place (a second run is as clean); the read-only cache gives one warning that names the
folder and ``JOURDAIN_CACHE``. Before the fix, (a) exited 0 with the other model's numbers,
(b) died of SIGBUS, (c) of SIGSEGV or SIGILL, and (d) failed with "Permission denied".
"""

from __future__ import annotations

import ctypes
import os
import shutil
import stat
import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from jourdain.numeric import toolchain

ROOT = Path(__file__).resolve().parents[1]
MODEL = ROOT / "examples" / "double_pendulum.toml"
#: exit statuses of a process killed by SIGILL, SIGBUS, SIGSEGV, as a shell reports them
CRASHES = (132, 135, 139)

#: the Python API in a child process: a simulation and its energies, saved as one array
_API = r"""
import sys
import numpy as np
import jourdain as jd
system = jd.load_model(sys.argv[1]).system
r = system.simulate((0.0, 1.0), [0.3, -0.2], [0.0, 0.5], rtol=1e-9, atol=1e-9)
with open(sys.argv[2], "wb") as fh:
    np.save(fh, np.concatenate([r.t, r.y.ravel(), r.yd.ravel(), r.kinetic_energy,
                                r.potential_energy]))
"""

pytestmark = pytest.mark.skipif(shutil.which(os.environ.get("CC") or "cc") is None
                                and shutil.which("gcc") is None, reason="no C compiler")


def _command(kind: str, model: Path, out: Path) -> list[str]:
    if kind == "api":
        return [sys.executable, "-c", _API, str(model), str(out)]
    exe = Path(sys.executable).parent / "jourdain"
    cmd = [str(exe)] if exe.is_file() else [sys.executable, "-m", "jourdain.cli"]
    return [*cmd, "simulate", str(model), "--t-end", "1", "--out", str(out), "--force"]


def _out(d: Path, stem: str, kind: str) -> Path:
    return d / f"{stem}-{kind}{'.npy' if kind == 'api' else '.csv'}"


def _run(kind: str, cache: Path, out: Path, model: Path = MODEL,
         prefix: tuple[str, ...] = ()) -> subprocess.CompletedProcess:
    env = {**os.environ, "JOURDAIN_CACHE": str(cache), "JOURDAIN_PREBUILT": ""}
    return subprocess.run([*prefix, *_command(kind, model, out)], env=env, capture_output=True,
                          text=True, timeout=600)


def _numbers(kind: str, out: Path) -> bytes:
    """The numbers a run wrote: the array (API) or the CSV's rows, without the header (which
    holds the wall time)."""
    if kind == "api":
        return np.load(out).tobytes()
    return "\n".join(ln for ln in out.read_text().splitlines()
                     if not ln.startswith("#")).encode()


def _clean(r: subprocess.CompletedProcess, what: str) -> None:
    crashed = r.returncode < 0 or r.returncode in CRASHES
    assert r.returncode == 0, (f"{what}: {'crashed' if crashed else 'failed'} with exit status "
                               f"{r.returncode}\n{r.stderr[-3000:]}")


def _compiled(cache: Path) -> list[Path]:
    """The compiled files of a cache: libraries and compiled functions."""
    return sorted(p for p in cache.iterdir() if p.suffix in (".so", ".llvm"))


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Per kind of run: the clean run's cache and numbers, and the compiled files of another
    model (with the files beside them) by this model's keys they are put under."""
    base = tmp_path_factory.mktemp("cache-faults")
    foreign_model = base / "other_pendulum.toml"
    foreign_model.write_text(MODEL.read_text().replace('com = [0, "-l1/2", 0]',
                                                       'com = [0, "-l1/3", 0]'))
    out = {}
    for kind in ("api", "cli"):
        clean, other = base / f"clean-{kind}", base / f"other-{kind}"
        r = _run(kind, clean, _out(base, "clean", kind))
        _clean(r, f"the clean {kind} run")
        o = _run(kind, other, _out(base, "other", kind), model=foreign_model)
        _clean(o, f"the {kind} run of the other model")
        assert _numbers(kind, _out(base, "other", kind)) != _numbers(kind,
                                                                     _out(base, "clean", kind))
        mine = {p.name: p for p in _compiled(clean)}
        theirs = {p.name: p for p in _compiled(other)}
        pairs = {}
        for suffix in (".so", ".llvm"):  # this model's files against the other's, by size
            a = sorted((p for n, p in mine.items() if n not in theirs and p.suffix == suffix),
                       key=lambda p: p.stat().st_size)
            b = sorted((p for n, p in theirs.items() if n not in mine and p.suffix == suffix),
                       key=lambda p: p.stat().st_size)
            assert len(a) == len(b)
            pairs.update({x.name: y for x, y in zip(a, b, strict=True)})
        assert any(n.endswith(".so") for n in pairs)
        out[kind] = (clean, _numbers(kind, _out(base, "clean", kind)), pairs)
    return out


def _faulty_cache(runs, kind: str, tmp_path: Path) -> Path:
    cache = tmp_path / "cache"
    shutil.copytree(runs[kind][0], cache)
    return cache


def _text_section(data: bytes) -> tuple[int, int]:
    """Offset and size of the ``.text`` section of an ELF64 shared library."""
    assert data[:4] == b"\x7fELF" and data[4] == 2, "not an ELF64 file"
    shoff, = struct.unpack_from("<Q", data, 0x28)
    shentsize, shnum, shstrndx = struct.unpack_from("<HHH", data, 0x3A)
    sections = [struct.unpack_from("<IIQQQQ", data, shoff + i * shentsize)
                for i in range(shnum)]
    names = sections[shstrndx][4]
    for name, _, _, _, offset, size in sections:
        if data[names + name:data.index(b"\0", names + name)] == b".text":
            return offset, size
    raise AssertionError("no .text section")


def _flip(path: Path) -> None:
    data = bytearray(path.read_bytes())
    if data[:4] == b"\x7fELF":
        offset, size = _text_section(bytes(data))
    else:  # a compiled function (a pickle of machine code): its middle half
        offset, size = len(data) // 4, len(data) // 2
    for i in range(offset, offset + size, 7):
        data[i] ^= 0xFF
    path.write_bytes(bytes(data))


def _truncate(path: Path) -> None:
    path.write_bytes(path.read_bytes()[:path.stat().st_size // 2])


def _foreign(cache: Path, pairs: dict[str, Path], beside: bool) -> None:
    for name, theirs in pairs.items():
        shutil.copy2(theirs, cache / name)
        if beside:  # whatever the cache keeps beside a file, under that file's name
            for extra in theirs.parent.glob(theirs.name + ".*"):
                shutil.copy2(extra, cache / (name + extra.name[len(theirs.name):]))


def _assert_runs_clean(runs, kind: str, cache: Path, tmp_path: Path,
                       damaged: dict[Path, bytes]) -> None:
    """Two runs on the damaged cache: the numbers of the clean run, bit for bit, and no damaged
    file left where it was."""
    for attempt in ("first", "second"):
        out = _out(tmp_path, attempt, kind)
        r = _run(kind, cache, out)
        _clean(r, f"the {attempt} {kind} run on the damaged cache")
        assert _numbers(kind, out) == runs[kind][1], (
            f"the {attempt} {kind} run on the damaged cache gave other numbers than the clean "
            f"run\n{r.stderr[-2000:]}")
        for path, bad in damaged.items():
            assert not (path.exists() and path.read_bytes() == bad), f"{path.name} left damaged"


@pytest.mark.parametrize("kind", ["api", "cli"])
@pytest.mark.parametrize("beside", [False, True], ids=["files", "with-checksums"])
def test_another_models_library_under_the_key_is_not_used(runs, kind, beside, tmp_path):
    cache = _faulty_cache(runs, kind, tmp_path)
    _foreign(cache, runs[kind][2], beside)
    damaged = {cache / n: (cache / n).read_bytes() for n in runs[kind][2]}
    _assert_runs_clean(runs, kind, cache, tmp_path, damaged)


@pytest.mark.parametrize("kind", ["api", "cli"])
@pytest.mark.parametrize("damage", [_truncate, _flip], ids=["truncated", "flipped"])
def test_a_damaged_library_is_rebuilt_not_loaded(runs, kind, damage, tmp_path):
    cache = _faulty_cache(runs, kind, tmp_path)
    for p in _compiled(cache):
        damage(p)
    damaged = {p: p.read_bytes() for p in _compiled(cache)}
    _assert_runs_clean(runs, kind, cache, tmp_path, damaged)


def _without_override() -> tuple[str, ...]:
    """A prefix that makes the command obey file permissions: for root (who may write into any
    folder), setpriv without CAP_DAC_OVERRIDE."""
    if not hasattr(os, "getuid") or os.getuid() != 0:
        return ()
    setpriv = shutil.which("setpriv")
    if setpriv is None:
        pytest.skip("root without setpriv: a read-only folder is writable")
    probe = subprocess.run([setpriv, "--bounding-set=-dac_override,-dac_read_search", "true"],
                           capture_output=True)
    if probe.returncode != 0:
        pytest.skip("setpriv cannot drop CAP_DAC_OVERRIDE here")
    return (setpriv, "--bounding-set=-dac_override,-dac_read_search")


@pytest.mark.parametrize("kind", ["api", "cli"])
def test_a_read_only_cache_falls_back_to_a_private_one_with_one_warning(runs, kind, tmp_path):
    prefix = _without_override()
    cache = tmp_path / "read-only-cache"
    cache.mkdir(mode=0o700)
    cache.chmod(stat.S_IRUSR | stat.S_IXUSR)
    try:
        out = _out(tmp_path, "run", kind)
        r = _run(kind, cache, out, prefix=prefix)
        _clean(r, f"the {kind} run with a read-only cache")
        assert _numbers(kind, out) == runs[kind][1]
        warned = [ln for ln in r.stderr.splitlines() if "JOURDAIN_CACHE" in ln]
        assert len(warned) == 1 and str(cache) in warned[0], r.stderr
        assert "compile cache" in warned[0]
        assert not any(cache.iterdir())
    finally:
        cache.chmod(stat.S_IRWXU)


# ------------------------------------------------------------------------------------------
# the same faults in this process, on libraries of one function
# ------------------------------------------------------------------------------------------

SOURCE = "double jd_answer(void) { return %d.0; }\n"


@pytest.fixture
def fresh_toolchain(monkeypatch, tmp_path):
    monkeypatch.setattr(toolchain, "_loaded", {})
    monkeypatch.setattr(toolchain, "_fallback", None)
    monkeypatch.setenv("JOURDAIN_CACHE", str(tmp_path / "cache"))
    return tmp_path / "cache"


def _answer(lib) -> float:
    lib.jd_answer.restype = ctypes.c_double
    return lib.jd_answer()


def test_a_library_built_for_another_key_is_rebuilt_even_with_its_files(fresh_toolchain):
    """Another key's library and everything beside it, copied under a key never loaded in this
    process: the key built into the library tells them apart."""
    theirs = toolchain.content_key("answer-of-another-key")
    assert _answer(toolchain.build(theirs, SOURCE % 666)) == 666.0
    mine = toolchain.content_key("answer-of-this-key")
    for f in list(fresh_toolchain.glob(f"{theirs}.so*")):
        shutil.copy2(f, fresh_toolchain / f.name.replace(theirs, mine))
    assert toolchain.cached_library(mine) is None
    assert not (fresh_toolchain / f"{mine}.so").exists()  # not left in place
    assert _answer(toolchain.build(mine, SOURCE % 7)) == 7.0


# ------------------------------------------------------------------------------------------
# models read from URDF files, pickled in the cache (item 11)
# ------------------------------------------------------------------------------------------

ARM = ROOT / "tests" / "data" / "urdf" / "two_link_arm.urdf"


@pytest.fixture
def urdf_cache(fresh_toolchain):
    """The folder of the pickled URDF models in a fresh cache."""
    pytest.importorskip("yourdfpy", reason="the URDF reader needs jourdain[urdf] (yourdfpy)")
    return fresh_toolchain / "urdf"


def test_a_cached_urdf_model_writable_by_others_is_not_unpickled(urdf_cache, tmp_path):
    """The folder is private, the file is not: it is not unpickled (before: only the folder
    was checked)."""
    from jourdain.io.urdf import cache, load_urdf

    arm = tmp_path / "arm.urdf"
    arm.write_bytes(ARM.read_bytes())
    first = load_urdf(arm)
    [pickled] = urdf_cache.glob("*.pickle")
    assert cache.cached(pickled.stem) == first
    pickled.chmod(0o666)
    assert cache.cached(pickled.stem) is None
    assert load_urdf(arm) == first


def test_another_urdf_model_under_the_key_is_not_used(urdf_cache, tmp_path):
    """The pickle of another file (with its seal) put under this file's key: this file's model
    is built again, not the other one handed out."""
    from jourdain.io.urdf import load_urdf

    arm, other = tmp_path / "arm.urdf", tmp_path / "other.urdf"
    arm.write_bytes(ARM.read_bytes())
    other.write_bytes(ARM.read_bytes().replace(b'name="elbow"', b'name="elbow_2"', 1))
    first = load_urdf(arm)
    [mine] = urdf_cache.glob("*.pickle")
    second = load_urdf(other)
    assert second != first
    [theirs] = (p for p in urdf_cache.glob("*.pickle") if p != mine)
    for f in urdf_cache.glob(theirs.name + "*"):
        shutil.copy2(f, urdf_cache / f.name.replace(theirs.stem, mine.stem))
    assert load_urdf(arm) == first
