"""Derivatives of the piecewise functions of the expression language: ``max``, ``min``,
``abs`` and ``sign`` (SymEngine's ``Max``, ``Min``, ``Abs``, ``sign``).

Each is smooth on either side of its switching point (arguments equal, argument zero) and has
no derivative there. A linearization differentiates it on the branch active at the point:

* where the quantity that decides the branch (``a − b`` for ``max(a, b)``, ``a`` for
  ``abs(a)``) is a number at the point, the branch is chosen now, and a zero is a
  :class:`SwitchingPoint` error;
* where it still depends on symbols (parameters, t, or the state of the general form), the
  derivative carries the step ``H(d) = (1 + sign(d))/2`` — exact on either side for any
  values — and ``d`` is returned as a *switch*: evaluating the derivative where ``d = 0``
  exactly is refused (:func:`check_switches`) instead of giving the mean of the two sides.

Only arguments that depend on the variables matter: ``max(c, 0)`` of parameters alone is a
constant of the linearization whatever its branch.

Floor: graph tools (imports only this package and :mod:`jourdain.errors`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import symengine as se

from ..errors import EvaluationError

#: SymEngine's names of the piecewise functions, by the language's names
PIECEWISE = {"Max": "max", "Min": "min", "Abs": "abs", "sign": "sign"}

ZERO = se.Integer(0)
ONE = se.Integer(1)
HALF = se.Rational(1, 2)

#: a switch: what to name in a message, and the expression whose zero is the switching point
Switch = tuple[str, Any]


class SwitchingPoint(EvaluationError):
    """A piecewise function (max, min, abs, sign) differentiated exactly where it switches
    branches: it has no derivative there."""


def describe(name: str, args: Sequence[Any], limit: int = 160) -> str:
    """``max(a, b)`` in the language's words, clipped to ``limit`` characters."""
    text = f"{PIECEWISE.get(name, name)}({', '.join(str(a) for a in args)})"
    return text if len(text) <= limit else text[:limit // 2] + " … " + text[-limit // 2:]


def refusal(what: str) -> SwitchingPoint:
    why = ("its argument is zero" if what.startswith(("abs(", "sign("))
           else "two of its arguments are equal")
    return SwitchingPoint(
        f"{what} switches branches exactly at this state ({why}): it has no derivative "
        "there, so the linearization is not defined; linearize about a state on either side "
        "(a nominal value or a parameter a little different)")


def _number(d: Any) -> float | None:
    """``d`` as a float when it holds no symbols, else None."""
    if d.is_Number:
        return float(d)
    if not d.free_symbols:
        try:
            return float(d)
        except (RuntimeError, TypeError, ValueError):
            return None
    return None


def symbolic_partials(name: str, args: Sequence[Any], live: Sequence[bool],
                      switches: list[Switch]) -> list[Any]:
    """∂f/∂args of a piecewise function at the point ``args`` (symbolic), for the arguments
    marked ``live`` (those that depend on the variables; the others get 0). Branches that
    still depend on symbols are appended to ``switches``."""
    what = describe(name, args)

    def step(d: Any) -> Any:  # H(d) = 1 for d > 0, 0 for d < 0
        x = _number(d)
        if x is None:
            switches.append((what, d))
            return HALF + HALF * se.sign(d)
        if x == 0.0:
            raise refusal(what)
        return ONE if x > 0 else ZERO

    if name in ("Abs", "sign"):
        if not live[0]:
            return [ZERO]
        h = step(args[0])
        return [2 * h - ONE] if name == "Abs" else [ZERO]
    out = []
    for k, a in enumerate(args):
        if not live[k]:
            out.append(ZERO)
            continue
        coeff = ONE
        for j, b in enumerate(args):
            if j != k:
                coeff = coeff * step(a - b if name == "Max" else b - a)
        out.append(coeff)
    return out


def float_partials(name: str, args: Sequence[float], live: Sequence[bool],
                   what: Callable[[], str]) -> list[float]:
    """The same in floating point: the branch at the point, a :class:`SwitchingPoint` where
    a live argument sits exactly at the switch (``what()`` names the function)."""
    if name in ("Abs", "sign"):
        if live[0] and args[0] == 0.0:
            raise refusal(what())
        return [(1.0 if args[0] > 0 else -1.0) if name == "Abs" else 0.0]
    best = max(args) if name == "Max" else min(args)
    on = [a == best for a in args]
    if sum(on) > 1 and any(o and v for o, v in zip(on, live, strict=True)):
        raise refusal(what())
    return [1.0 if o else 0.0 for o in on]


def check_switches(switches: Sequence[Switch], evaluate: Callable[[list[Any]],
                   Sequence[float]]) -> None:
    """Refuse the numbers of a linearization where one of its ``switches`` is exactly zero:
    ``evaluate`` gives the numbers of a list of expressions at the values at hand."""
    if not switches:
        return
    for (what, _), d in zip(switches, evaluate([e for _, e in switches]), strict=True):
        if d == 0.0:
            raise refusal(what)


def switches_at(switches: Sequence[Switch], values: Mapping[str, float],
                evaluate_float: Callable[..., list[float]]) -> None:
    """:func:`check_switches` with :func:`jourdain.graph.evaluate_float` at ``values``
    (symbols without a value are not checked: the caller's evaluation reports them)."""
    check_switches(switches, lambda exprs: evaluate_float(exprs, values))


_PIECEWISE_TYPES = (se.Max, se.Min, se.Abs, type(se.sign(se.Symbol("x"))))


def _step(d: Any) -> Any:
    """H(d) = (1 + sign(d))/2, the branch indicator, as an expression."""
    return HALF + HALF * se.sign(d)


def diff(e: Any, x: Any) -> Any:
    """∂e/∂x, with ``max``, ``min``, ``abs`` and ``sign`` differentiated on their branches
    (``∂max(a, b)/∂a = H(a − b)``, ``∂|a|/∂a = sign(a)``, ``∂sign(a)/∂a = 0``, H the step
    ``(1 + sign)/2``): exact on either side of a switching point, where SymEngine's own
    ``diff`` leaves an unevaluated ``Derivative`` (a prescribed motion ``Ω·max(t − T, 0)``)."""
    pieces = [a for a in e.atoms(*_PIECEWISE_TYPES) if x in a.free_symbols]
    if not pieces:
        return se.diff(e, x)
    # the outermost pieces: those inside no other piece
    inner = {b for a in pieces for arg in a.args for b in arg.atoms(*_PIECEWISE_TYPES)}
    outer = sorted((a for a in pieces if a not in inner), key=str)
    dummies = [se.Dummy(f"pw{k}") for k in range(len(outer))]
    back = dict(zip(dummies, outer, strict=True))
    e_d = e.xreplace(dict(zip(outer, dummies, strict=True)))
    total = se.diff(e_d, x)
    for dummy, piece in zip(dummies, outer, strict=True):
        args = piece.args
        name = type(piece).__name__
        if name == "sign":
            continue
        if name == "Abs":
            d_piece = se.sign(args[0]) * diff(args[0], x)
        else:
            d_piece = se.Integer(0)
            for k, a in enumerate(args):
                coeff = ONE
                for j, b in enumerate(args):
                    if j != k:
                        coeff = coeff * _step(a - b if name == "Max" else b - a)
                d_piece = d_piece + coeff * diff(a, x)
        total = total + se.diff(e_d, dummy) * d_piece
    return total.xreplace(back)
