"""Compile generated C once with the system's C compiler and cache the shared library on disk.

The cache is a plain directory (``$JOURDAIN_CACHE``, else ``$XDG_CACHE_HOME/jourdain``, else
``~/.cache/jourdain``) holding ``<key>.c`` (the source, for reading) and ``<key>.so`` (the
library), where ``<key>`` is a SHA-256 hash of the content that determines the code. Deleting
the directory, or any file in it, is always safe: the library is rebuilt on the next use. Only
shared libraries compiled from jourdain's own generated source are loaded; nothing is pickled.
"""

from __future__ import annotations

import ctypes
import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path

from ..errors import JourdainError

#: Compiler flags; part of every cache key. No -ffast-math: NaN checks must keep working.
CFLAGS = ("-O2", "-fPIC", "-shared", "-fno-math-errno", "-std=c99")

_loaded: dict[str, ctypes.CDLL] = {}


class CompilerError(JourdainError, RuntimeError):
    """No C compiler, or the generated code did not compile."""


def cache_dir() -> Path:
    """The directory of compiled libraries (created on demand; safe to delete)."""
    env = os.environ.get("JOURDAIN_CACHE")
    if env:
        return Path(env).expanduser()
    xdg = os.environ.get("XDG_CACHE_HOME")
    base = Path(xdg).expanduser() if xdg else Path.home() / ".cache"
    return base / "jourdain"


def compiler() -> str:
    """The C compiler: ``$CC``, else ``cc``, ``gcc`` or ``clang`` on the PATH."""
    cand = [os.environ["CC"]] if os.environ.get("CC") else ["cc", "gcc", "clang"]
    for c in cand:
        path = shutil.which(c)
        if path:
            return path
    raise CompilerError(
        "no C compiler found (tried " + ", ".join(cand) + "); jourdain compiles its numeric code "
        "with the system's C compiler: install gcc or clang, or set CC")


def content_key(*parts: str) -> str:
    """SHA-256 of the parts, the compiler flags and the Python platform."""
    h = hashlib.sha256()
    for part in (*parts, " ".join(CFLAGS), sys.platform):
        h.update(part.encode())
        h.update(b"\0")
    return h.hexdigest()[:32]


def cached_library(key: str) -> ctypes.CDLL | None:
    """The library cached under ``key``, or None if it was never built (or was deleted)."""
    if key in _loaded:
        return _loaded[key]
    so = cache_dir() / f"{key}.so"
    if not so.exists():
        return None
    try:
        lib = ctypes.CDLL(str(so))
    except OSError:  # a truncated or foreign file: rebuild
        return None
    _loaded[key] = lib
    return lib


def build(key: str, source: str | Sequence[str]) -> ctypes.CDLL:
    """Compile ``source`` to ``<cache>/<key>.so`` (unless there) and load it.

    ``source`` may be several translation units: they are compiled in parallel (one compiler
    process each) and linked into one library; ``<key>.c`` keeps them one after the other.
    """
    lib = cached_library(key)
    if lib is not None:
        return lib
    units = [source] if isinstance(source, str) else list(source)
    d = cache_dir()
    d.mkdir(parents=True, exist_ok=True)
    so = d / f"{key}.so"
    src = d / f"{key}.c"
    # write and compile under private names, then rename: a concurrent build of the same key
    # (another process) never sees a half-written source or library
    fd, tmp = tempfile.mkstemp(suffix=".so", dir=d)
    os.close(fd)
    tmp_units: list[str] = []
    objects: list[str] = []
    try:
        for text in units:
            fd, tmp_c = tempfile.mkstemp(suffix=".c", dir=d)
            with os.fdopen(fd, "w") as fh:
                fh.write(text)
            tmp_units.append(tmp_c)
        if len(units) == 1:
            procs = [subprocess.Popen([compiler(), *CFLAGS, "-o", tmp, tmp_units[0], "-lm"],
                                      stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)]
        else:
            objects = [u[:-2] + ".o" for u in tmp_units]
            flags = [f for f in CFLAGS if f != "-shared"]
            procs = [subprocess.Popen([compiler(), *flags, "-c", "-o", o, u],
                                      stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
                     for u, o in zip(tmp_units, objects, strict=True)]
        errors = [p.communicate()[1] for p in procs]
        failed = [e for p, e in zip(procs, errors, strict=True) if p.returncode != 0]
        if not failed and objects:
            link = subprocess.run([compiler(), "-shared", "-o", tmp, *objects, "-lm"],
                                  capture_output=True, text=True)
            if link.returncode != 0:
                failed.append(link.stderr)
        # kept for reading, also when the compiler fails
        with open(src, "w") as fh:
            fh.write("\n".join(units))
        if failed:
            raise CompilerError(f"compiling {src} failed:\n{failed[0][-4000:]}")
        os.replace(tmp, so)
    finally:
        for leftover in (tmp, *tmp_units, *objects):
            if os.path.exists(leftover):
                os.unlink(leftover)
    lib = ctypes.CDLL(str(so))
    _loaded[key] = lib
    return lib
