"""Compile generated C once with the system's C compiler and cache the shared library on disk.

The cache is a plain directory (``$JOURDAIN_CACHE``, else ``$XDG_CACHE_HOME/jourdain``, else
``~/.cache/jourdain``) holding ``<key>.c`` (the source, for reading), ``<key>.so`` (the library)
and its seal ``<key>.so.sha256``, where ``<key>`` is a SHA-256 hash of the content that
determines the code. Deleting the directory, or any file in it, is always safe: the library is
rebuilt on the next use. Only shared libraries compiled from jourdain's own generated source are
loaded. The cache also holds pickles, each with its seal: functions compiled by LLVM
(``<key>.llvm``, :mod:`jourdain.numeric.compiled`) and models read from URDF files
(``urdf/<key>.pickle``, :mod:`jourdain.io.urdf.cache`); besides them, JSON and NumPy files that
are read as data only. No file is loaded or unpickled before it passed the checks of
:mod:`jourdain.numeric.cachefile`: private, whole (its SHA-256 against its seal: a truncated or
changed library is deleted and rebuilt, never handed to the dynamic loader) and built for its
key (each library exports its key, read back after loading; each pickle holds its key).

Code for this machine: the libraries are compiled with ``-march=native`` (every instruction set
extension of the processor but those with fused multiply-adds,
:data:`jourdain.numeric.native.NO_FUSED`) where the compiler accepts it, and the key holds the
processor's features as the compiler reports them, so that a cache shared by different machines
never hands one a library built for another. ``-ffp-contract=off`` keeps every operation of the
source a separately rounded one, and ``NO_FUSED`` the vectorizer from fusing any, so the numbers
are bit-for-bit those of the portable build (tests/test_native.py); only the speed
differs. Measured with ``benchmarks/simulation.py`` (12-link pendulum on a cart, AMD EPYC with
AVX-512, alternated with the portable build): M, k, q 222-227 → 179-188 ns, a right-hand side
480-503 → 440-470 ns, 8.4-8.7× → 9.2-9.4× PyDy. Everything native or nothing: the
integrator library alone compiled native made the runs slower, not faster (2.30 against 2.10
ms; probably its AVX code beside the model's SSE code). ``JOURDAIN_NATIVE=0`` compiles for the
architecture's baseline instead (valgrind, for one, does not know AVX-512). FMUs are not built
here and stay portable (:mod:`jourdain.io.fmu.binary`).

``JOURDAIN_OPTIMIZE=0``/``1``: ``-O0``/``-O1`` for ``-O2``/``-O3``, compiled in a tenth/quarter
of the time, slower code, the same numbers bit for bit (no flag reorders arithmetic).

Loading a library runs its code, so a library is loaded only from a directory that belongs to
the user and that no one else may write to, and only if the file itself belongs to the user and
is not writable by others (as Python's own caches are trusted only when private): a library
another user could have put or changed there is never loaded. A library file that fails the
check is rebuilt; a cache directory that fails it, or that cannot be written to (read-only),
is not used at all: jourdain says so once, naming the directory and ``JOURDAIN_CACHE``, and
compiles into a private temporary directory instead (removed at exit).

Libraries no model changes (the integrator, :mod:`jourdain.numeric.integrator_c`) are compiled
when jourdain is installed from source, into ``prebuilt/`` beside this module (``setup.py``,
:func:`prebuild`), so that a machine's first run does not wait for them: a library is looked up
in the cache, then there (``$JOURDAIN_PREBUILT`` names another directory; empty: none), under
the same key and the same checks. One built for another machine, compiler or source has
another key and is not found; without a compiler at install time nothing is prebuilt and the
library is compiled at its first use, as any other.
"""

from __future__ import annotations

import _ctypes
import atexit
import ctypes
import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
import warnings
from collections.abc import Mapping, Sequence
from functools import lru_cache
from pathlib import Path

from ..errors import JourdainError
from .buildlock import build_lock as build_lock  # the builds' locks, also the callers'
from .buildlock import build_soon as build_soon
from .cachefile import FORMAT, discard, read_sealed, seal, stamp, stamp_of, stamp_source
from .cachefile import keep_file as keep_file  # the cache's writer, for the other layers
from .cachefile import not_private as not_private
from .native import NATIVE_FLAGS as NATIVE_FLAGS  # -march=native, no fused multiply-adds
from .native import native_target_of

#: Compiler flags; part of every cache key. No -ffast-math: NaN checks must keep working. No
#: contraction to fused multiply-adds: the same results with and without FMA hardware.
CFLAGS = ("-O2", "-fPIC", "-shared", "-fno-math-errno", "-std=c99", "-ffp-contract=off")

