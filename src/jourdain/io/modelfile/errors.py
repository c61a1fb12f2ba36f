"""Mistakes in model files: :class:`ModelFileError` and how an error is located in the file
(line and key path) and worded.
"""

from __future__ import annotations

import difflib
import re

from ...errors import ModelError, shorten_words
from ..toml_positions import Path, deep_nesting, key_lines, line_of
from .schema import _MAX_NESTING, _TOP, MAX_FILE_BYTES


class ModelFileError(ModelError):
    """A mistake in a model file. ``file``, ``line`` and ``path`` (the key path) say where."""

    def __init__(self, message: str, file: str, line: int | None, path: Path = (),
                 detail: str = "") -> None:
        super().__init__(message)
        self.file = file
        self.line = line
        self.path = path
        self.detail = detail



def _clip(text: str, n: int = 120) -> str:
    """``text`` for a message: at most ``n`` characters, the middle left out."""
    return text if len(text) <= n else f"{text[:n // 2]} … {text[-n // 2:]}"


def _too_big(size: int, text: str | None = None) -> str | None:
    """Why a file of ``size`` bytes (or characters of ``text``) is refused, or None."""
    if text is not None and size <= MAX_FILE_BYTES < 4 * size:
        size = len(text.encode("utf-8", "surrogatepass"))
    if size <= MAX_FILE_BYTES:
        return None
    return (f"the file is too large ({size / 1e6:.1f} MB); model files are at most "
            f"{MAX_FILE_BYTES / 1e6:g} MB")


def _type_name(v: object) -> str:
    if isinstance(v, bool):
        return "a boolean"
    if isinstance(v, int | float):
        return f"the number {v!r}"
    if isinstance(v, str):
        return f'the string "{v}"'
    if isinstance(v, dict):
        return "a table"
    if isinstance(v, list):
        return f"an array of {len(v)} item{'s' if len(v) != 1 else ''}"
    return type(v).__name__


def describe_path(path: Path) -> str:
    """``("bodies", "link2", "joint", "axis")`` → ``body "link2" → joint → axis``."""
    singular = {"bodies": "body", "forces": "force", "parameters": "parameter",
                "coordinates": "coordinate", "inputs": "input", "nominal": "nominal motion",
                "quantities": "quantity"}
    parts: list[str] = []
    items = list(path)
    if len(items) >= 2 and items[0] in singular and isinstance(items[1], str):
        parts.append(f'{singular[str(items[0])]} "{items[1]}"')
        items = items[2:]
    elif items and isinstance(items[0], str):
        parts.append(f"[{items[0]}]" if items[0] in _TOP else str(items[0]))
        items = items[1:]
    for it in items:
        if isinstance(it, int):
            if parts:
                parts[-1] += f"[{it}]"
            else:
                parts.append(f"[{it}]")
        else:
            parts.append(str(it))
    return " → ".join(parts) if parts else "the file"



class Locator:
    """Where things are in a model file's text: the line of each key path, and errors worded
    with file, line and key path."""

    def __init__(self, text: str, filename: str) -> None:
        self.file = filename
        self.text = text
        self._lines: dict[Path, int] | None = None
        self.body_names: list[str] = []
        self.joint_of_body: dict[str, str] = {}

    @property
    def lines(self) -> dict[Path, int]:
        """Line of every key path, scanned on first use: only a file with a mistake needs it."""
        if self._lines is None:
            self._lines = key_lines(self.text)
        return self._lines

    # --- errors ---------------------------------------------------------------------------
    def fail(self, path: Path, message: str) -> ModelFileError:
        line = line_of(self.lines, path)
        where = describe_path(path)
        for k in range(len(path), 0, -1):  # a core message that names the same element
            prefix = describe_path(path[:k]) + ": "
            if message.startswith(prefix):
                message = message[len(prefix):]
                break
        loc = f"{self.file}:{line}" if line else self.file
        message = shorten_words(message)  # a value of 5 000 characters, not echoed whole
        return ModelFileError(f"{loc}: {where}: {message}", self.file, line, path, message)

    def missing(self, message: str) -> ModelFileError:
        """A table the file lacks, located at its first line (a file whose table headers
        were swallowed, e.g. by an unterminated multi-line string, still names a line)."""
        return ModelFileError(f"{self.file}:1: the file: {message}", self.file, 1, (), message)

    def suggest(self, word: str, options: list[str]) -> str:
        close = difflib.get_close_matches(word, options, n=1)
        if not close:  # a name in the other case ("G" for "g") is close, however short
            close = [o for o in options if o.lower() == word.lower()][:1]
        return f' (did you mean "{close[0]}"?)' if close else ""


    def nesting_error(self) -> ModelFileError:
        """The TOML reader recursed too deeply: name the value nested deepest."""
        found = deep_nesting(self.text, _MAX_NESTING)
        why = (f"arrays or inline tables nested too deeply (more than {_MAX_NESTING} levels; "
               "a model file needs a few)")
        if found is None:
            return ModelFileError(f"{self.file}: {why}", self.file, None, (), why)
        path, line = found
        return ModelFileError(f"{self.file}:{line}: {describe_path(path)}: {why}", self.file,
                              line, path, why)

    def locate(self, message: str) -> Path:
        """Best key path for an error the core raised about the assembled system: the element
        named first in the message."""
        found: list[tuple[int, Path]] = []
        for m in re.finditer(r'body "(\w+)"', message):
            if m.group(1) in self.body_names:
                found.append((m.start(), ("bodies", m.group(1))))
        for m in re.finditer(r'joint "(\w+)"', message):
            for b, j in self.joint_of_body.items():
                if j == m.group(1):
                    found.append((m.start(), ("bodies", b, "joint")))
        for m in re.finditer(r'(?:force|spring-damper|torque|bushing|joint friction) "(\w+)"',
                             message):
            found.append((m.start(), ("forces", m.group(1))))
        for m in re.finditer(r'quantity "(\w+)"', message):
            found.append((m.start(), ("quantities", m.group(1))))
        if found:
            return min(found)[1]
        if "coordinate" in message:
            return ("coordinates",)
        return ()


