"""Worker processes of ``jourdain run``: the report's symbolic display and its figures are
computed in processes forked from the command's, while it computes the numbers (two cores
or more: the report of a small model in about half the time)."""

from __future__ import annotations

import multiprocessing
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor


def _ready() -> bool:
    return True


def fork_worker(initializer: Callable[[], None] | None = None) -> ProcessPoolExecutor | None:
    """A pool of one worker process forked from this one now (it shares what this process
    has computed so far: the symbolic equations), or None where processes cannot be forked
    (the work then stays in this process)."""
    try:
        context = multiprocessing.get_context("fork")
    except ValueError:  # no fork on this platform
        return None
    pool = ProcessPoolExecutor(1, mp_context=context, initializer=initializer)
    pool.submit(_ready)  # forks now, not at the first real job
    return pool
