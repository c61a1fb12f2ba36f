"""The ``jourdain`` command: model files in, equations, numbers and reports out.

A thin layer over the public API. Exit status: 0 on success, 1 on a model error (the message,
no traceback; a failed simulation writes the motion up to the failure first), 2 on a usage error
(a malformed option, a name the model does not have, an output that cannot be written), 130
when interrupted (Ctrl-C: what was computed is written and says so). Every subcommand has
``--help`` with an example. Control characters in any text printed (names and messages from a
model file) are shown escaped, never sent to the terminal.

The package: :mod:`~jourdain.cli.parser` (the options), :mod:`~jourdain.cli.arguments`
(reading them), :mod:`~jourdain.cli.outputs` (files, progress, terminal text) and one module
per group of subcommands (:mod:`~jourdain.cli.model_commands`: check, eom;
:mod:`~jourdain.cli.numbers`: eval, reactions, linearize; :mod:`~jourdain.cli.running`:
simulate, run, fmu). The workflow they share with the report is :mod:`jourdain.workflow`.
"""

from __future__ import annotations

import os
import sys
import warnings
from collections.abc import Sequence
from typing import Any

from ..errors import JourdainError, shorten_words
from ..workflow import EVAL_FORMAT, NotAvailable
from .arguments import UsageError
from .numbers import reaction_units
from .numbers import wrench_text as _wrench_text
from .outputs import PROGRESS_SECONDS, Printable, printable
from .parser import build_parser

EXIT_OK, EXIT_MODEL, EXIT_USAGE, EXIT_INTERRUPTED = 0, 1, 2, 130

__all__ = [
    "main", "build_parser", "printable", "reaction_units", "UsageError", "NotAvailable",
    "EVAL_FORMAT", "PROGRESS_SECONDS", "EXIT_OK", "EXIT_MODEL", "EXIT_USAGE",
    "EXIT_INTERRUPTED", "_wrench_text",
]


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``jourdain`` console script; returns the exit status."""
    out, err = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = Printable(out), Printable(err)
    try:
        return _main(argv)
    finally:
        if isinstance(sys.stdout, Printable):
            sys.stdout = out
        if isinstance(sys.stderr, Printable):
            sys.stderr = err


#: NumPy's floating-point warnings: the results they concern are checked for inf and NaN, and
#: such a result is an error that names the quantity; the warning itself says nothing more
_FLOATING_POINT = r"(overflow|invalid value|divide by zero|underflow) encountered"


def _main(argv: Sequence[str] | None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help(sys.stderr)
        return EXIT_USAGE
    with warnings.catch_warnings():  # restores the filters and showwarning at the end
        warnings.filterwarnings("ignore", _FLOATING_POINT, RuntimeWarning)
        warnings.showwarning = _warning_line(args.command)
        return _run(args)


def _warning_line(command: str) -> Any:
    """``warnings.showwarning`` for the command line: one line, ``jourdain <command>: warning:
    <message>``, never the Python source file and line that issued it."""

    def show(message: Warning | str, category: type[Warning], filename: str, lineno: int,
             file: Any = None, line: str | None = None) -> None:
        # the advice in the command line's words where the warning has them
        text = " ".join(str(getattr(message, "command_line", "") or message).split())
        print(f"jourdain {command}: warning: {shorten_words(text)}",
              file=file or sys.stderr)
    return show


def _run(args: Any) -> int:
    try:
        return int(args.func(args))
    except UsageError as exc:
        print(f"jourdain {args.command}: usage error: {shorten_words(str(exc))}",
              file=sys.stderr)
        return EXIT_USAGE
    except NotAvailable as exc:
        print(f"jourdain {args.command}: {shorten_words(str(exc))}", file=sys.stderr)
        return EXIT_MODEL
    except JourdainError as exc:
        if isinstance(exc.__cause__, KeyboardInterrupt):  # a SciPy method's run, Ctrl-C
            print(f"jourdain {args.command}: interrupted (Ctrl-C): {exc}", file=sys.stderr)
            return EXIT_INTERRUPTED
        print(f"jourdain {args.command}: error: {shorten_words(str(exc))}", file=sys.stderr)
        return EXIT_MODEL
    except KeyboardInterrupt:
        print(f"jourdain {args.command}: interrupted (Ctrl-C)", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # output piped into head & co.
        sys.stdout = open(os.devnull, "w")  # noqa: SIM115 - silence the flush at exit
        return EXIT_OK
    except OSError as exc:  # an output that failed after the checks (a full disk)
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"jourdain {args.command}: error: cannot write {where}{exc.strerror or exc}",
              file=sys.stderr)
        return EXIT_MODEL


