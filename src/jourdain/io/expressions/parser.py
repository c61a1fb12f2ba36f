"""The precedence-climbing parser of the grammar in :mod:`jourdain.io.expressions`, building
SymEngine expressions directly (never ``eval``/``sympify``), and :func:`parse_number`.
"""

from __future__ import annotations

from collections.abc import Callable, Container

import symengine as se

from .numbers import _bad_number, _number, _power_bits, _real_and_finite, _short
from .tokens import Token, tokenize
from .vocabulary import (
    CONSTANTS,
    FUNCTIONS,
    MAX_DEPTH,
    MAX_NUMBER_BITS,
    MAX_NUMERIC_EXPONENT,
    ExpressionError,
)


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
