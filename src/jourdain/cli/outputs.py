"""What the commands write: checked output files and folders, progress lines on stderr, and
text made safe for the terminal (:func:`printable`)."""

from __future__ import annotations

import re
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ..io.report import model_copy, report_files
from .arguments import UsageError

#: seconds between two progress lines of a long simulation
PROGRESS_SECONDS = 2.0


def writable_folder(folder: Path, option: str, text: str) -> None:
    """Create ``folder`` (and its parents) and check that a file can be written in it."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            pass
    except (FileExistsError, NotADirectoryError):
        raise UsageError(f"{option} {text}: a part of the path {folder} is a file, not a "
                         "folder") from None
    except OSError as exc:
        raise UsageError(f"{option} {text}: cannot write in the folder {folder}: "
                         f"{exc.strerror or exc}") from None


def output_file(text: str, force: bool, suffixes: Sequence[str],
                 option: str = "--out") -> Path:
    """The results file of ``--out``, checked before any work: a known type, a folder that
    can be written, not an existing file unless ``--force``."""
    path = Path(text)
    if path.is_dir():
        raise UsageError(f"{option} {text}: is a folder; expected a file name ending in "
                         f"{', '.join(suffixes)}")
    if path.suffix.lower() not in suffixes:
        kind = repr(path.suffix) if path.suffix else "(no extension)"
        raise UsageError(f"{option} {text}: unknown file type {kind}; use "
                         f"{', '.join(suffixes)}")
    if path.exists() and not force:
        raise UsageError(f"{option} {text}: the file exists; --force overwrites it")
    writable_folder(path.parent, option, text)
    return path


def output_folder(text: str, force: bool, model: Any) -> Path:
    """The report folder of ``run --out``, checked before any work: a folder (created if
    missing) that can be written, not the model file's own, holding none of the files the
    report writes unless ``--force``."""

    out = Path(text)
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {text}: is a file; expected a folder for the report")
    src = Path(model.path)
    if out.is_dir() and src.is_file() and out.resolve() == src.resolve().parent:
        raise UsageError(f"--out {text}: is the folder of the model file {model.path}; the "
                         f"report writes {model_copy(model)}, report.html and its "
                         "data files into a "
                         "folder of their own (e.g. --out report/)")
    if out.is_dir() and not force:
        clash = [n for n in report_files(model) if (out / n).exists()]
        if clash:
            shown = ", ".join(clash[:6]) + (", …" if len(clash) > 6 else "")
            raise UsageError(f"--out {text}: would overwrite {shown}; --force overwrites them")
    writable_folder(out, "--out", text)
    return out


class Progress:
    """Prints t and the fraction done to stderr every :data:`PROGRESS_SECONDS` of a long
    simulation (on a terminal one line rewritten in place, else a line each time)."""

    def __init__(self, stream: Any, tty: bool, label: str) -> None:
        self.stream, self.tty, self.label = stream, tty, printable(label)
        self.last = time.monotonic()
        self.width = 0

    def __call__(self, t: float, t1: float) -> None:
        now = time.monotonic()
        if now - self.last < PROGRESS_SECONDS:
            return
        self.last = now
        line = f"{self.label}: t = {t:.6g} of {t1:.6g} ({100 * t / t1:.0f} %)"
        if self.tty:
            self.stream.write("\r" + line.ljust(self.width))
            self.width = len(line)
        else:
            self.stream.write(line + "\n")
        self.stream.flush()

    def done(self) -> None:
        if self.tty and self.width:
            self.stream.write("\n")
            self.stream.flush()
            self.width = 0


def progress_printer(asked: bool, label: str) -> Progress | None:
    """A progress printer when asked (``--progress``) or when stderr is a terminal."""
    stream = sys.stderr
    tty = bool(getattr(stream, "isatty", lambda: False)())
    if not (asked or tty):
        return None
    return Progress(getattr(stream, "raw", stream), tty, label)


def samples(n: int) -> str:
    return f"{n} sample" + ("" if n == 1 else "s")



_CONTROL = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\u2028\u2029\u202a-\u202e\u2066-\u2069]")


def printable(text: str) -> str:
    """``text`` with control characters other than line breaks and tabs written as escapes
    (``\\x1b``): names and messages from a model file never reach the terminal as escape
    sequences or hidden text."""
    return _CONTROL.sub(lambda m: m.group().encode("unicode_escape").decode("ascii"), text)


class Printable:
    """A text stream that writes through :func:`printable` (``raw``: the stream itself)."""

    def __init__(self, raw: Any) -> None:
        self.raw = raw

    def write(self, text: str) -> int:
        return self.raw.write(printable(text))

    def __getattr__(self, name: str) -> Any:
        return getattr(self.raw, name)

