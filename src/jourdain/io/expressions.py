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

from __future__ import annotations

import math
import re
from collections.abc import Callable, Container
from dataclasses import dataclass
from fractions import Fraction

import symengine as se

from ..errors import ModelError

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


class _Parser:
    """Recursive-descent parser over the token list, building SymEngine expressions."""

    def __init__(self, text: str, names: Container[str] | None,
                 symbol: Callable[[str], se.Basic], describe: Callable[[str], str]) -> None:
        self.text = text
        self.tokens = tokenize(text)
        self.i = 0
        self.names = names
        self.symbol = symbol
        self.describe = describe
        self.depth = 0

    # --- helpers --------------------------------------------------------------------------
    @property
    def tok(self) -> Token:
        return self.tokens[self.i]

    def error(self, msg: str, tok: Token | None = None) -> ExpressionError:
        tok = tok or self.tok
        return ExpressionError(msg, tok.pos + 1)

    def take(self) -> Token:
        tok = self.tokens[self.i]
        self.i += 1
        return tok

    def expect(self, text: str, context: str) -> None:
        if self.tok.kind == "op" and self.tok.text == text:
            self.i += 1
            return
        raise self.error(f"expected '{text}' {context}, got {self._what(self.tok)}")

    @staticmethod
    def _what(tok: Token) -> str:
        return "the end of the expression" if tok.kind == "end" else repr(tok.text)

    def checked(self, e: se.Basic, tok: Token) -> se.Basic:
        """``e``, the result of the operation at ``tok``, if its constant part is a finite number
        of bounded size. Sums and products only add the sizes of their operands, so the
        numbers on top (the number itself, a product's coefficient, a sum's constant term) are
        enough here; the whole result is checked once at the end (:func:`_real_and_finite`)."""
        for node in (e, *(e.args[:1] if e.is_Mul or e.is_Add else ())):
            why = _bad_number(node, final=False)
            if why:
                raise self.error(f"{why} here", tok)
        return e

    def enter(self) -> None:
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise self.error(f"expression is nested too deeply (more than {MAX_DEPTH} levels)")

    # --- grammar --------------------------------------------------------------------------
    def parse(self) -> se.Basic:
        if self.tok.kind == "end":
            raise ExpressionError("empty expression", 1)
        e = self.expr()
        if self.tok.kind != "end":
            tok = self.tok
            if tok.kind == "op" and tok.text == "(":
                raise self.error("'(' here would call something that is not a function")
            if tok.kind == "op" and tok.text == ")":
                raise self.error("unbalanced ')'")
            raise self.error(f"unexpected {self._what(tok)} after a complete expression "
                             "(missing operator?)")
        return e

    def expr(self) -> se.Basic:
        e = self.term()
        while self.tok.kind == "op" and self.tok.text in "+-":
            tok = self.take()
            rhs = self.term()
            e = self.checked(e + rhs if tok.text == "+" else e - rhs, tok)
        return e

    def term(self) -> se.Basic:
        e = self.unary()
        while self.tok.kind == "op" and self.tok.text in ("*", "/"):
            tok = self.take()
            rhs = self.unary()
            if tok.text == "/":
                if rhs.is_Number and rhs == 0:
                    raise self.error("division by zero", tok)
                e = self.checked(e / rhs, tok)
            else:
                e = self.checked(e * rhs, tok)
        return e

    def unary(self) -> se.Basic:
        if self.tok.kind == "op" and self.tok.text in "+-":
            op = self.take().text
            self.enter()
            e = self.unary()
            self.depth -= 1
            return -e if op == "-" else e
        return self.power()

    def power(self) -> se.Basic:
        base = self.atom()
        if self.tok.kind == "op" and self.tok.text in ("^", "**"):
            tok = self.take()
            self.enter()
            exponent = self.unary()
            self.depth -= 1
            if exponent.is_Number:
                n = abs(float(exponent))
                if n > MAX_NUMERIC_EXPONENT:
                    raise self.error(f"numeric exponent {_short(exponent)} is too large (at most "
                                     f"{MAX_NUMERIC_EXPONENT} in magnitude)", tok)
                # the power multiplies the size of the exact numbers in its base by |exponent|
                # (a coefficient 2^999 of a product raised to 999 is 2^998001): bounded
                # before SymEngine computes it
                bits = _power_bits(base) * n
                if bits > MAX_NUMBER_BITS:
                    raise self.error(f"this power would build a number of about {bits:.3g} bits "
                                     f"(at most {MAX_NUMBER_BITS} bits, about "
                                     f"{int(MAX_NUMBER_BITS * 0.30103)} digits, are allowed)",
                                     tok)
                if base.is_Number and base == 0 and float(exponent) < 0:
                    raise self.error("zero raised to a negative power", tok)
            return self.checked(base**exponent, tok)
        return base

    def atom(self) -> se.Basic:
        tok = self.tok
        if tok.kind == "num":
            self.i += 1
            try:
                return _number(tok.text)
            except ExpressionError as exc:
                raise self.error(str(exc), tok) from None
        if tok.kind == "op" and tok.text == "(":
            self.i += 1
            self.enter()
            if self.tok.kind == "op" and self.tok.text == ")":
                raise self.error("empty parentheses")
            e = self.expr()
            self.depth -= 1
            self.expect(")", "to close the '(' at column " + str(tok.pos + 1))
            return e
        if tok.kind == "name":
            self.i += 1
            return self.name(tok)
        if tok.kind == "end":
            raise self.error("the expression ends where a number, a name or '(' is expected")
        raise self.error(f"unexpected {tok.text!r} where a number, a name or '(' is expected")

    def name(self, tok: Token) -> se.Basic:
        name = tok.text
        nxt = self.tok
        is_call = nxt.kind == "op" and nxt.text == "("
        if name.startswith("__") or name.endswith("__"):
            raise self.error(f"name {name!r} is not allowed (double-underscore names are "
                             "reserved)", tok)
        if is_call:
            if name not in FUNCTIONS:
                known = ", ".join(sorted(FUNCTIONS))
                raise self.error(f"{name!r} is not a function of the expression language; "
                                 f"functions are: {known}", tok)
            return self.call(tok)
        if name in FUNCTIONS:
            raise self.error(f"function {name!r} must be called with arguments, as {name}(x)",
                             tok)
        if name in CONSTANTS:
            return CONSTANTS[name]
        if self.names is not None and name not in self.names:
            raise self.error(f"unknown name {name!r}{self.describe(name)}", tok)
        return self.symbol(name)

    def call(self, tok: Token) -> se.Basic:
        nargs, fn = FUNCTIONS[tok.text]
        self.i += 1  # the "("
        self.enter()
        args: list[se.Basic] = []
        if not (self.tok.kind == "op" and self.tok.text == ")"):
            args.append(self.expr())
            while self.tok.kind == "op" and self.tok.text == ",":
                self.i += 1
                args.append(self.expr())
        self.depth -= 1
        self.expect(")", f"to close the call of {tok.text}()")
        if len(args) != nargs:
            raise self.error(f"{tok.text}() takes {nargs} argument{'s' if nargs > 1 else ''}, "
                             f"got {len(args)}", tok)
        try:
            value = fn(*args)
        except (RuntimeError, ValueError, ZeroDivisionError) as exc:
            raise self.error(f"{tok.text}(): {exc}", tok) from None
        return self.checked(value, tok)


