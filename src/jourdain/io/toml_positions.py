"""Line numbers of the keys of a TOML document.

:mod:`tomllib` returns plain dicts without positions. To name the line of a mistake, this module
scans the (already syntax-checked) text once and records, for every key path — table headers,
``key = value`` lines, keys inside inline tables and elements of arrays — the line it starts on.
It only follows the structure; values are not interpreted.

The scan moves from token to token with regular expressions (whitespace and comments, strings,
bare values are each skipped by one match), so its time grows with the number of keys and
values, not of characters (a few MB of model file in well under a second), and it follows
nested arrays and inline tables with an explicit stack, so no nesting depth makes it recurse.
"""

from __future__ import annotations

import re

Path = tuple[str | int, ...]

# whitespace, newlines and comments between tokens
_SPACE = re.compile(r"(?:[ \t\r\n]++|#[^\n]*+)*+")
_INLINE_SPACE = re.compile(r"[ \t]*+")
# string literals (possessive quantifiers: no backtracking on any input)
_STRINGS = {
    '"""': re.compile(r'"""(?:[^"\\]++|\\.|"(?!""))*+"""(?:"(?!"""))?(?:"(?!"""))?', re.S),
    "'''": re.compile(r"'''(?:[^']++|'(?!''))*+'''(?:'(?!'''))?(?:'(?!'''))?"),
    '"': re.compile(r'"(?:[^"\\\n]++|\\.)*+"?'),
    "'": re.compile(r"'[^'\n]*+'?"),
}
_BARE_KEY = re.compile(r"[A-Za-z0-9_-]++")
# a scalar that is not a string: numbers, booleans, dates (which may hold a space)
_BARE_VALUE = re.compile(r"[^,\]}\n#\"'\[{]*+")
# the common line, read in one match: `key = scalar` or `key = { k = scalar, ... }` (scalars
# without brackets, braces, commas, '=' or escapes), then a comment or the end of the line
_SCALAR = r"""(?:"[^"\\\n,={}]*+"|'[^'\n,={}]*+'|[^\s,\[\]{}#"'=]++)"""
_SIMPLE_LINE = re.compile(
    rf"""([A-Za-z0-9_-]++)[ \t]*+=[ \t]*+(?:{_SCALAR}|\{{((?:[ \t]*+[A-Za-z0-9_-]++[ \t]*+=[ \t]*+"""
    rf"""{_SCALAR}[ \t]*+,)*+[ \t]*+(?:[A-Za-z0-9_-]++[ \t]*+=[ \t]*+{_SCALAR}[ \t]*+)?)\}}"""
    rf"""|\[((?:[ \t]*+{_SCALAR}[ \t]*+,)*+[ \t]*+(?:{_SCALAR}[ \t]*+)?)\])"""
    r"""[ \t\r]*+(?:\#[^\n]*+)?(?=\n|\Z)""")
_INLINE_KEY = re.compile(r"([A-Za-z0-9_-]++)[ \t]*+=")
_ELEMENT = re.compile(_SCALAR)


def _end(rx: re.Pattern[str], s: str, i: int) -> int:
    """Where ``rx`` (a pattern that may match nothing) stops matching at ``i``."""
    m = rx.match(s, i)
    return i if m is None else m.end()


