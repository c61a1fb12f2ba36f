"""jourdain's own restricted expression language for model files.

Model files are data. Their expressions (``"m*l*sin(phi1)"``) are read by a small tokenizer and a
Pratt (precedence-climbing) parser that accept exactly this grammar and nothing else::

    expr    := term (("+" | "-") term)*
    term    := unary (("*" | "/") unary)*
    unary   := ("+" | "-") unary | power
    power   := atom (("^" | "**") unary)?          # right-associative, binds tighter than unary
    atom    := NUMBER | NAME | FUNCTION "(" expr ("," expr)* ")" | "(" expr ")"

Names must be declared in the model (coordinates, their rates ``<name>_d``, parameters, inputs,
``t`` where time is allowed) or be the constant ``pi``; functions come from a
fixed whitelist (:data:`FUNCTIONS`). Anything else (attribute access, indexing, strings, keywords,
calls of other names, dunder names, lambdas, comparisons, ...) is rejected with a message that
says what and where. The result is a SymEngine expression built directly from the parse tree:
nothing is ever passed to ``eval``, ``exec`` or ``sympify``.
"""


from .numbers import SMALLEST_NORMAL, SUBNORMAL, _number
from .parser import parse_expression, parse_number
from .tokens import Token, tokenize
from .vocabulary import (
    CONSTANTS,
    FUNCTIONS,
    MAX_DEPTH,
    MAX_LENGTH,
    MAX_NUMBER_BITS,
    MAX_NUMBER_LENGTH,
    MAX_NUMERIC_EXPONENT,
    RESERVED_NAMES,
    ExpressionError,
)

__all__ = ["CONSTANTS", "FUNCTIONS", "MAX_DEPTH", "MAX_LENGTH", "MAX_NUMBER_BITS",
           "MAX_NUMBER_LENGTH", "MAX_NUMERIC_EXPONENT", "RESERVED_NAMES", "SMALLEST_NORMAL",
           "SUBNORMAL", "ExpressionError",
           "Token", "parse_expression", "parse_number", "tokenize", "_number"]
