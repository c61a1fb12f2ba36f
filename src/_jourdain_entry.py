"""The ``jourdain`` console script: :func:`jourdain.cli.main`, imported here so that Ctrl-C
while it imports ends the command with exit status 130 and one line, not a traceback.

This module lies outside the ``jourdain`` package on purpose: importing anything inside it
runs ``jourdain/__init__`` first (NumPy, SymEngine, SymPy: the first 0.1–0.5 s of every
command), and an exception raised there reaches no handler of the command line. Nothing
here imports more than :mod:`sys` and :mod:`signal` before that import, and the extension
modules are imported with Ctrl-C held back (:func:`_import_extensions`).
"""

from __future__ import annotations

import signal
import sys

#: the exit status of an interrupted command (jourdain.cli.EXIT_INTERRUPTED)
EXIT_INTERRUPTED = 130


def main() -> int:
    """Run the command line; Ctrl-C while it starts, or after its own handlers, exits 130;
    once the command is done, Ctrl-C changes nothing (Python's finalization would otherwise
    die by the signal, a status of 130 for a command whose files say it finished)."""
    try:
        _import_extensions()
        from jourdain.cli import main as run
    except KeyboardInterrupt:
        return _interrupted("while starting")
    except Exception as exc:  # Python wraps it in a class body (RuntimeError of __set_name__)
        if _by_interrupt(exc):
            return _interrupted("while starting")
        raise
    try:
        code = run()
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        return code
    except KeyboardInterrupt:  # between the command's own handling and its return
        return _interrupted("")
    except Exception as exc:  # an extension that turned Ctrl-C into an error of its own
        if _by_interrupt(exc):
            return _interrupted("")
        raise


def _import_extensions() -> None:
    """Import NumPy and SymEngine with SIGINT held back (where the platform can block a signal).

    Ctrl-C while SymEngine's extension module initializes killed the interpreter with SIGSEGV,
    no message and no status of ours (its module initialization does not survive the
    KeyboardInterrupt raised inside it: reproduced by SIGINT 10-20 ms after start-up with an
    empty compile cache, 7 times in 12). Held back, the signal arrives when the imports are
    done, as a KeyboardInterrupt that :func:`main` turns into exit status 130.
    """
    block = hasattr(signal, "pthread_sigmask")
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT}) if block else None
    try:
        import numpy  # noqa: F401 - imported for its side effect: initialized whole
        import symengine  # noqa: F401
    finally:
        if old is not None:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)


def _by_interrupt(exc: BaseException | None) -> bool:
    """Whether Ctrl-C caused ``exc`` (a KeyboardInterrupt in its chain of causes)."""
    seen = 0
    while exc is not None and seen < 20:
        if isinstance(exc, KeyboardInterrupt):
            return True
        exc, seen = exc.__cause__ or exc.__context__, seen + 1
    return False


def _interrupted(when: str) -> int:
    try:
        print("jourdain: interrupted (Ctrl-C)" + (f" {when}" if when else ""), file=sys.stderr)
    except (OSError, KeyboardInterrupt):  # a closed stream, a second Ctrl-C: the status
        pass
    return EXIT_INTERRUPTED


if __name__ == "__main__":
    sys.exit(main())