class _Scanner:
    def __init__(self, text: str, max_depth: int | None = None) -> None:
        self.s = text
        self.n = len(text)
        self.i = 0
        self._pos = 0  # the offset up to which newlines are counted into _line
        self._line = 1
        self.out: dict[Path, int] = {}
        self.aot: dict[Path, int] = {}
        self.max_depth = max_depth
        #: (path, line) of the first value nested deeper than max_depth
        self.too_deep: tuple[Path, int] | None = None

    # --- low level ------------------------------------------------------------------------
    @property
    def line(self) -> int:
        """The line of the current offset (newlines counted since the last call)."""
        if self.i > self._pos:
            self._line += self.s.count("\n", self._pos, self.i)
            self._pos = self.i
        return self._line

    def peek(self) -> str:
        return self.s[self.i] if self.i < self.n else ""

    def skip_ws(self, newlines: bool) -> None:
        if newlines:
            self.i = _end(_SPACE, self.s, self.i)
        else:
            self.i = _end(_INLINE_SPACE, self.s, self.i)
            if self.i < self.n and self.s[self.i] == "#":
                end = self.s.find("\n", self.i)
                self.i = self.n if end < 0 else end

    def string(self) -> str:
        """Skip a string literal starting here; return its (approximate) content."""
        q = self.s[self.i]
        opener = q * 3 if self.s.startswith(q * 3, self.i) else q
        m = _STRINGS[opener].match(self.s, self.i)
        if m is None:  # an unterminated multi-line string runs to the end of the file
            text, self.i = self.s[self.i:], self.n
        else:
            text, self.i = m.group(), m.end()
        return text[len(opener):].rstrip(q)

    def key(self) -> tuple[str, ...]:
        """A dotted key; stops before '=' or ']'."""
        parts: list[str] = []
        while True:
            self.skip_ws(False)
            c = self.peek()
            if c in ('"', "'"):
                parts.append(self.string())
            else:
                m = _BARE_KEY.match(self.s, self.i)
                if m is None:
                    return tuple(parts)
                parts.append(m.group())
                self.i = m.end()
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
            if self.i >= self.n or self.too_deep:
                return self.out
            line = self.line
            m = _SIMPLE_LINE.match(self.s, self.i)
            if m:
                path = (*current, m.group(1))
                self.out.setdefault(path, line)
                if m.group(2):
                    for k in _INLINE_KEY.findall(m.group(2)):
                        self.out.setdefault((*path, k), line)
                elif m.group(3):
                    for k in range(len(_ELEMENT.findall(m.group(3)))):
                        self.out.setdefault((*path, k), line)
                self.i = m.end()
                continue
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
                    end = self.s.find("\n", self.i)
                    self.i = self.n if end < 0 else end
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
        """Skip the value at ``path``, recording its keys and elements; nested arrays and
        inline tables are followed with a stack of [kind, path, next index] frames."""
        top = path
        stack: list[list] = []
        start = True  # a value begins here (else: continue in the innermost container)
        while True:
            if start:
                self.skip_ws(False)
                c = self.peek()
                if c in ("{", "["):
                    self.i += 1
                    if self.max_depth is not None and len(stack) >= self.max_depth:
                        self.too_deep = (top, self.line)
                        self.i = self.n
                        return
                    stack.append([c, path, 0])
                elif c in ('"', "'"):
                    self.string()
                else:
                    self.i = _end(_BARE_VALUE, self.s, self.i)
                start = False
            if not stack:
                return
            frame = stack[-1]
            kind, fpath, idx = frame
            self.skip_ws(True)
            c = self.peek()
            if c in ("}", "]", ""):
                self.i += 1
                stack.pop()
                if self.i > self.n:
                    return
                continue
            if c == ",":
                self.i += 1
                if kind == "[":
                    frame[2] = idx + 1
                continue
            if kind == "[":
                path = (*fpath, idx)
                self.out.setdefault(path, self.line)
                start = True
                continue
            line = self.line
            keys = self.key()
            if not keys:
                self.i += 1
                continue
            path = (*fpath, *keys)
            self.out.setdefault(path, line)
            self.skip_ws(False)
            if self.peek() == "=":
                self.i += 1
            start = True


def key_lines(text: str) -> dict[Path, int]:
    """Map every key path of the TOML ``text`` to the line (1-based) where it is written.

    Paths are tuples of keys and array indices: ``("bodies", "rod1", "joint", "axis")``,
    ``("bodies", "rod1", "com", 1)``, ``("forces", 0, "type")`` for arrays of tables.
    """
    try:
        return _Scanner(text).document()
    except (IndexError, ValueError, AttributeError):  # positions are a convenience, never fatal
        return {}


def deep_nesting(text: str, depth: int) -> tuple[Path, int] | None:
    """The first value of ``text`` whose arrays or inline tables are nested more than ``depth``
    levels deep: its key path and the line where it goes deeper (None when there is none)."""
    scanner = _Scanner(text, max_depth=depth)
    try:
        scanner.document()
    except (IndexError, ValueError, AttributeError):
        pass
    return scanner.too_deep


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
