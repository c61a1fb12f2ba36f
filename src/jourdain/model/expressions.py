"""Conversion of user input (numbers, SymPy or SymEngine expressions, strings) into SymEngine
expressions.

Strings (``Body(mass="m")``, ``com=(0, "-l/2", 0)``) are read by the same restricted parser as
model files (:mod:`jourdain.io.expressions`: its grammar and whitelist of functions, never
``eval`` or ``sympify``), so nothing is ever evaluated as code; their names become symbols,
which the :class:`~jourdain.model.System` checks against its declarations like any other.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterable, Mapping, Sequence
from typing import Any, TypeAlias

import symengine as se

from ..errors import ModelError

#: a SymEngine expression (SymEngine has no type information: to the type checker, Any)
Expr: TypeAlias = se.Basic

#: a vector and a matrix of three components / rows (joint frames, axes, inertia tensors)
Vec3: TypeAlias = tuple[Expr, Expr, Expr]
Mat3: TypeAlias = tuple[Vec3, Vec3, Vec3]

#: time, shared by every model
t = se.Symbol("t")


def symbols(names: str | Sequence[str], *, seq: bool = False
            ) -> se.Symbol | tuple[se.Symbol, ...] | list[se.Symbol]:
    """SymEngine symbols from a string of names, by SymPy's rules for ``sympy.symbols``.

    Names are separated by commas and/or white space. The result is

    - one ``Symbol`` for a string with exactly one name (``symbols("x")``, ``" x "``),
    - a tuple for several names (``"x y"``, ``"x, y"``), for a trailing comma (``"x,"`` gives
      ``(x,)``), for a range, and always with ``seq=True``;
    - for a list or tuple of strings, a list or tuple of the results of each string.

    Ranges: ``"x0:3"`` or ``"x:3"`` give ``(x0, x1, x2)`` (end excluded, start 0 by default);
    ``"a:d"`` gives ``(a, b, c, d)`` (single letters, end included, as SymPy).

    >>> phi1, phi2 = symbols("phi1 phi2")
    >>> m = symbols("m")
    >>> (x,) = symbols("x", seq=True)

    Raises
    ------
    ModelError
        No name at all, a name that is not a Python identifier, or a range jourdain does not
        read (several colons, ``"x(:2)"``).
    """
    if isinstance(names, (list, tuple)):
        out = [symbols(n, seq=seq) for n in names]
        return tuple(out) if isinstance(names, tuple) else out
    if not isinstance(names, str):
        raise ModelError(f"symbols: expected a string of names, got {type(names).__name__}")
    text = names.strip()
    if not text:
        raise ModelError("symbols: no symbol names given")
    many = seq or text.endswith(",")
    parts = [p for chunk in text.split(",") for p in chunk.split()]
    syms: list[se.Symbol] = []
    for part in parts:
        if ":" in part:
            many = True
            syms.extend(se.Symbol(n) for n in _range(part))
            continue
        _identifier(part, part)
        syms.append(se.Symbol(part))
    if not many and len(syms) == 1:
        return syms[0]
    return tuple(syms)


def _identifier(name: str, where: str) -> None:
    if not name.isidentifier():
        raise ModelError(f"symbols: name {name!r} in {where!r} is not a valid identifier")


def _range(part: str) -> list[str]:
    """The names of a range ``prefix[start]:end`` (numbers, end excluded) or ``a:d`` (letters,
    end included), as in SymPy."""
    head, _, end = part.partition(":")
    if ":" in end or "(" in part or ")" in part:
        raise ModelError(f"symbols: range {part!r} is not supported; write one range such as "
                         "'x0:3' or 'a:d' per name")
    if (len(head) == 1 and len(end) == 1 and head.isalpha() and end.isalpha()
            and head.isascii() and end.isascii()):
        names = [chr(c) for c in range(ord(head), ord(end) + 1)]
    else:
        digits = len(head) - len(head.rstrip("0123456789"))
        prefix, start = (head[:-digits], head[-digits:]) if digits else (head, "0")
        if not prefix or not end.isdigit():
            raise ModelError(f"symbols: range {part!r} must read 'name:end', "
                             "'name<start>:<end>' with whole numbers, or 'a:d' (letters)")
        names = [f"{prefix}{i}" for i in range(int(start), int(end))]
    for n in names:
        _identifier(n, part)
    return names


def as_expr(value: object, where: str) -> Expr:
    """Convert a number, a SymPy/SymEngine expression or a string of the expression language
    (:mod:`jourdain.io.expressions`, the model files' safe parser) to a SymEngine expression.

    ``where`` names the model element for the error message.
    """
    if isinstance(value, se.Basic):
        return finite_constants(value, where)
    if isinstance(value, str):
        return parse_text(value, where)
    if isinstance(value, bool):
        raise ModelError(f"{where}: expected a number or an expression, got a bool {value!r}")
    if isinstance(value, numbers.Integral):
        return se.Integer(int(value))
    if isinstance(value, numbers.Real):
        v = float(value)
        if v != v or v in (float("inf"), float("-inf")):
            raise ModelError(f"{where}: value {value!r} is not finite")
        # keep exact rationals for simple decimal numbers such as 0.5
        return se.Float(v) if v != int(v) else se.Integer(int(v))
    # SymPy expressions (duck-typed: do not import sympy on the hot path)
    if hasattr(value, "free_symbols") and hasattr(value, "subs") and not isinstance(value, str):
        try:
            converted = se.sympify(value)
        except Exception as exc:  # noqa: BLE001 - conversion failure reported with context
            raise ModelError(f"{where}: cannot convert {value!r} to SymEngine: {exc}") from exc
        return finite_constants(converted, where)
    raise ModelError(
        f"{where}: expected a number, a SymPy/SymEngine expression or a string of the "
        f"expression language, got {type(value).__name__} {value!r}"
    )


def parse_text(text: str, where: str) -> Expr:
    """``text`` read by the model files' expression parser (any declared-looking name becomes
    a symbol; the System checks them); a :class:`ModelError` naming ``where`` and the column
    otherwise."""
    # the language is on this floor (it imports only jourdain.errors), but its package sits
    # in jourdain.io, whose __init__ imports the model: imported when a string is first read
    from ..io.expressions import ExpressionError, parse_expression

    try:
        return finite_constants(parse_expression(text), where)
    except ExpressionError as exc:
        column = f" (column {exc.column})" if exc.column else ""
        raise ModelError(f"{where}: {text!r}: {exc}{column}") from None


#: the magnitudes a parameter may have besides 0: the equations multiply parameters with each
#: other and with lengths and rates (m·l², k·x, 1/m), and beyond these bounds such products leave
#: the floating-point range (inf) or fall into subnormal numbers that have lost their digits
#: (1e-320: a factorization then overflows or does not converge). Physical constants in any unit
#: system lie far inside (the mass of a galaxy, 1e42 kg; Planck's constant, 6.6e-34 J·s).
PARAMETER_MAGNITUDE = (1e-150, 1e150)


def magnitude_problem(value: float) -> str | None:
    """Why a parameter value is absurd (subnormal, or outside :data:`PARAMETER_MAGNITUDE`),
    or None."""
    a = abs(value)
    low, high = PARAMETER_MAGNITUDE
    if a == 0 or low <= a <= high or a != a:
        return None
    what = ("a subnormal number (below 2.2e-308, with fewer digits than a float)"
            if a < 2.2250738585072014e-308 else "too small" if a < low else "too large")
    return (f"{value:g} is {what}: a parameter's magnitude must be 0 or between {low:g} and "
            f"{high:g} (products of parameters would leave the floating-point range); "
            "choose units in which the value is moderate")


_NOT_FINITE = {"Infinity": "an infinite constant", "NegativeInfinity": "an infinite constant",
               "ComplexInfinity": "an infinite constant (zoo)", "NaN": "an undefined constant (NaN)"}


def finite_constants(e: Expr, where: str) -> Expr:
    """``e``, after checking that no number in it is infinite or NaN (``-l*inf``, ``1.0e308 *
    1.0e308``): such constants would make every result built from ``e`` undefined, and compiled
    code cannot hold them."""
    stack = [e]
    while stack:
        node = stack.pop()
        why = _NOT_FINITE.get(type(node).__name__)
        if why is None and node.is_Number and not node.is_Rational:
            try:
                z = complex(node)
            except (RuntimeError, TypeError, ValueError, OverflowError):
                z = complex(0.0)
            if not (math.isfinite(z.real) and math.isfinite(z.imag)):
                why = f"the non-finite number {node}"
        if why:
            raise ModelError(f"{where}: {e} contains {why}")
        stack.extend(node.args)
    return e


def values_at(exprs: Iterable[Expr], values: Mapping[str, float]) -> list[float]:
    """Each expression as a float at the parameter ``values`` (by name); NaN where it has no
    finite real value there (``sqrt(-l)``), or uses a name that ``values`` lacks."""
    out = []
    for e in exprs:
        syms = e.free_symbols
        try:
            v = float(e.subs({s: values[str(s)] for s in syms}) if syms else e)
        except (KeyError, RuntimeError, TypeError, ValueError, OverflowError):
            v = math.nan
        out.append(v if math.isfinite(v) else math.nan)
    return out


def as_vector(value: object, where: str, n: int = 3) -> tuple[Expr, ...]:
    """Convert an n-sequence (or an axis name 'x', 'y', 'z', '-x', ...) to a tuple of expressions."""
    if isinstance(value, str):
        return axis_vector(value, where)
    if hasattr(value, "shape") and not isinstance(value, se.Basic):
        array: Any = value  # NumPy, SymPy or SymEngine matrices
        try:
            value = list(array.reshape(-1)) if hasattr(array, "reshape") else list(array)
        except Exception:  # noqa: BLE001
            value = list(array)
    if not isinstance(value, Iterable):
        raise ModelError(f"{where}: expected a {n}-vector, got {value!r}")
    items = list(value)
    if len(items) != n:
        raise ModelError(f"{where}: expected a {n}-vector, got {len(items)} components")
    return tuple(as_expr(v, f"{where}[{i}]") for i, v in enumerate(items))


_AXES = {"x": (1, 0, 0), "y": (0, 1, 0), "z": (0, 0, 1)}


def axis_vector(value: object, where: str) -> tuple[Expr, ...]:
    """A joint axis: ``'x'``, ``'y'``, ``'z'`` (optionally signed) or a 3-vector along it.

    A vector gives the direction only and is made a unit vector by :func:`unit_axis`, so
    ``(1, 1, 0)`` is the axis ``(√2/2, √2/2, 0)``; the zero vector is refused. ``where`` names
    the joint or step for the error message.
    """
    if isinstance(value, str):
        s = value.strip().lower()
        sign = -1 if s.startswith("-") else 1
        s = s.lstrip("+-")
        if s not in _AXES:
            raise ModelError(
                f"{where}: expected one of x, y, z or a 3-vector, got {value!r}"
            )
        return tuple(se.Integer(sign * c) for c in _AXES[s])
    u = unit_axis(as_vector(value, where))
    if u is None:
        raise ModelError(f"{where} must not be the zero vector")
    return u


def unit_axis(vec: Sequence[Expr]) -> tuple[Expr, ...] | None:
    """The unit vector u/|u| along the 3-vector ``vec``; None for the zero vector.

    The one rule for joint axes, in the Python API and in model files alike. A constant vector
    is divided by its length, exactly for integers and rationals (``(3, 4, 0)`` → ``(3/5, 4/5,
    0)``), and kept as given when its length is 1 to rounding (1e-12). A vector with parameters
    is kept as given when u·u simplifies to 1 (SymPy's ``simplify``: ``(sin(b), 0, cos(b))``),
    and divided by its symbolic length √(u·u) otherwise, so it is a unit vector for every value
    of the parameters where it is not zero (:class:`jourdain.System` checks that it is not zero
    at the default values).
    """
    u = tuple(vec)
    n2 = se.expand(sum((c * c for c in u), se.Integer(0)))
    if not n2.free_symbols:
        length2 = float(n2)
        if length2 == 0.0:
            return None
        if abs(length2 - 1.0) <= 1e-12:
            return u
    elif n2 == 1 or _simplifies_to_one(n2):
        return u
    length = se.sqrt(n2)
    return tuple(c / length for c in u)


def _simplifies_to_one(e: Expr) -> bool:
    # only for axes with parameters, so SymPy is not imported on the common path
    import sympy

    return sympy.simplify(sympy.sympify(e) - 1) == 0


def as_matrix3(value: object, where: str) -> Mat3:
    """A 3x3 matrix from nested sequences (or a SymPy/NumPy matrix)."""
    try:
        rows = [list(value[i]) if not hasattr(value, "shape") else [value[i, j] for j in range(3)]  # type: ignore[index]
                for i in range(3)]
    except Exception as exc:  # noqa: BLE001
        raise ModelError(f"{where}: expected a 3x3 matrix, got {value!r}") from exc
    if any(len(r) != 3 for r in rows):
        raise ModelError(f"{where}: expected a 3x3 matrix")
    try:
        if len(value) != 3 and not hasattr(value, "shape"):  # type: ignore[arg-type]
            raise ModelError(f"{where}: expected a 3x3 matrix")
    except TypeError:
        pass
    e = [[as_expr(rows[i][j], f"{where}[{i},{j}]") for j in range(3)] for i in range(3)]
    return (e[0][0], e[0][1], e[0][2]), (e[1][0], e[1][1], e[1][2]), (e[2][0], e[2][1], e[2][2])


def free_names(exprs: Sequence[Expr]) -> set[str]:
    """Names of the free symbols of some expressions."""
    out: set[str] = set()
    for e in exprs:
        out.update(str(s) for s in e.free_symbols)
    return out
