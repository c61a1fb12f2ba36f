"""The words of the expression language: its limits, the whitelisted functions and constants,
the reserved names, and :class:`ExpressionError`.
"""

from __future__ import annotations

from collections.abc import Callable

import symengine as se

from ...errors import ModelError

#: Longest expression accepted (characters); model expressions are short, this bounds the work.
MAX_LENGTH = 20_000
#: Deepest nesting of parentheses, unary signs and powers accepted.
MAX_DEPTH = 100
#: Largest magnitude of a numeric exponent (``10^1000000`` would build a huge integer).
MAX_NUMERIC_EXPONENT = 1000
#: Largest exact number the arithmetic on constants may build, in bits of its numerator or
#: denominator (10 000 bits: about 3 000 decimal digits; ``1000^1000`` fits). Every power is
#: bounded before it is computed, so ``((2^999)^999)^999`` is refused instead of building a
#: number of a billion bits (or crashing the big-integer library).
MAX_NUMBER_BITS = 10_000
#: Longest number literal (characters).
MAX_NUMBER_LENGTH = 1000


def _atan2(y: se.Basic, x: se.Basic) -> se.Basic:
    return se.atan2(y, x)


#: Whitelisted functions: name -> (number of arguments, SymEngine constructor).
FUNCTIONS: dict[str, tuple[int, Callable[..., se.Basic]]] = {
    "sin": (1, se.sin), "cos": (1, se.cos), "tan": (1, se.tan), "cot": (1, se.cot),
    "sec": (1, se.sec), "csc": (1, se.csc),
    "asin": (1, se.asin), "acos": (1, se.acos), "atan": (1, se.atan), "atan2": (2, _atan2),
    "sinh": (1, se.sinh), "cosh": (1, se.cosh), "tanh": (1, se.tanh),
    "exp": (1, se.exp), "log": (1, se.log), "sqrt": (1, se.sqrt),
    "abs": (1, se.Abs), "sign": (1, se.sign),
    "min": (2, se.Min), "max": (2, se.Max),
}

#: Named constants (``E`` is left free: engineers name Young's modulus so; write ``exp(1)``).
CONSTANTS: dict[str, se.Basic] = {"pi": se.pi}

#: Names a model may not declare (functions, constants and Python words that look like names).
RESERVED_NAMES = frozenset(FUNCTIONS) | frozenset(CONSTANTS) | frozenset({
    "t", "world", "elongation", "elongation_d", "deflection", "deflection_d",
    "lambda", "import", "and", "or", "not", "if",
    "else", "for", "in", "is", "None", "True", "False", "def", "class", "return", "exec", "eval",
})


class ExpressionError(ModelError):
    """An expression of a model file is not in jourdain's expression language.

    ``column`` is the 1-based position in the expression text where the problem is.
    """

    def __init__(self, message: str, column: int | None = None) -> None:
        super().__init__(message)
        self.column = column