def _number(text: str) -> se.Basic:
    """Exact value of a decimal literal (``0.1`` is 1/10), a float when the exponent is huge."""
    if len(text) > MAX_NUMBER_LENGTH:
        raise ExpressionError(f"number {_short(text)} is too long ({len(text)} characters, at "
                              f"most {MAX_NUMBER_LENGTH})")
    mantissa, _, exp = text.lower().partition("e")
    if exp and abs(int(exp)) > 300:
        value = float(text)
        if value in (float("inf"), float("-inf")):
            raise ExpressionError(f"number {_short(text)} is too large for a floating-point "
                                  "number (at most about 1.8e308)")
        return se.Float(value)
    frac = Fraction(text)
    out = (se.Integer(frac.numerator) if frac.denominator == 1
           else se.Rational(frac.numerator, frac.denominator))
    why = _bad_number(out)
    if why:
        raise ExpressionError(f"number {_short(text)}: {why}")
    return out


def _short(x: object, n: int = 40) -> str:
    """``x`` as text, shortened in the middle when longer than ``n`` characters."""
    s = str(x)
    return s if len(s) <= n else f"{s[:n // 2]}…{s[-n // 2:]} ({len(s)} characters)"


def _bits(x: se.Basic) -> int:
    """Size of an exact number: the bit length of its numerator or denominator (0 otherwise)."""
    if x.is_Integer:
        return int(x).bit_length()
    if x.is_Rational:
        num, den = x.get_num_den()
        return max(int(num).bit_length(), int(den).bit_length())
    return 0


def _power_bits(base: se.Basic) -> float:
    """Bits of the largest exact number that raising ``base`` to an exponent n multiplies by
    |n|: a number itself, a product's numeric factors, and b^k of a number b (b^(k·n))."""
    if base.is_Number:
        return max(_bits(base), 1)
    if base.is_Pow:
        b, k = base.args
        if b.is_Number and k.is_Number:
            return max(_bits(b), 1) * abs(float(k))
        return 1.0
    if base.is_Mul:
        return max(_power_bits(a) for a in base.args)
    return 1.0


