"""jourdain's restricted expression parser: meaning of the grammar, and rejection of everything
outside it (including attempts to run Python)."""

import math
import random
import re

import pytest
import symengine as se
import sympy

from jourdain.io.expressions import (
    MAX_DEPTH,
    ExpressionError,
    parse_expression,
    parse_number,
    tokenize,
)

x, y, m, l, phi1 = se.symbols("x y m l phi1")
NAMES = {"x", "y", "m", "l", "phi1", "phi1_d", "t"}


def val(text: str, **subs: float) -> float:
    e = parse_expression(text, NAMES)
    return float(e.subs({se.Symbol(k): v for k, v in subs.items()}))


@pytest.mark.parametrize("text, expected", [
    ("1 + 2*3", 7), ("(1 + 2)*3", 9), ("2^3^2", 512), ("2**3**2", 512), ("-2^2", -4),
    ("(-2)^2", 4), ("2^-1", 0.5), ("8/4/2", 1), ("8/(4/2)", 4), ("1 - 2 - 3", -4),
    ("--3", 3), ("+-+3", -3), ("1.5e1", 15), (".5", 0.5), ("3.", 3), ("2.5E-1", 0.25),
    ("pi/4", math.pi / 4), ("atan2(1, 1)", math.pi / 4), ("sqrt(16)", 4), ("abs(-3)", 3),
    ("sign(-2)", -1), ("exp(0)", 1), ("log(exp(2))", 2), ("min(2, 3)", 2), ("max(2, 3)", 3),
    ("cos(0)*sin(pi/2)", 1), ("tan(0) + cosh(0) + sinh(0) + tanh(0)", 1),
])
def test_arithmetic_follows_the_usual_precedence(text, expected):
    assert val(text) == pytest.approx(expected, rel=1e-14)


def test_names_become_symbols_and_decimals_are_exact():
    e = parse_expression("m*l*sin(phi1)", NAMES)
    assert e == m * l * se.sin(phi1)
    assert parse_expression("0.1", ()) == se.Rational(1, 10)
    assert parse_expression("l/2", NAMES) == parse_expression("0.5*l", NAMES)
    assert parse_expression("x^2", NAMES) == x**2


def _random_expr(rng: random.Random, depth: int) -> se.Basic:
    if depth == 0 or rng.random() < 0.2:
        return rng.choice([x, y, m, se.Integer(rng.randint(1, 9)), se.Rational(rng.randint(1, 9),
                                                                             rng.randint(2, 9))])
    op = rng.choice(["+", "-", "*", "/", "^", "sin", "cos", "exp", "atan2", "sqrt", "abs"])
    a = _random_expr(rng, depth - 1)
    b = _random_expr(rng, depth - 1)
    return {"+": lambda: a + b, "-": lambda: a - b, "*": lambda: a * b,
            "/": lambda: a / (b**2 + 1), "^": lambda: (a**2 + 1) ** rng.choice([2, -1, se.Rational(1, 2)]),
            "sin": lambda: se.sin(a), "cos": lambda: se.cos(a), "exp": lambda: se.exp(a / 10),
            "atan2": lambda: se.atan2(a, b**2 + 1), "sqrt": lambda: se.sqrt(a**2 + 1),
            "abs": lambda: se.Abs(a)}[op]()


def test_reads_back_what_symengine_prints():
    """SymEngine's printer is an independent writer of the same grammar: 300 random
    expressions printed by it and parsed by jourdain evaluate to the same numbers."""
    rng = random.Random(7)
    point = {sympy.Symbol("x"): 0.37, sympy.Symbol("y"): -1.3, sympy.Symbol("m"): 2.1}
    for _ in range(300):
        e = _random_expr(rng, 4)
        text = str(e).replace("Abs(", "abs(")
        back = parse_expression(text, NAMES)
        a, b = (complex(sympy.N(v._sympy_().subs(point))) for v in (e, back))
        assert abs(a - b) <= 1e-9 * max(1.0, abs(a)), (text, a, b)


def test_parse_number_accepts_constant_expressions_only():
    assert parse_number("pi/2") == pytest.approx(math.pi / 2)
    assert parse_number("-2e-3") == -0.002
    with pytest.raises(ExpressionError, match="unknown name 'x'"):
        parse_number("x")


