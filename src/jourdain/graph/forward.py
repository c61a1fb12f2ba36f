"""First derivatives of shared expression graphs at a point, symbolically (forward mode).

The recursive kinematics builds M, k, q as graphs that share sub-expressions; SymEngine's
``diff`` walks them as trees, and expanding the derivative of every entry separately repeats the
work for every shared node. :func:`jet` instead visits each distinct node of the
:class:`~jourdain.graph.Graph` once, children before parents, and carries for every node

* its *value at the point* (the node with the point's substitutions, e.g. ``y → y_s(t)``,
  ``ẏ → ẏ_s(t)``), and
* its *gradient at the point*: a sparse dict ``{variable index: ∂node/∂variable |_point}``.

This is the chain rule of dual numbers, with symbolic (parameter- and time-dependent) values.
Substituting while differentiating keeps the results short: at an equilibrium ``sin(0)`` and
``ẏ_s = 0`` collapse whole sub-graphs to numbers, and a product with two factors that vanish at
the point needs no gradient of its other factors at all (the *needed* pass below finds them
before any derivative is formed). The same walk in floating point is :mod:`.numbers`.

Floor: graph tools (imports only this package and :mod:`jourdain.errors`); the linearization
stage (``docs/method.md`` §5) and the equilibrium search build on it.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import symengine as se

from ..errors import JourdainError
from .identity import Expr, no_gc
from .nodes import Graph
from .piecewise import PIECEWISE, Switch, symbolic_partials

ZERO = se.Integer(0)
ONE = se.Integer(1)


@dataclass(frozen=True)
class Jet:
    """Result of :func:`jet`: ``values[i]`` is ``exprs[i]`` at the point and ``gradients[i]``
    a dict ``{j: ∂exprs[i]/∂variables[j] at the point}`` (entries that vanish are left out).
    ``switches``: the piecewise functions (max, min, abs, sign) whose branch at the point
    still depends on symbols, each with the expression whose zero is its switching point
    (:mod:`.piecewise`): the gradients hold there only where it is not zero."""

    values: tuple[Expr, ...]
    gradients: tuple[dict[int, Expr], ...]
    switches: tuple[Switch, ...] = ()

    def jacobian(self, n: int, offset: int = 0) -> list[list[Expr]]:
        """Dense rows ``∂exprs[i]/∂variables[offset + j]`` for ``j < n``."""
        rows = []
        for g in self.gradients:
            row = [ZERO] * n
            for j, d in g.items():
                if offset <= j < offset + n:
                    row[j - offset] = d
            rows.append(row)
        return rows


def _is_zero(e: Expr) -> bool:
    return e.is_Number and e == 0


def needed_gradients(g: Graph, value: Mapping[int, Any], mask: list[bool], atom_keys: set[int],
            is_zero: Callable[[Any], bool]) -> set[int]:
    """Nodes whose gradient is needed, top-down (reverse post-order): the masked roots and their
    descendants, except through a product with two factors that vanish at the point (its
    gradient is zero) or, with one vanishing factor, through the other factors."""
    need: set[int] = {k for k, m in zip(g.roots, mask, strict=True) if m} - atom_keys
    for k in reversed(g.order):
        if k not in need:
            continue
        kids = g.children[k]
        if g.kind[k] == "Mul":
            zeros = [c for c in kids if is_zero(value[c])]
            if len(zeros) >= 2:
                continue
            if len(zeros) == 1:
                need.add(zeros[0])
                continue
        need.update(kids)
    return need


def jet(exprs: Sequence[Expr], variables: Sequence[se.Symbol],
        point: Mapping[se.Symbol, Expr], differentiate: Sequence[bool] | None = None) -> Jet:
    """Values and first derivatives of ``exprs`` with respect to ``variables`` at ``point``.

    Parameters
    ----------
    exprs : sequence of SymEngine expressions
        May share sub-expressions (a DAG); each distinct node is visited once.
    variables : sequence of symbols
        The variables to differentiate by.
    point : mapping symbol -> expression
        Substitutions that define the point; symbols not in it stay as they are (parameters,
        ``t``). It may substitute symbols that are not variables (e.g. accelerations).
    differentiate : sequence of bool, optional
        Which expressions to differentiate (all when None); of the others only the values are
        wanted (their gradients come back empty).

    Returns
    -------
    Jet
        ``values`` (one per expression) and sparse ``gradients``.
    """
    exprs = list(exprs)
    mask = [True] * len(exprs) if differentiate is None else [bool(d) for d in differentiate]
    with no_gc():
        return _jet(exprs, variables, point, mask)


def _jet(exprs: list[Expr], variables: Sequence[se.Symbol], point: Mapping[se.Symbol, Expr],
         mask: list[bool]) -> Jet:
    g = Graph(exprs)
    # symbols are told apart by name (their hashes may collide too)
    var_index = {str(v): i for i, v in enumerate(variables)}
    sub = {str(k): as_basic(v) for k, v in point.items()}
    value: dict[int, Expr] = {}
    grad: dict[int, dict[int, Expr]] = {}
    changed: set[int] = set()
    for ka, a in g.atoms.items():
        value[ka] = a
        grad[ka] = {}
        if a.is_Symbol:
            name = str(a)
            if name in sub:
                value[ka] = sub[name]
                changed.add(ka)
            i = var_index.get(name)
            if i is not None:
                grad[ka] = {i: ONE}
    atom_keys = set(g.atoms)

    # 1. values at the point, bottom-up; a node whose children keep their values is kept as is
    for k in g.order:
        kids = g.children[k]
        if any(c in changed for c in kids):
            value[k] = _rebuild(g.node[k], [value[c] for c in kids])
            changed.add(k)
        else:
            value[k] = g.node[k]

    # 2. which nodes need a gradient, top-down (reverse post-order): a factor of a product
    #    whose other factors vanish at the point contributes nothing
    need = needed_gradients(g, value, mask, atom_keys, _is_zero)

    # 3. gradients of the needed nodes, bottom-up
    switches: list[Switch] = []
    for k in g.order:
        if k not in need:
            continue
        kids = g.children[k]
        grads = [grad.get(c, {}) for c in kids]
        if not any(grads):
            grad[k] = {}
            continue
        grad[k] = _chain(g.node[k], [value[c] for c in kids], grads, value[k], switches)

    values = tuple(value[k] for k in g.roots)
    gradients = tuple(dict(grad.get(k, {})) if m else {}
                      for k, m in zip(g.roots, mask, strict=True))
    return Jet(values, gradients, tuple(dict.fromkeys(switches)))


def as_basic(v: object) -> Expr:
    if isinstance(v, se.Basic):
        return v
    return se.sympify(v)


def _rebuild(node: Expr, args: list[Expr]) -> Expr:
    name = type(node).__name__
    if name == "Add":
        return se.Add(*args)
    if name == "Mul":
        return se.Mul(*args)
    if name == "Pow":
        return se.Pow(args[0], args[1])
    return node.func(*args)


def _accumulate(terms: dict[int, list[Expr]], coeff: Expr, g: dict[int, Expr]) -> None:
    if _is_zero(coeff):
        return
    one = coeff.is_Number and coeff == 1
    for j, d in g.items():
        terms.setdefault(j, []).append(d if one else coeff * d)


def _collect(terms: dict[int, list[Expr]]) -> dict[int, Expr]:
    out = {}
    for j, ts in terms.items():
        s = ts[0] if len(ts) == 1 else se.Add(*ts)
        if not _is_zero(s):
            out[j] = s
    return out


def _chain(node: Expr, vals: list[Expr], grads: list[dict[int, Expr]],
           value: Expr, switches: list[Switch]) -> dict[int, Expr]:
    """Gradient of ``node`` from its arguments' values and gradients (chain rule); the
    branches of piecewise functions that depend on symbols are added to ``switches``."""
    name = type(node).__name__
    terms: dict[int, list[Expr]] = {}
    if name == "Add":
        for gk in grads:
            _accumulate(terms, ONE, gk)
        return _collect(terms)
    if name == "Mul":
        n = len(vals)
        for k in range(n):
            if not grads[k]:
                continue
            coeff = se.Mul(*(vals[j] for j in range(n) if j != k))
            _accumulate(terms, coeff, grads[k])
        return _collect(terms)
    if name == "Pow":
        b, e = vals
        gb, ge = grads
        if gb:
            # d(b^e)/db = e·b^(e-1)
            _accumulate(terms, e * se.Pow(b, e - 1), gb)
        if ge:
            _accumulate(terms, value * se.log(b), ge)
        return _collect(terms)
    if name in PIECEWISE:
        coeffs = symbolic_partials(name, vals, [bool(gk) for gk in grads], switches)
    else:
        coeffs = partials(node, name, vals, value)
    for c, gk in zip(coeffs, grads, strict=True):
        if gk:
            _accumulate(terms, c, gk)
    return _collect(terms)


def partials(node: Expr, name: str, v: list[Expr], value: Expr) -> list[Expr]:
    """Partial derivatives of a function node with respect to each argument, at the point."""
    if name == "sin":
        return [se.cos(v[0])]
    if name == "cos":
        return [-se.sin(v[0])]
    if name == "tan":
        return [ONE + value**2]
    if name == "log":
        return [ONE / v[0]]
    if name == "atan":
        return [ONE / (ONE + v[0] ** 2)]
    if name == "asin":
        return [ONE / se.sqrt(ONE - v[0] ** 2)]
    if name == "acos":
        return [-ONE / se.sqrt(ONE - v[0] ** 2)]
    if name == "sinh":
        return [se.cosh(v[0])]
    if name == "cosh":
        return [se.sinh(v[0])]
    if name == "tanh":
        return [ONE - value**2]
    if name in PIECEWISE:  # the branch at the point, no switches recorded
        return symbolic_partials(name, v, [True] * len(v), [])
    if name == "atan2":
        yy, xx = v
        r2 = xx**2 + yy**2
        return [xx / r2, -yy / r2]
    # any other function: differentiate one level with dummies (never the whole graph)
    dummies = [se.Symbol(f"_jourdain_arg{i}") for i in range(len(v))]
    try:
        shallow = node.func(*dummies)
    except Exception as exc:  # noqa: BLE001 - reported with the node's name
        raise JourdainError(f"cannot differentiate a {name} node: {exc}") from exc
    out = []
    for d in dummies:
        p = se.diff(shallow, d)
        if "Derivative" in str(p) or "Subs" in str(p):
            raise JourdainError(
                f"cannot differentiate {name}(...): no derivative is known for this function"
            )
        out.append(p.subs(dict(zip(dummies, v, strict=True))))
    return out