def _bad_number(x: se.Basic, final: bool = True) -> str | None:
    """Why the number ``x`` is not allowed in an expression (None when it is, or for a
    non-number): too large an exact number, an infinite or undefined floating-point constant,
    or (``final``: in the expression read, not in an intermediate result such as the 10^400 of
    10^400/10^399) an exact number beyond floating-point range."""
    if not x.is_Number:
        return None
    if x.is_Rational:
        bits = _bits(x)
        if bits > MAX_NUMBER_BITS:
            return (f"the exact number built would have {bits} bits (at most {MAX_NUMBER_BITS} "
                    "bits are allowed)")
        if not final:
            return None
        if x.is_Integer:
            big = bits > 1024
        else:
            num, den = x.get_num_den()
            big = int(num).bit_length() - int(den).bit_length() > 1024
        if big:
            return (f"the constant {_short(x)} is too large for a floating-point number (at "
                    "most about 1.8e308)")
        return None
    try:
        v = complex(x)
    except (RuntimeError, TypeError, ValueError, OverflowError):
        return None
    if not (math.isfinite(v.real) and math.isfinite(v.imag)):
        what = "undefined (NaN)" if v != v else "infinite"
        return f"the constant {x} is {what} (beyond floating-point range)"
    return None


def _no_hint(name: str) -> str:
    return ""


def parse_expression(text: str, names: Container[str] | None = None, *,
                     symbol: Callable[[str], se.Basic] | None = None,
                     describe: Callable[[str], str] | None = None) -> se.Basic:
    """Parse ``text`` of jourdain's expression language into a SymEngine expression.

    Parameters
    ----------
    text : str
        The expression, e.g. ``"m*l^2/12 + sin(phi1)"``.
    names : container of str, optional
        The names allowed here (declared coordinates, rates, parameters, inputs, ``t``); any other
        name is an error. ``None`` allows every identifier that is not reserved.
    symbol : callable, optional
        Maps an allowed name to its expression (default: a SymEngine symbol of that name).
    describe : callable, optional
        Returns extra text for the message about an unknown name (e.g. "; declared names are ...").

    Raises
    ------
    ExpressionError
        With the 1-based column of the problem in ``.column``.
    """
    if not isinstance(text, str):
        raise ExpressionError(f"expected an expression string, got {type(text).__name__}")
    parser = _Parser(text, names, symbol or se.Symbol, describe or _no_hint)
    return _real_and_finite(parser.parse(), text)


_NOT_REAL = {"ImaginaryUnit": "is complex (contains the imaginary unit)",
             "Complex": "is complex", "ComplexDouble": "is complex",
             "ComplexInfinity": "is infinite", "Infinity": "is infinite",
             "NegativeInfinity": "is infinite", "NaN": "is not a number (NaN)"}


def _real_and_finite(expr: se.Basic, text: str) -> se.Basic:
    """Reject constants such as sqrt(-1), log(0) or 0*oo that the arithmetic produced, infinite
    floating-point constants (1e308*1e308) and exact numbers too large for floating point."""
    stack = [expr]
    while stack:
        node = stack.pop()
        why = _NOT_REAL.get(type(node).__name__)
        if why:
            raise ExpressionError(f"the expression {why}: {_short(text.strip(), 200)} = "
                                  f"{_short(expr, 200)}")
        bad = _bad_number(node)
        if bad:
            raise ExpressionError(f"in {_short(text.strip(), 200)}: {bad}")
        stack.extend(node.args)
    if not expr.free_symbols:
        # a constant must be a real number: (-8)^(1/3) is 2*(-1)^(1/3), complex
        try:
            value = float(expr)
        except (RuntimeError, TypeError, ValueError, OverflowError):
            value = math.nan
        if not math.isfinite(value):
            raise ExpressionError(f"the expression is not a finite real number: "
                                  f"{_short(text.strip(), 200)} = {_short(expr, 200)}")
    return expr


def parse_number(text: str) -> float:
    """A number given as a constant expression (``"0.3"``, ``"pi/4"``, ``"-2e-3"``)."""
    value = parse_expression(text, names=())
    try:
        out = float(value)
    except (RuntimeError, TypeError, ValueError):
        raise ExpressionError(f"{text!r} is not a number") from None
    if out != out or out in (float("inf"), float("-inf")):
        raise ExpressionError(f"{text!r} is not finite")
    return out
