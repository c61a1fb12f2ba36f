"""The tokenizer: numbers, names, operators and the explanation of characters it refuses.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from .vocabulary import MAX_LENGTH, ExpressionError


@dataclass(frozen=True)
class Token:
    kind: str  # "num", "name", "op", "end"
    text: str
    pos: int  # 0-based offset in the source


_NUMBER = re.compile(r"(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?")
_NAME = re.compile(r"[A-Za-z_][A-Za-z_0-9]*")
_OPS = ("**", "+", "-", "*", "/", "^", "(", ")", ",")
# characters that are not part of the language, with the reason a user most likely typed them
_EXPLAIN = {
    ".": "attribute access is not allowed",
    "[": "indexing and lists are not allowed in an expression",
    "]": "indexing and lists are not allowed in an expression",
    "{": "braces are not allowed in an expression",
    "}": "braces are not allowed in an expression",
    "'": "strings are not allowed in an expression",
    '"': "strings are not allowed in an expression",
    "=": "assignments and comparisons are not allowed in an expression",
    "<": "comparisons are not allowed in an expression",
    ">": "comparisons are not allowed in an expression",
    "!": "comparisons are not allowed in an expression",
    ":": "':' (lambdas, slices) is not allowed in an expression",
    ";": "';' is not allowed in an expression",
    "@": "'@' is not allowed in an expression",
    "%": "'%' is not allowed; write the expression with + - * / ^",
    "&": "'&' is not allowed in an expression",
    "|": "'|' is not allowed; write abs(x)",
    "~": "'~' is not allowed in an expression",
    "#": "comments are not allowed in an expression",
    "\\": "backslashes are not allowed in an expression",
    "`": "backquotes are not allowed in an expression",
    "$": "'$' is not allowed in an expression",
    "?": "'?' is not allowed in an expression",
}


def tokenize(text: str) -> list[Token]:
    """Split ``text`` into tokens; raise :class:`ExpressionError` at the first foreign character."""
    if len(text) > MAX_LENGTH:
        raise ExpressionError(f"expression is too long ({len(text)} characters, at most "
                              f"{MAX_LENGTH})")
    tokens: list[Token] = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if c in " \t\r\n":
            i += 1
            continue
        m = _NUMBER.match(text, i)
        if m and (c.isdigit() or (c == "." and m.end() > i + 1)):
            end = m.end()
            if end < n and (text[end].isalpha() or text[end] == "_"):
                raise ExpressionError(
                    f"a number must not run into a name: {text[i:end + 1]!r}; write a '*' "
                    "between them", i + 1)
            tokens.append(Token("num", m.group(), i))
            i = end
            continue
        m = _NAME.match(text, i)
        if m:
            tokens.append(Token("name", m.group(), i))
            i = m.end()
            continue
        op = next((o for o in _OPS if text.startswith(o, i)), None)
        if op is not None:
            tokens.append(Token("op", op, i))
            i += len(op)
            continue
        why = _EXPLAIN.get(c, "this character is not part of jourdain's expression language")
        raise ExpressionError(f"unexpected character {c!r}: {why}", i + 1)
    tokens.append(Token("end", "", n))
    return tokens


