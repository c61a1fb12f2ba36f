"""The files of the compile cache: written whole or not at all, sealed by a checksum, checked
before they are used, and bound to their key.

Loading a library runs its code, and unpickling runs what the pickle says. A file of the cache
(a library, a pickled compiled function, a pickled URDF model) is therefore used only when

1. it belongs to the user and no one else may write to it, in a folder of the same kind
   (:func:`not_private`; the folder is checked by :func:`jourdain.numeric.toolchain.library_dir`);
2. its SHA-256 is the one in its *seal*, the file ``<name>.sha256`` beside it, written whole
   (under a temporary name, then renamed) after the file's content is complete and before the
   file is renamed into place (:func:`seal`, :func:`keep_sealed`). A file whose seal is missing
   or differs (cut short by a full disk or a killed process, bytes changed on disk, copied from
   elsewhere, written by an earlier jourdain) is deleted with its seal and built again
   (:func:`read_sealed`): a damaged library never reaches the dynamic loader, where it crashes
   the process (SIGBUS for a truncated file, SIGSEGV or SIGILL for changed code);
3. it was built for its key. A sound file of another model (another key's library and its seal,
   copied over this key's) passes the checksum, so every library holds its key
   (:func:`stamp_source`, read back after loading by :func:`stamp_of`, before anything of the
   library is called) and every pickle holds its key beside its object (:func:`dump_pickle`,
   :func:`load_pickle`); a file of another key is deleted and built again.

The seal guards against damage, not against an attacker: one who may write the file may write
its seal; rule 1 keeps others from writing either. Only the standard library is imported here
(``setup.py`` loads this module without jourdain's package).
"""

from __future__ import annotations

import ctypes
import hashlib
import os
import pickle
import stat
import tempfile
from pathlib import Path

#: the version of the cache's files (seals, stamps, pickles): part of every key
#: (:func:`jourdain.numeric.toolchain.content_key`) and of every library's stamp, so that the
#: files of a jourdain that wrote them otherwise are never looked up
FORMAT = "jourdain-cache-2"
#: the suffix of a file's seal
SEAL = ".sha256"
#: the exported symbol holding a library's stamp (:func:`stamp_source`)
STAMP_SYMBOL = "jd_library_stamp"


def not_private(path: Path) -> str | None:
    """Why ``path`` cannot be trusted to hold code to load, or None: it must belong to the user
    running jourdain and be writable by no one else (no group or other write permission)."""
    try:
        st = os.stat(path)
    except OSError as exc:
        return f"{path} cannot be examined ({exc.strerror})"
    uid = os.getuid() if hasattr(os, "getuid") else None
    if uid is not None and st.st_uid != uid:
        return f"{path} belongs to user id {st.st_uid}, not to you (user id {uid})"
    if st.st_mode & (stat.S_IWGRP | stat.S_IWOTH):
        who = " and ".join(w for w, bit in (("its group", stat.S_IWGRP),
                                            ("all users", stat.S_IWOTH)) if st.st_mode & bit)
        return f"{path} is writable by {who} (mode {stat.filemode(st.st_mode)})"
    return None


def keep_file(path: Path, data: bytes) -> bool:
    """Write ``data`` to ``path`` whole or not at all: under a private temporary name beside it,
    then renamed into place, so that a concurrent reader (another process, another thread)
    never sees half a file. For the cache's entries: one that cannot be written costs time,
    not results (an OSError leaves nothing behind and is not raised; False)."""
    tmp: str | None = None
    try:
        path.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.replace(tmp, path)
        return True
    except OSError:
        if tmp is not None:
            try:
                os.unlink(tmp)
            except OSError:
                pass
        return False


def seal_path(path: Path) -> Path:
    """Where the seal of ``path`` is: ``<name>.sha256`` beside it."""
    return path.with_name(path.name + SEAL)


def digest(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def seal(path: Path, data: bytes) -> bool:
    """Write the seal of ``data``, the complete content that ``path`` is about to be given
    (call it before renaming the file into place: no complete file is ever without its seal);
    False where it cannot be written (then the file is not worth writing either)."""
    return keep_file(seal_path(path), f"{digest(data)}\n".encode())


def keep_sealed(path: Path, data: bytes) -> None:
    """:func:`keep_file` with its seal (written first)."""
    if seal(path, data):
        keep_file(path, data)


def discard(path: Path) -> None:
    """Delete ``path`` and its seal (what cannot be deleted stays, never loaded)."""
    for p in (path, seal_path(path)):
        try:
            p.unlink(missing_ok=True)
        except OSError:
            pass


def read_sealed(path: Path) -> bytes | None:
    """The content of ``path`` when it may be used: private (:func:`not_private`) and the same
    as its seal says. None when it is missing or not private (left: it is never used, and the
    next build replaces it), or when its seal is missing or differs: then it is deleted with its
    seal, never left in place."""
    if not_private(path) is not None:
        return None
    try:
        data = path.read_bytes()
    except OSError:
        return None
    try:
        want = seal_path(path).read_text(encoding="ascii").strip()
    except (OSError, UnicodeDecodeError):
        want = ""
    if digest(data) != want:
        discard(path)
        return None
    return data


def stamp(key: str) -> str:
    """What the library built for ``key`` holds (:func:`stamp_source`)."""
    if not key or not all(c.isalnum() or c in "-_." for c in key):
        raise ValueError(f"a cache key is letters, digits, '-', '_' and '.', got {key!r}")
    return f"{FORMAT} {key}"


def stamp_source(key: str) -> str:
    """A translation unit that exports the stamp of ``key`` as data (reading it runs no code
    of the library): compiled into every library built for the cache."""
    return f'const char {STAMP_SYMBOL}[] = "{stamp(key)}";\n'


def stamp_of(lib: ctypes.CDLL) -> str | None:
    """The stamp of a loaded library; None when it has none (not built by this jourdain)."""
    try:
        first = ctypes.c_char.in_dll(lib, STAMP_SYMBOL)
    except ValueError:
        return None
    return ctypes.string_at(ctypes.addressof(first)).decode("ascii", "replace")


def dump_pickle(key: str, obj: object) -> bytes:
    """``obj`` pickled with ``key`` beside it, for :func:`load_pickle`."""
    return pickle.dumps((FORMAT, key, obj), protocol=pickle.HIGHEST_PROTOCOL)


def load_pickle(path: Path, key: str) -> object | None:
    """The object pickled under ``key`` in ``path`` (:func:`keep_sealed` of
    :func:`dump_pickle`), unpickled only after :func:`read_sealed` found the file private and
    whole; None when there is none, and a file of another key or format, or one that cannot be
    unpickled, is deleted."""
    data = read_sealed(path)
    if data is None:
        return None
    try:
        fmt, held, obj = pickle.loads(data)  # noqa: S301 - private, sealed, this user's own
    except Exception:  # noqa: BLE001 - an entry that cannot be read back is built again
        fmt = held = obj = None
    if fmt != FORMAT or held != key:
        discard(path)
        return None
    return obj
