"""Worker processes of ``jourdain run``: the report's symbolic display and its figures are
computed in a process forked from the command's while it computes the numbers (where the
machine has two cores or more)."""

from __future__ import annotations

import multiprocessing
import os
import signal
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor


def _ready() -> bool:
    return True


def ignore_interrupt() -> None:
    """A worker's initializer: Ctrl-C is the parent's to handle (it waits for the work of the
    sections it finished)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def cores() -> int:
    """The processor cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def fork_workers(initializer: Callable[[], None] | None = None,
                 workers: int = 1) -> ProcessPoolExecutor | None:
    """A pool of ``workers`` processes forked from this one now (they share what this process
    has computed so far: the symbolic equations), or None where processes cannot be forked
    or a single core would run them by turns with this one (the work then stays here)."""
    if cores() < 2:
        return None
    try:
        context = multiprocessing.get_context("fork")
    except ValueError:  # no fork on this platform
        return None
    pool = ProcessPoolExecutor(workers, mp_context=context, initializer=initializer)
    pool.submit(_ready)  # forks them all now, not at the first real job
    return pool