_loaded: dict[str, ctypes.CDLL] = {}
#: the private directory used instead of a cache directory that is not safe (one per process)
_fallback: Path | None = None


class CompilerError(JourdainError, RuntimeError):
    """No C compiler, or the generated code did not compile."""


def cache_dir() -> Path:
    """The directory of compiled libraries (created on demand; safe to delete): the private
    temporary one when the configured directory was found not to be private."""
    if _fallback is not None:
        return _fallback
    env = os.environ.get("JOURDAIN_CACHE")
    if env:
        return Path(env).expanduser()
    xdg = os.environ.get("XDG_CACHE_HOME")
    base = Path(xdg).expanduser() if xdg else Path.home() / ".cache"
    return base / "jourdain"


def library_dir() -> Path:
    """Where libraries are built and loaded from: :func:`cache_dir` when it is private (created
    with mode 0700 if missing) and can be written to, else a private temporary directory, with
    one warning saying why (it names the directory and ``JOURDAIN_CACHE``)."""
    global _fallback
    if _fallback is not None:
        return _fallback
    d = cache_dir()
    fix = "make it yours and not writable by others (chmod go-w)"
    try:
        d.mkdir(parents=True, exist_ok=True, mode=0o700)
        why = not_private(d)
        if why is None and d not in _writable:
            why, fix = _unwritable(d), "make it writable"
    except OSError as exc:
        why, fix = f"{d} cannot be created ({exc.strerror})", "make it a directory you can create"
    if why is None:
        return d
    _fallback = Path(tempfile.mkdtemp(prefix="jourdain-"))  # mode 0700, this user's
    atexit.register(shutil.rmtree, _fallback, True)
    warnings.warn(f"jourdain does not use its compile cache {d}: {why}. Compiling into the "
                  f"private temporary directory {_fallback} for this run instead (removed at "
                  f"exit); to keep compiled code between runs, {fix}, or set JOURDAIN_CACHE to "
                  "a private, writable directory.", RuntimeWarning, stacklevel=2)
    return _fallback


#: the cache directories found writable in this process (:func:`_unwritable`)
_writable: set[Path] = set()


def _unwritable(d: Path) -> str | None:
    """Why nothing can be written into ``d`` (a read-only folder or file system), or None:
    tried with a file created and removed there, once per directory and process."""
    try:
        fd, probe = tempfile.mkstemp(prefix=".probe-", dir=d)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        return f"{d} cannot be written to ({exc.strerror})"
    _writable.add(d)
    return None


def compiler() -> str:
    """The C compiler: ``$CC``, else ``cc``, ``gcc`` or ``clang`` on the PATH (looked up once
    per value of ``$CC`` and ``$PATH``: every cache key asks, see :func:`native_target`)."""
    cand = [os.environ["CC"]] if os.environ.get("CC") else ["cc", "gcc", "clang"]
    where = (*cand, os.environ.get("PATH"))
    if where in _found:
        return _found[where]
    for c in cand:
        path = shutil.which(c)
        if path:
            _found[where] = path  # only what was found: a compiler installed later is seen
            return path
    raise CompilerError(
        "no C compiler found (tried " + ", ".join(cand) + "); jourdain compiles its numeric code "
        "with the system's C compiler: install gcc or clang, or set CC")


#: compiler() by ($CC or the default names, $PATH)
_found: dict[tuple[str | None, ...], str] = {}


def native_target() -> str | None:
    """What ``-march=native`` means to the compiler on this machine (the processor and the
    instruction set extensions it enables, as its driver reports them with ``-###``), or None
    when native code is off (``JOURDAIN_NATIVE=0``) or the compiler does not know the flag.
    Asked once per processor and compiler (:mod:`jourdain.numeric.native`)."""
    if os.environ.get("JOURDAIN_NATIVE", "1").strip().lower() in ("0", "no", "false", "off"):
        return None
    try:
        cc = compiler()
    except CompilerError:
        return None
    return None if cc in _native_failed else _native_target(cc)


@lru_cache(maxsize=8)
def _native_target(cc: str) -> str | None:
    # kept in the cache once it exists (an install, which prebuilds, creates none)
    return native_target_of(cc, NATIVE_FLAGS, library_dir() if cache_dir().is_dir() else None)


#: compilers whose native build failed in this process (then portable code)
_native_failed: set[str] = set()


def optimization() -> str | None:
    """``-O0``/``-O1`` for every optimization flag (``JOURDAIN_OPTIMIZE``; module docstring) or
    None for the default flags; JourdainError for another value."""
    level = os.environ.get("JOURDAIN_OPTIMIZE", "").strip()
    if level not in ("0", "1", "", "2"):
        raise JourdainError(f"JOURDAIN_OPTIMIZE={level!r}: give 0 or 1 (faster compiling, "
                            "slower code), or 2 / nothing for the default optimization")
    return f"-O{level}" if level in ("0", "1") else None


