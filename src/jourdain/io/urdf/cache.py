"""The models read from URDF files, kept in the compile cache.

Reading a URDF file needs yourdfpy, whose import (it imports trimesh, and trimesh SciPy's
spatial package) takes about 0.6 s, a third of a report's time (``benchmarks/report.py``:
``planar_arm.urdf`` 1.9 s against 1.3 s for the same report from a cached model). The model
built from a file is therefore kept in the cache directory of the compiled libraries
(:func:`jourdain.numeric.toolchain.library_dir`: private to the user, as the libraries loaded
from it are), pickled, under a SHA-256 of everything it is built from: the file's bytes and
path, the options of :func:`~jourdain.io.urdf.load_urdf`, and the source of the modules that
build it and of the model's classes (a changed jourdain makes new keys, never stale models).
The pickle holds its key and is sealed by its checksum, and it is unpickled only after the
checks of :mod:`jourdain.numeric.cachefile`: the file (not only its folder) belongs to the user
and no one else may write to it, it is whole (its SHA-256 against its seal) and of this key;
a file that fails them is deleted. A model that cannot be read back is built again; a cache
that cannot be written costs time, not results.
"""

from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Any

from ...numeric.cachefile import dump_pickle, keep_sealed, load_pickle
from ...numeric.toolchain import library_dir
from .model import UrdfModel

__all__ = ["cached", "keep", "model_key"]

FORMAT = "jourdain-urdf-model-2"

#: the packages whose source a cached model depends on (relative to jourdain's root)
_SOURCES = ("io/urdf", "model")


def model_key(raw: bytes, path: str, options: dict[str, Any]) -> str:
    """The cache key of the model built from ``raw`` (the file at ``path``) with ``options``."""
    h = hashlib.sha256()
    for part in (FORMAT, path, repr(sorted(options.items()))):
        h.update(part.encode("utf-8", "surrogatepass"))
        h.update(b"\x00")
    h.update(raw)
    root = Path(__file__).resolve().parents[2]
    for rel in _SOURCES:
        for src in sorted((root / rel).glob("*.py")):
            h.update(src.name.encode())
            h.update(src.read_bytes())
    return h.hexdigest()


def _file(key: str) -> Path:
    return library_dir() / "urdf" / f"{key}.pickle"


def cached(key: str) -> UrdfModel | None:
    """The model kept under ``key``; None when there is none or it cannot be used."""
    model = load_pickle(_file(key), key)
    return model if isinstance(model, UrdfModel) else None


def keep(key: str, model: UrdfModel) -> None:
    """Keep ``model`` under ``key`` (written whole under a temporary name, then renamed, after
    its seal)."""
    try:
        data = dump_pickle(key, model)
    except Exception:  # noqa: BLE001 - a model that cannot be pickled is built next time
        return
    keep_sealed(_file(key), data)
