"""The locks of the compile cache's builds, one per library (or larger step), and builds
started in a thread (:func:`build_soon`): one thread of a process builds a library at a time,
the others wait for it (:func:`jourdain.numeric.toolchain.build`). Only the standard library
is imported (``setup.py`` loads the toolchain without jourdain's package).
"""

from __future__ import annotations

import os
import threading
from collections.abc import Callable

_BUILDING: dict[str, threading.Lock] = {}
_BUILDING_GUARD = threading.Lock()


def build_lock(name: str) -> threading.Lock:
    """The lock of one build, by ``name`` (a library's key, or a name of the caller's for a
    larger step that builds, such as generating a source): one thread at a time builds it,
    the others wait and then find it built. Fresh in a child forked while it was held."""
    with _BUILDING_GUARD:
        return _BUILDING.setdefault(name, threading.Lock())


def _forget_builds() -> None:
    """In a child forked while a thread built: the build's locks are the parent's (none of
    its threads runs here to release them); fresh ones."""
    global _BUILDING_GUARD
    _BUILDING.clear()
    _BUILDING_GUARD = threading.Lock()


os.register_at_fork(after_in_child=_forget_builds)


def build_soon(fn: Callable[..., object], *args: object, name: str = "jourdain-build") -> None:
    """Start ``fn(*args)``, a function that builds a library (through :func:`jourdain.numeric.toolchain.build`), in a
    thread and return at once: the compiler runs in a process of its own, on another core,
    while the caller goes on (other code to generate and compile). The caller's own later call
    of ``fn`` waits for that build (:func:`~jourdain.numeric.toolchain.build` holds one lock per library), or builds where
    this one failed and raises its error then: the thread's errors are dropped. A child
    forked meanwhile builds for itself."""

    def quietly() -> None:
        try:
            fn(*args)
        except Exception:  # noqa: BLE001 - the caller's own call reports it
            pass

    # not a daemon: an exit waits for the compiler (Ctrl-C stops the compiler with it), so
    # that no half-built library is left in the cache
    threading.Thread(target=quietly, name=name).start()
