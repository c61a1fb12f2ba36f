"""Line numbers of the keys of a TOML document.

:mod:`tomllib` returns plain dicts without positions. To name the line of a mistake, this module
scans the (already syntax-checked) text once and records, for every key path — table headers,
``key = value`` lines, keys inside inline tables and elements of arrays — the line it starts on.
It only follows the structure; values are not interpreted.
"""

from __future__ import annotations

Path = tuple[str | int, ...]

_BARE = set("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-")


class _Scanner:
    def __init__(self, text: str) -> None:
        self.s = text
        self.i = 0
        self.line = 1
        self.out: dict[Path, int] = {}
        self.aot: dict[Path, int] = {}

    # --- low level ------------------------------------------------------------------------
    def peek(self, k: int = 0) -> str:
        j = self.i + k
        return self.s[j] if j < len(self.s) else ""

    def advance(self, n: int = 1) -> None:
        for _ in range(n):
            if self.i < len(self.s):
                if self.s[self.i] == "\n":
                    self.line += 1
                self.i += 1

    def skip_ws(self, newlines: bool) -> None:
        while self.i < len(self.s):
            c = self.s[self.i]
            if c in " \t\r" or (newlines and c == "\n"):
                self.advance()
            elif c == "#":
                while self.i < len(self.s) and self.s[self.i] != "\n":
                    self.i += 1
            else:
                return

    def string(self) -> str:
        """Skip a string literal starting here; return its (approximate) content."""
        q = self.peek()
        if self.s.startswith(q * 3, self.i):
            self.advance(3)
            start = self.i
            while self.i < len(self.s) and not self.s.startswith(q * 3, self.i):
                if q == '"' and self.peek() == "\\":
                    self.advance()
                self.advance()
            content = self.s[start:self.i]
            self.advance(3)
            while self.peek() == q:  # up to two quotes may end a multi-line string
                self.advance()
            return content
        self.advance()
        start = self.i
        while self.i < len(self.s) and self.peek() != q and self.peek() != "\n":
            if q == '"' and self.peek() == "\\":
                self.advance()
            self.advance()
        content = self.s[start:self.i]
        self.advance()
        return content

    def key(self) -> tuple[str, ...]:
        """A dotted key; stops before '=' or ']'."""
        parts: list[str] = []
        while True:
            self.skip_ws(False)
            c = self.peek()
            if c in ('"', "'"):
                parts.append(self.string())
            else:
                start = self.i
                while self.peek() and self.peek() in _BARE:
                    self.i += 1
                if self.i == start:
                    return tuple(parts)
                parts.append(self.s[start:self.i])
            self.skip_ws(False)
            if self.peek() == ".":
                self.i += 1
                continue
            return tuple(parts)

    # --- structure ------------------------------------------------------------------------
    def document(self) -> dict[Path, int]:
        current: Path = ()
        while True:
            self.skip_ws(True)
            if self.i >= len(self.s):
                return self.out
            line = self.line
            if self.s.startswith("[[", self.i):
                self.i += 2
                path = self.key()
                self.skip_ws(False)
                self.i += 2  # "]]"
                self.aot[path] = self.aot.get(path, 0) + 1
                # sub-tables of an array element restart the counting of nested arrays
                for p in [p for p in self.aot if len(p) > len(path) and p[:len(path)] == path]:
                    del self.aot[p]
                current = self._resolve(path)
                self.out.setdefault(current[:-1], line)
                self.out[current] = line
            elif self.peek() == "[":
                self.i += 1
                keys = self.key()
                self.skip_ws(False)
                self.i += 1  # "]"
                current = self._resolve(keys)
                self.out.setdefault(current, line)
            else:
                keys = self.key()
                if not keys:  # not a key: skip the line (the text was checked by tomllib)
                    while self.peek() and self.peek() != "\n":
                        self.i += 1
                    continue
                path = (*current, *keys)
                self.out.setdefault(path, line)
                self.skip_ws(False)
                if self.peek() == "=":
                    self.i += 1
                self.value(path)

    def _resolve(self, keys: tuple[str, ...]) -> Path:
        """Insert the index of the current element after every array-of-tables prefix."""
        out: list[str | int] = []
        for n in range(1, len(keys) + 1):
            out.append(keys[n - 1])
            count = self.aot.get(keys[:n])
            if count:
                out.append(count - 1)
        return tuple(out)

    def value(self, path: Path) -> None:
        self.skip_ws(False)
        c = self.peek()
        if c == "{":
            self.i += 1
            while True:
                self.skip_ws(True)
                if self.peek() in ("}", ""):
                    self.i += 1
                    return
                line = self.line
                keys = self.key()
                if not keys:
                    self.i += 1
                    continue
                sub = (*path, *keys)
                self.out.setdefault(sub, line)
                self.skip_ws(False)
                if self.peek() == "=":
                    self.i += 1
                self.value(sub)
                self.skip_ws(True)
                if self.peek() == ",":
                    self.i += 1
        elif c == "[":
            self.i += 1
            idx = 0
            while True:
                self.skip_ws(True)
                if self.peek() in ("]", ""):
                    self.i += 1
                    return
                self.out.setdefault((*path, idx), self.line)
                self.value((*path, idx))
                self.skip_ws(True)
                if self.peek() == ",":
                    self.i += 1
                idx += 1
        elif c in ('"', "'"):
            self.string()
        else:
            while self.peek() and self.peek() not in ",]}\n#":
                self.i += 1


def key_lines(text: str) -> dict[Path, int]:
    """Map every key path of the TOML ``text`` to the line (1-based) where it is written.

    Paths are tuples of keys and array indices: ``("bodies", "rod1", "joint", "axis")``,
    ``("bodies", "rod1", "com", 1)``, ``("forces", 0, "type")`` for arrays of tables.
    """
    try:
        return _Scanner(text).document()
    except (IndexError, ValueError):  # defensive: positions are a convenience, never fatal
        return {}


def line_of(lines: dict[Path, int], path: Path) -> int | None:
    """The line of ``path``, or of its longest prefix that has one."""
    p = tuple(path)
    while p:
        if p in lines:
            return lines[p]
        # a table created implicitly by a header such as [a.b] has no line of its own
        below = [ln for q, ln in lines.items() if q[:len(p)] == p]
        if below:
            return min(below)
        p = p[:-1]
    return None