def _optimized(flags: Sequence[str]) -> list[str]:
    return [optimization() or f if f.startswith("-O") else f for f in flags]


def host_flags() -> tuple[str, ...]:
    """The flags for this machine's instruction set (empty where native code is off)."""
    return NATIVE_FLAGS if native_target() is not None else ()


def content_key(*parts: str) -> str:
    """SHA-256 of the parts, the compiler flags, the native target, the Python platform and
    the format of the cache's files (:data:`jourdain.numeric.cachefile.FORMAT`)."""
    h = hashlib.sha256()
    for part in (*parts, " ".join(CFLAGS), optimization() or "", native_target() or "portable",
                 sys.platform, FORMAT):
        h.update(part.encode())
        h.update(b"\0")
    return h.hexdigest()[:32]


def prebuilt_dir() -> Path | None:
    """The directory of the libraries compiled at install time (:func:`prebuild`):
    ``$JOURDAIN_PREBUILT`` where set (empty: none), else ``prebuilt/`` beside this module."""
    env = os.environ.get("JOURDAIN_PREBUILT")
    if env is not None:
        return Path(env).expanduser() if env.strip() else None
    return Path(__file__).with_name("prebuilt")


def cached_library(key: str) -> ctypes.CDLL | None:
    """The library cached under ``key`` (in :func:`library_dir`, else in :func:`prebuilt_dir`),
    or None if it was never built (or was deleted, or failed a check and was deleted now)."""
    if key in _loaded:
        return _loaded[key]
    pre = prebuilt_dir()
    for d in (library_dir(), *([pre] if pre is not None else [])):
        so = d / f"{key}.so"
        # missing, someone else's or writable by others (never loaded: rebuilt over), or not
        # whole (truncated, changed, unsealed: deleted, never loaded): the next place, then a
        # build; one of another key is deleted after loading (_open)
        if not so.exists() or read_sealed(so) is None:
            continue
        lib = _open(so, key)
        if lib is not None:
            _loaded[key] = lib
            return lib
    return None


def _open(so: Path, key: str) -> ctypes.CDLL | None:
    """The library ``so`` loaded, if it holds the stamp of ``key`` (built for it, by this
    jourdain: :func:`jourdain.numeric.cachefile.stamp_source`); else unloaded again (nothing of
    it was called), deleted, and None."""
    try:
        lib = ctypes.CDLL(str(so))
    except OSError:
        discard(so)
        return None
    if stamp_of(lib) == stamp(key):
        return lib
    try:  # so that the library rebuilt under this name is loaded, not this one again
        _ctypes.dlclose(lib._handle)
    except (AttributeError, OSError):
        pass
    discard(so)
    return None