@pytest.mark.parametrize("text, message", [
    ("__import__('os').system('ls')", "strings are not allowed"),
    ("__import__(os)", "double-underscore"),
    ("__builtins__", "double-underscore"),
    ("().__class__.__bases__", "attribute access"),
    ("x.real", "attribute access"),
    ("(lambda: 1)()", "lambdas"),
    ("lambda x: x", "lambdas"),
    ("'abc'", "strings are not allowed"),
    ('"abc"', "strings are not allowed"),
    ("[1, 2]", "indexing and lists"),
    ("x[0]", "indexing"),
    ("{1: 2}", "braces"),
    ("eval('1')", "strings"),
    ("eval(x)", "'eval' is not a function"),
    ("open(x)", "'open' is not a function"),
    ("getattr(x, y)", "'getattr' is not a function"),
    ("exec(x)", "'exec' is not a function"),
    ("x(y)", "'x' is not a function"),
    ("(x)(y)", "would call something"),
    ("sin", "must be called with arguments"),
    ("sin(x, y)", "takes 1 argument, got 2"),
    ("atan2(x)", "takes 2 arguments, got 1"),
    ("x = 1", "assignments"),
    ("x == 1", "assignments and comparisons"),
    ("x < 1", "comparisons"),
    ("1 if x else 2", "unexpected 'if'"),
    ("x; y", "';'"),
    ("x @ y", "'@'"),
    ("x % 2", "'%'"),
    ("x | y", "abs"),
    ("`x`", "backquotes"),
    ("0x10", "must not run into a name"),
    ("2x", "must not run into a name"),
    ("x +", "ends where"),
    ("(x", "expected ')'"),
    ("x)", "unbalanced"),
    ("2 3", "missing operator"),
    ("", "empty expression"),
    ("()", "empty parentheses"),
    ("10^10^10", "too large"),
    ("1/0", "division by zero"),
    ("0^-1", "zero raised to a negative power"),
    ("z", "unknown name 'z'"),
    ("phi2", "unknown name 'phi2'"),
    ("x # comment", "comments"),
    ("x\\y", "backslashes"),
    ("x $ y", "'$'"),
    ("1e999", "too large"),
    ("sqrt(-1)*x", "is complex"),
    ("log(0)", "is infinite"),
    ("x*log(0)", "is infinite"),
    ("(-8)^(1/2)", "is complex"),
])
def test_rejects_everything_outside_the_grammar(text, message):
    with pytest.raises(ExpressionError, match=re.escape(message)) as info:
        parse_expression(text, NAMES)
    assert info.value.column is not None or message in (
        "empty expression", "too large", "is complex", "is infinite")


def test_error_column_points_at_the_problem():
    with pytest.raises(ExpressionError) as info:
        parse_expression("m*l*foo(phi1)", NAMES)
    assert info.value.column == 5
    with pytest.raises(ExpressionError) as info:
        parse_expression("m + x.y", NAMES)
    assert info.value.column == 6


def test_depth_and_length_are_bounded():
    deep = "(" * (MAX_DEPTH + 5) + "x" + ")" * (MAX_DEPTH + 5)
    with pytest.raises(ExpressionError, match="nested too deeply"):
        parse_expression(deep, NAMES)
    with pytest.raises(ExpressionError, match="nested too deeply"):
        parse_expression("-" * (MAX_DEPTH + 5) + "x", NAMES)
    with pytest.raises(ExpressionError, match="too long"):
        parse_expression("x+" * 20000 + "x", NAMES)


def test_non_strings_are_rejected():
    with pytest.raises(ExpressionError, match="expected an expression string"):
        parse_expression(3, NAMES)  # type: ignore[arg-type]


def test_tokenizer_positions():
    toks = tokenize("ab + 2.5*sin(c)")
    assert [(t.kind, t.text, t.pos) for t in toks[:4]] == [
        ("name", "ab", 0), ("op", "+", 3), ("num", "2.5", 5), ("op", "*", 8)]


def test_random_text_gives_only_expression_errors():
    """5000 random strings over the characters of Python and of the grammar: each parses or
    raises ExpressionError (never another exception, never a hang)."""
    rng = random.Random(11)
    alphabet = "xym01._()[]{}+-*/^%@,:;'\"=<>!#~|&\\ \t" + "abcdefghijklmnopqrstuvwxyz" + "sin cos "
    for _ in range(5000):
        text = "".join(rng.choice(alphabet) for _ in range(rng.randint(0, 30)))
        try:
            parse_expression(text, NAMES)
        except ExpressionError:
            pass
