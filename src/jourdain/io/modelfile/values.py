"""Typed access to the values of a model file: tables, strings, numbers, names, expressions,
vectors, axes and matrices, each checked and located (file, line, key path) when wrong.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Container, Iterable, Mapping
from typing import Any

import symengine as se

from ...model.expressions import unit_axis
from ..expressions import SMALLEST_NORMAL, SUBNORMAL, ExpressionError, _number, parse_expression
from ..toml_positions import Path
from .errors import Locator, _clip, _type_name
from .schema import _CONTROL, _IDENT


class _Values(Locator):
    """The reader's state (names declared so far) and its typed accessors."""

    def __init__(self, text: str, filename: str) -> None:
        super().__init__(text, filename)
        self.coords: list[str] = []
        self.params: dict[str, float] = {}
        self.inputs: list[str] = []
        self.units: dict[str, str] = {}
        self.descriptions: dict[str, str] = {}
        self.driven: dict[str, str] = {}
        #: symbols of the kinematic quantities of [quantities], by name
        self.quantity_symbols: dict[str, se.Basic] = {}


    # --- typed access ---------------------------------------------------------------------
    def table(self, value: object, path: Path, allowed: set[str] | None = None,
              what: str = "a table") -> dict[str, Any]:
        if not isinstance(value, dict):
            raise self.fail(path, f"expected {what}, got {_type_name(value)}")
        if allowed is not None:
            for k in value:
                if k not in allowed:
                    opts = sorted(allowed)
                    raise self.fail((*path, k), f'unknown key "{k}"{self.suggest(k, opts)}; '
                                    f"expected one of {', '.join(opts)}")
        return value

    def require(self, tbl: Mapping[str, Any], key: str, path: Path) -> Any:
        if key not in tbl:
            raise self.fail(path, f'missing key "{key}"')
        return tbl[key]

    def string(self, value: object, path: Path) -> str:
        if not isinstance(value, str):
            raise self.fail(path, f"expected a string, got {_type_name(value)}")
        return value

    def kind(self, spec: Mapping[str, object], path: Path, kinds: Iterable[str], what: str,
             lower: bool = False) -> str:
        """The ``type`` of the table ``spec`` at ``path``, one of ``kinds`` (a located error
        with a suggestion otherwise): forces, joints, quantities, closing joints, contacts."""
        kind = self.string(self.require(spec, "type", path), (*path, "type"))
        kind = kind.lower() if lower else kind
        options = list(kinds)
        if kind not in options:
            raise self.fail((*path, "type"), f'unknown {what} type "{kind}"'
                            f"{self.suggest(kind, options)}; expected one of "
                            f"{', '.join(options)}")
        return kind

    def line_string(self, value: object, path: Path) -> str:
        """A string of one line: no line breaks or other control characters (a model's name
        and units are written into comments and headers of the output files)."""
        s = self.string(value, path)
        bad = next((c for c in s if _CONTROL.match(c)), None)
        if bad is not None:
            raise self.fail(path, f"expected one line of text, got a string with the control "
                            f"character {bad!r} at position {s.index(bad) + 1}")
        return s

    def number(self, value: object, path: Path, positive: bool = False,
               integer: bool = False) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.fail(path, f"expected a number, got {_type_name(value)}")
        if integer and not isinstance(value, int):
            raise self.fail(path, f"expected an integer, got {_type_name(value)}")
        if isinstance(value, int):
            self.integer_in_range(value, path)
        if not math.isfinite(value):
            raise self.fail(path, f"expected a finite number, got {value}")
        if value and abs(value) < SMALLEST_NORMAL:
            raise self.fail(path, f"{value:g} is {SUBNORMAL}")
        if positive and value <= 0:
            raise self.fail(path, f"expected a positive number, got {value}")
        return float(value)

    def integer_in_range(self, value: int, path: Path) -> None:
        """An integer of the file must be a floating-point number (|value| < 1.8e308)."""
        try:
            float(value)
        except OverflowError:
            raise self.fail(path, f"the integer of {len(str(abs(value)))} digits is too large for "
                            "a floating-point number (at most about 1.8e308)") from None

    def name(self, value: object, path: Path, what: str) -> str:
        s = self.string(value, path)
        if not _IDENT.match(s):
            raise self.fail(path, f'{what} name "{s}" must start with a letter and contain only '
                            "letters, digits and _")
        return s

    # --- expressions ----------------------------------------------------------------------
    def names_hint(self, allowed: Container[str], context: str) -> Callable[[str], str]:
        def hint(name: str) -> str:
            if name in self.coords and "coordinates" not in context:
                return f" (coordinates are not allowed in {context})"
            if name.endswith("_d") and name[:-2] in self.coords:
                return f" (rates are not allowed in {context})"
            if name == "t":
                return f" (time t is not allowed in {context})"
            if name in self.inputs:
                return f" (inputs are not allowed in {context})"
            if name in ("elongation", "elongation_d"):
                return " (elongation and elongation_d are allowed in a spring law only)"
            if name in ("deflection", "deflection_d"):
                return (" (deflection and deflection_d are allowed in a generalized force's "
                        "value and a bushing law only)")
            pool = [n for n in (*self.coords, *self.params, *self.inputs) if n in allowed]
            sugg = self.suggest(name, pool)
            return f"; it is not declared{sugg} — {context} may use {_listing(self, allowed)}"
        return hint

    def expr(self, value: object, path: Path, allowed: Container[str], context: str) -> se.Basic:
        if isinstance(value, bool):
            raise self.fail(path, "expected a number or an expression string, got a boolean")
        if isinstance(value, int):
            self.integer_in_range(value, path)
            return se.Integer(value)
        if isinstance(value, float):
            if not math.isfinite(value):
                raise self.fail(path, f"expected a finite number, got {value}")
            if value and abs(value) < SMALLEST_NORMAL:
                raise self.fail(path, f"{value:g} is {SUBNORMAL}")
            # the decimal the user wrote (0.7 is 7/10), as in expression strings
            return _number(repr(value))
        if not isinstance(value, str):
            raise self.fail(path, f"expected a number or an expression string, got "
                            f"{_type_name(value)}")
        try:
            e = parse_expression(value, allowed, describe=self.names_hint(allowed, context),
                                 symbol=self.symbol)
        except ExpressionError as exc:
            col = f" at column {exc.column}" if exc.column else ""
            raise self.fail(path, f'in expression "{_clip(value)}"{col}: {exc}') from None
        self.real_at_defaults(e, value, path)
        return e

    def symbol(self, name: str) -> se.Basic:
        """The symbol of a name: a kinematic quantity's own symbol, or a plain one."""
        q = self.quantity_symbols.get(name)
        return q if q is not None else se.Symbol(name)

    def real_at_defaults(self, e: se.Basic, text: str, path: Path) -> None:
        """An expression of the parameters alone must be a finite real number at their default
        values (``sqrt(-l1)``, ``1/(l1 - 1)`` with l1 = 1 are refused where they are written);
        expressions of coordinates, rates, inputs or t are checked when evaluated."""
        syms = e.free_symbols
        if not syms or not all(str(x) in self.params for x in syms):
            return
        values = {x: self.params[str(x)] for x in syms}
        at = e.subs(values)
        try:
            v = float(at)
        except (RuntimeError, TypeError, ValueError, OverflowError):
            v = math.nan
        if not math.isfinite(v):
            given = ", ".join(f"{x} = {values[x]:g}" for x in sorted(values, key=str))
            raise self.fail(path, f'"{_clip(text)}" is not a finite real number at the default '
                            f"parameter values ({given}): it is {_clip(str(at))}")

    def vector(self, value: object, path: Path, allowed: Container[str], context: str,
               n: int = 3) -> tuple[se.Basic, ...]:
        if not isinstance(value, list):
            raise self.fail(path, f"expected a {n}-vector (an array of {n} numbers or "
                            f"expressions), got {_type_name(value)}")
        if len(value) != n:
            raise self.fail(path, f"expected a {n}-vector, got {len(value)} component"
                            f"{'s' if len(value) != 1 else ''}")
        return tuple(self.expr(v, (*path, i), allowed, context) for i, v in enumerate(value))

    def axis(self, value: object, path: Path, allowed: Container[str],
             context: str) -> str | tuple[se.Basic, ...]:
        if isinstance(value, str):
            s = value.strip().lower().lstrip("+")
            if s.lstrip("-") not in ("x", "y", "z"):
                raise self.fail(path, f'expected one of x, y, z or a 3-vector, got "{value}"')
            return s
        if isinstance(value, list):
            # a direction: the same rule as the Python API (unit_axis), located in the file
            u = unit_axis(self.vector(value, path, allowed, context))
            if u is None:
                jname = self.joint_of_body.get(str(path[1])) if path[:1] == ("bodies",) else None
                which = f'the axis of joint "{jname}"' if jname else "the axis"
                raise self.fail(path, f"{which} must not be the zero vector")
            return u
        raise self.fail(path, f"expected one of x, y, z or a 3-vector, got {_type_name(value)}")

    def matrix3(self, value: object, path: Path, allowed: Container[str],
                context: str) -> tuple[tuple[se.Basic, ...], ...]:
        if not isinstance(value, list) or len(value) != 3 or not all(
                isinstance(r, list) for r in value):
            raise self.fail(path, f"expected a 3x3 matrix (an array of 3 rows of 3), got "
                            f"{_type_name(value)}")
        for i, r in enumerate(value):
            if len(r) != 3:
                raise self.fail((*path, i), f"expected a row of 3 entries, got {len(r)}")
        return tuple(tuple(self.expr(v, (*path, i, j), allowed, context)
                           for j, v in enumerate(r)) for i, r in enumerate(value))


def _listing(loader: _Values, allowed: Container[str]) -> str:
    parts = []
    for label, names in (("coordinates", loader.coords),
                         ("rates", [f"{c}_d" for c in loader.coords]),
                         ("parameters", list(loader.params)), ("inputs", loader.inputs),
                         ("kinematic quantities", list(loader.quantity_symbols))):
        shown = [n for n in names if n in allowed]
        if shown:
            parts.append(f"{label} {', '.join(shown)}")
    if "t" in allowed:
        parts.append("t")
    return "; ".join(parts) if parts else "numbers only"


