"""Meshes already read, kept so that a mesh file is parsed once: in this process by file
(resolved path, modification time and size: a mesh used by several visuals, such as the four
legs of a quadruped, or by several views) and on disk by content (SHA-256 of the file's bytes
and :data:`FORMAT`) in ``<cache>/meshes/`` next to the compiled libraries
(:func:`jourdain.numeric.toolchain.cache_dir`), so that the next ``jourdain run`` of a robot
does not parse its COLLADA files again.

The stored arrays are the parsed ones bit for bit (``.npz``, float64 and int64), and they are
read without pickles; a stored file that cannot be read is parsed again. The arrays handed out
are read-only, since every user of a file shares them.
"""

from __future__ import annotations

import hashlib
import io
import os
from collections import OrderedDict
from pathlib import Path

import numpy as np

from ...numeric.toolchain import cache_dir, keep_file

#: version of the parsed form: a change to the readers changes it, and the stored meshes of
#: older readers are not used
FORMAT = "jourdain-mesh/1"
#: meshes kept in memory (least recently used dropped first)
MEMORY_ENTRIES = 64

Arrays = tuple[np.ndarray, np.ndarray, tuple[tuple[int, int, tuple[float, float, float] | None], ...]]

_memory: OrderedDict[tuple[str, int, int], Arrays] = OrderedDict()


def file_key(path: Path, st: os.stat_result) -> tuple[str, int, int]:
    """The in-memory key of a mesh file: resolved path, modification time (ns), size."""
    return (str(path.resolve()), st.st_mtime_ns, st.st_size)


def remembered(key: tuple[str, int, int]) -> Arrays | None:
    hit = _memory.get(key)
    if hit is not None:
        _memory.move_to_end(key)
    return hit


def remember(key: tuple[str, int, int], arrays: Arrays) -> Arrays:
    """Keep ``arrays`` (made read-only) for ``key``; returns them."""
    for a in arrays[:2]:
        a.setflags(write=False)
    _memory[key] = arrays
    while len(_memory) > MEMORY_ENTRIES:
        _memory.popitem(last=False)
    return arrays


def digest(data: bytes, suffix: str) -> str:
    return hashlib.sha256(FORMAT.encode() + b"\0" + suffix.encode() + b"\0" + data).hexdigest()


def _stored(key: str) -> Path:
    return cache_dir() / "meshes" / f"{key}.npz"


def load(key: str) -> Arrays | None:
    """The stored arrays of the file with content ``key`` (:func:`digest`), or None."""
    path = _stored(key)
    try:
        with np.load(path, allow_pickle=False) as z:
            vertices, faces = np.array(z["vertices"]), np.array(z["faces"])
            starts, counts, colours = z["starts"], z["counts"], z["colours"]
    except (OSError, KeyError, ValueError):
        return None
    groups = tuple((int(s), int(n), None if np.isnan(c[0]) else
                    (float(c[0]), float(c[1]), float(c[2])))
                   for s, n, c in zip(starts, counts, colours, strict=True))
    return vertices, faces, groups


def store(key: str, arrays: Arrays) -> None:
    """Store the arrays under ``key`` (written under a private name and renamed into place, so
    that a concurrent reader never sees half a file); nothing when the cache is not writable."""
    vertices, faces, groups = arrays
    colours = np.array([c if c is not None else (np.nan,) * 3 for _, _, c in groups],
                       dtype=float).reshape(-1, 3)
    buf = io.BytesIO()
    np.savez(buf, vertices=vertices, faces=faces,
             starts=np.array([g[0] for g in groups], dtype=np.int64),
             counts=np.array([g[1] for g in groups], dtype=np.int64), colours=colours)
    keep_file(_stored(key), buf.getvalue())
