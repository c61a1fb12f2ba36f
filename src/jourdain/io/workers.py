"""Worker processes of the report (``jourdain run``, trees and closed systems alike): the
report's symbolic display and its figures are computed in a process forked from the
command's while it computes the numbers (where the machine has two cores or more)."""

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


def stop_workers(pool: ProcessPoolExecutor) -> None:
    """Shut ``pool`` down without waiting for its work (an error before the report: the
    worker may still be importing Matplotlib, 0.3-0.5 s the user would wait for the message).
    Python 3.14's ``terminate_workers``, else the same by the pool's processes."""
    terminate = getattr(pool, "terminate_workers", None)
    if terminate is not None:
        terminate()
        return
    for process in list((getattr(pool, "_processes", None) or {}).values()):
        process.terminate()
    pool.shutdown(wait=True, cancel_futures=True)


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
