"""Files that say ``interrupted`` whenever a command ends by Ctrl-C (exit status 130).

A command's own handling of Ctrl-C (a simulation keeps its motion, a report the sections it
finished) writes files that say so. Ctrl-C can also come later: while the results are
assembled and saved, while a report's figures are collected, while the summary is printed.
Then the command marks what it wrote (:func:`mark_results`; the report's files:
:func:`jourdain.io.report.mark_report`; a study's: :mod:`jourdain.study.cli`), with Ctrl-C
ignored for the few file operations that takes (:func:`deaf_to_ctrl_c`), and exits 130.
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
from collections.abc import Iterator
from pathlib import Path

from ..simulation.results import mark_interrupted

#: the message of a file marked after the run's own handling
LATE = "interrupted by the user (Ctrl-C) {when}; the data are what was computed up to there"


@contextlib.contextmanager
def deaf_to_ctrl_c() -> Iterator[None]:
    """SIGINT ignored inside (in the main thread; elsewhere nothing changes): a bounded file
    operation that must not be cut short by a second Ctrl-C."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)


@contextlib.contextmanager
def deferred_ctrl_c() -> Iterator[None]:
    """Ctrl-C inside is raised as KeyboardInterrupt at its end (in the main thread;
    elsewhere nothing changes): for imports of C extensions that turn an interruption of
    their initialization into an ImportError and leave the interpreter unable to finalize
    (Matplotlib's ft2font: "initialization failed", then a fatal error at exit)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    hit: list[int] = []
    old = signal.signal(signal.SIGINT, lambda signum, frame: hit.append(signum))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)
    if hit:
        raise KeyboardInterrupt


def mark_results(path: str | Path | None, when: str) -> bool:
    """Mark the results file ``path`` (if the command wrote it) as interrupted ``when``
    (``"as the results were saved"``); False where there is none."""
    if path is None or not os.path.isfile(path):
        return False
    with deaf_to_ctrl_c():
        return mark_interrupted(path, LATE.format(when=when))


def write_text(path: Path, text: str) -> None:
    """``text`` into ``path`` through a temporary file renamed over it."""
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