def compile_shared(sources: Mapping[str, str | bytes], units: Sequence[str], out: Path,
                   flags: Sequence[str],
                   unit_flags: Sequence[Sequence[str]] | None = None) -> None:
    """Compile the translation ``units`` (names in ``sources``, which may also hold the headers
    they include) into the shared library ``out``: each unit by its own compiler process, in
    parallel, then linked. The sources are written into a private folder beside ``out`` (the
    include path), removed afterwards, and named relative to it, so that the same sources give
    the same bytes in every build (no temporary path in the library). ``out`` is written under a
    private name, sealed (:func:`jourdain.numeric.cachefile.seal`) and renamed into place, so a
    concurrent reader never sees half a library or one without its seal. ``flags`` are for
    compiling (``-shared`` is for the link alone and dropped there); ``unit_flags``, one per
    unit, follow them for that unit alone (``-O3`` overrides ``-O2``). CompilerError names the
    unit."""
    cc = os.path.abspath(compiler())  # the compiler runs in the build folder
    compile_flags = [f for f in _optimized(flags) if f != "-shared"]
    work = Path(tempfile.mkdtemp(prefix=".build-", dir=out.parent))
    try:
        for name, text in sources.items():
            (work / name).write_bytes(text if isinstance(text, bytes) else text.encode())
        objects = [f"{Path(u).stem}.o" for u in units]
        own = ([_optimized(f) for f in unit_flags] if unit_flags is not None
               else [[]] * len(units))
        procs = [subprocess.Popen([cc, *compile_flags, *fl, "-I.", "-c", "-o", o, u], cwd=work,
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
                 for u, o, fl in zip(units, objects, own, strict=True)]
        errors = [p.communicate()[1] for p in procs]
        for p, e, u in zip(procs, errors, units, strict=True):
            if p.returncode != 0:
                raise CompilerError(f"compiling {u} with {cc} failed:\n{e[-4000:]}")
        tmp = work / f"{out.name}.tmp"
        link = subprocess.run([cc, "-shared", "-o", tmp.name, *objects, "-lm"], cwd=work,
                              capture_output=True, text=True)
        if link.returncode != 0:
            raise CompilerError(f"linking {out.name} with {cc} failed:\n{link.stderr[-4000:]}")
        os.chmod(tmp, 0o700)  # this user's alone, whatever the umask
        if not seal(out, tmp.read_bytes()):
            raise OSError(f"cannot write the seal of {out}")
        os.replace(tmp, out)
    finally:
        shutil.rmtree(work, ignore_errors=True)


def build(key: str, source: str | Sequence[str], extra_flags: Sequence[str] = (),
          unit_flags: Sequence[Sequence[str]] | None = None) -> ctypes.CDLL:
    """Compile ``source`` to ``<cache>/<key>.so`` (unless there) and load it.

    ``source`` may be several translation units: they are compiled in parallel (one compiler
    process each, :func:`compile_shared`) and linked into one library; ``<key>.c`` keeps them
    one after the other. ``extra_flags`` follow :data:`CFLAGS` (``-O3`` overrides ``-O2``), and
    ``unit_flags`` (one per unit) follow those for one unit; the caller puts them in ``key``
    (:func:`content_key`).
    """
    lib = cached_library(key)
    if lib is not None:
        return lib
    with build_lock(key):  # one build per key at a time (a background build, then a caller)
        lib = cached_library(key)  # built meanwhile by another thread
        return lib if lib is not None else _build(key, source, extra_flags, unit_flags)


def _build(key: str, source: str | Sequence[str], extra_flags: Sequence[str],
           unit_flags: Sequence[Sequence[str]] | None) -> ctypes.CDLL:
    for _ in range(2):  # once more where another process deleted or replaced it meanwhile
        so = _compile(library_dir(), key, source, extra_flags, unit_flags)
        lib = _open(so, key)
        if lib is not None:
            _loaded[key] = lib
            return lib
    raise CompilerError(f"{so} was compiled, but what is there cannot be loaded as the library "
                        f"of its key (another process replacing it?)")


def prebuild(dest: Path, key: str, source: str | Sequence[str],
             unit_flags: Sequence[Sequence[str]] | None = None) -> Path:
    """Compile a library that no model changes into ``dest`` at install time (``setup.py``;
    :func:`cached_library` looks there after the cache): ``<key>.so`` and its source, as
    :func:`build` would compile it into the cache, with the same flags, and its seal; the files
    of other keys in ``dest`` (an earlier version's) are removed. Returns the library's path; raises
    CompilerError (no compiler, a failed compile), which an install reports and goes on."""
    dest.mkdir(parents=True, exist_ok=True)
    so = _compile(dest, key, source, (), unit_flags)
    for old in dest.iterdir():
        if old.suffix in (".so", ".c", ".sha256") and old.name.split(".")[0] != key:
            old.unlink(missing_ok=True)
    return so


def _compile(d: Path, key: str, source: str | Sequence[str], extra_flags: Sequence[str],
             unit_flags: Sequence[Sequence[str]] | None) -> Path:
    """``<d>/<key>.so`` from ``source`` (and ``<d>/<key>.c``): native code where the compiler
    takes it, else portable code for this process. The library holds ``key`` (a unit of its
    own: :func:`jourdain.numeric.cachefile.stamp_source`), checked after every load."""
    units = [source] if isinstance(source, str) else list(source)
    so = d / f"{key}.so"
    src = d / f"{key}.c"
    # the source is kept for reading, also when the compiler fails; written under a private
    # name and renamed into place like the library
    fd, tmp_src = tempfile.mkstemp(suffix=".c.tmp", dir=d)
    with os.fdopen(fd, "w") as fh:
        fh.write("\n".join(units))
    os.replace(tmp_src, src)
    sources = {f"jd_unit{k}.c": u for k, u in enumerate([*units, stamp_source(key)])}
    names = list(sources)
    if unit_flags is not None:
        unit_flags = [*unit_flags, ()]
    native = host_flags()
    try:
        try:
            compile_shared(sources, names, so, (*CFLAGS, *native, *extra_flags), unit_flags)
        except CompilerError:
            if not native:
                raise
            # e.g. an assembler older than the compiler's instruction sets: portable code,
            # for this process (the key stays: the library is correct on this machine); where
            # the portable build fails too, the source is at fault, not the flag
            compile_shared(sources, names, so, (*CFLAGS, *extra_flags), unit_flags)
            _native_failed.add(compiler())
    except CompilerError as exc:
        raise CompilerError(f"compiling {src} failed:\n{str(exc)[-4000:]}") from None
    return so
