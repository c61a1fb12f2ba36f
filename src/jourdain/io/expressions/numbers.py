"""Exact numbers in expressions: number literals, the bound on the size of the numbers that
the arithmetic on constants may build, and the check that a result is real and finite.
"""

from __future__ import annotations

import math
from fractions import Fraction

import symengine as se

from .vocabulary import MAX_NUMBER_BITS, MAX_NUMBER_LENGTH, ExpressionError

#: the smallest positive normal floating-point number; below it (down to 5e-324) numbers are
#: subnormal: they have lost digits, and their reciprocals and products overflow
SMALLEST_NORMAL = 2.2250738585072014e-308
SUBNORMAL = ("a subnormal floating-point number (nonzero, below 2.2e-308: it has lost its digits "
             "and its reciprocal overflows); write 0 or a value in other units")


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
        if value != 0 and abs(value) < SMALLEST_NORMAL:
            raise ExpressionError(f"number {_short(text)} is {SUBNORMAL}")
        return se.Float(value)
    frac = Fraction(text)
    if frac and abs(frac) < SMALLEST_NORMAL:
        raise ExpressionError(f"number {_short(text)} is {SUBNORMAL}")
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


