"""Numbers of shared expression graphs: evaluation and first derivatives in floating point.

:func:`evaluate_float` gives the numbers of some expressions for numbers of their symbols, and
:func:`jet_float` their values and Jacobian (forward mode with dense NumPy gradients),
:func:`evaluate_float_many` their numbers at several sets of values in one walk, and
:func:`evaluate_arrays` their values at many states at once (NumPy arrays), each visiting every
distinct node of the :class:`~jourdain.graph.Graph` once. For one evaluation this
is faster than compiling; for many, compile (:func:`jourdain.numeric.lambdify`).

Floor: graph tools (imports only this package and :mod:`jourdain.errors`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import symengine as se

from ..errors import EvaluationError, JourdainError
from .forward import needed_gradients, partials
from .identity import Expr, no_gc
from .memo import graph_of
from .nodes import Graph
from .piecewise import PIECEWISE, describe, float_partials

# --- numbers -------------------------------------------------------------------------------------
_FLOAT_FUNCS: dict[str, Callable[..., float]] = {
    "sin": math.sin, "cos": math.cos, "tan": math.tan, "asin": math.asin, "acos": math.acos,
    "atan": math.atan, "sinh": math.sinh, "cosh": math.cosh, "tanh": math.tanh, "log": math.log,
    "Abs": abs, "atan2": math.atan2, "sign": lambda x: float((x > 0) - (x < 0)),
    "Max": max, "Min": min,
}


def evaluate_float(exprs: Sequence[Expr], values: Mapping[str, float]) -> list[float]:
    """Numbers of some expressions for numbers of their symbols, visiting each shared node once.

    For a single evaluation this is faster than compiling (no code generation); for many
    evaluations compile with :func:`jourdain.numeric.lambdify`. ``values`` maps symbol names to
    numbers; a symbol without a value raises :class:`JourdainError`. The graph of the same
    expression objects is built once (:func:`jourdain.graph.memo.graph_of`).
    """
    g = graph_of(exprs)
    with no_gc():
        num = _float_values(g, values)
    return [num[k] for k in g.roots]


def _float_values(g: Graph, values: Mapping[str, float]) -> dict[int, float]:
    num: dict[int, float] = {}
    for ka, a in g.atoms.items():
        if a.is_Symbol:
            name = str(a)
            if name not in values:
                raise JourdainError(f'no value for the symbol "{name}"')
            num[ka] = float(values[name])
        else:
            num[ka] = float(a)
    funcs = _FLOAT_FUNCS
    fsum, prod = _sum, math.prod
    kind, children = g.kind, g.children
    for k in g.order:
        args = [num[c] for c in children[k]]
        name = kind[k]
        if name == "Add":
            v = fsum(args)
        elif name == "Mul":
            v = prod(args)
        elif name == "Pow":
            b, e = args
            try:
                base = g.atoms.get(children[k][0])
                # `is not None` first: comparing None with a SymEngine number imports SymPy
                # (0.3 s) to convert it
                v = math.exp(e) if base is not None and base == se.E else b**e
            except (ZeroDivisionError, OverflowError):
                raise JourdainError(f"{b}**{e}: division by zero or overflow") from None
            if isinstance(v, complex):
                raise JourdainError(f"{b}**{e} has no real value")
        elif name in funcs:
            try:
                v = funcs[name](*args)
            except (ValueError, ZeroDivisionError, OverflowError):
                raise JourdainError(f"{name}{tuple(args)} has no real value") from None
        else:
            v = float(g.node[k].func(*(se.RealDouble(x) for x in args)))
        num[k] = v
    return num


def evaluate_float_many(exprs: Sequence[Expr], values: Sequence[Mapping[str, float]]
                        ) -> np.ndarray:
    """:func:`evaluate_float` at several sets of symbol values at once: an array (sets,
    expressions). The graph is walked once with NumPy vectors of the sets' values (sums left to
    right, not ``fsum``: rounding of the terms' size). Where a value is not finite, each set is
    evaluated again by :func:`evaluate_float`, which names a value that is not real."""
    g = graph_of(exprs)
    n = len(values)
    num: dict[int, Any] = {}
    for ka, a in g.atoms.items():
        if a.is_Symbol:
            name = str(a)
            if any(name not in v for v in values):
                raise JourdainError(f'no value for the symbol "{name}"')
            num[ka] = np.array([float(v[name]) for v in values])
        else:
            num[ka] = np.full(n, float(a))
    kind, children = g.kind, g.children
    with no_gc(), np.errstate(all="ignore"):
        for k in g.order:
            args = [num[c] for c in children[k]]
            name = kind[k]
            if name == "Add" or name == "Mul":
                v = args[0]
                for x in args[1:]:
                    v = v + x if name == "Add" else v * x
            elif name == "Pow":
                base = g.atoms.get(children[k][0])
                v = (np.exp(args[1]) if base is not None and base == se.E
                     else np.power(args[0], args[1]))
            elif name in ("Max", "Min"):
                v = (np.maximum if name == "Max" else np.minimum).reduce(args)
            elif name in _NUMPY:
                v = _NUMPY[name](*args)
            else:
                v = np.array([float(g.node[k].func(*(se.RealDouble(float(x[i])) for x in args)))
                              for i in range(n)])
            num[k] = v
        out = np.array([num[k] for k in g.roots]).reshape(len(g.roots), n).T
    if not np.all(np.isfinite(out)):
        return np.array([evaluate_float(exprs, v) for v in values], dtype=float)
    return out


def _sum(args: list[float]) -> float:
    """``math.fsum`` (exactly rounded), or the floating-point sum where fsum refuses: inf where
    a partial sum overflows, NaN for inf − inf (fsum raises OverflowError and ValueError there;
    the callers check their results for inf and NaN and name the quantity)."""
    try:
        return math.fsum(args)
    except (OverflowError, ValueError):
        total = 0.0
        for x in args:
            total += x  # Python floats: inf and NaN, never an exception or a warning
        return total


def free_symbol_names(exprs: Sequence[Expr]) -> set[str]:
    """Names of the symbols in some expressions, visiting each shared node once (SymEngine's
    ``free_symbols`` walks a shared graph as a tree)."""
    return graph_of(exprs).symbol_names()


# --- numeric forward mode --------------------------------------------------------------------
_DFLOAT = {
    "sin": lambda v, val: math.cos(v[0]),
    "cos": lambda v, val: -math.sin(v[0]),
    "tan": lambda v, val: 1.0 + val * val,
    "log": lambda v, val: 1.0 / v[0],
    "atan": lambda v, val: 1.0 / (1.0 + v[0] ** 2),
    "asin": lambda v, val: 1.0 / math.sqrt(1.0 - v[0] ** 2),
    "acos": lambda v, val: -1.0 / math.sqrt(1.0 - v[0] ** 2),
    "sinh": lambda v, val: math.cosh(v[0]),
    "cosh": lambda v, val: math.sinh(v[0]),
    "tanh": lambda v, val: 1.0 - val * val,
}


def _describer(node: Expr) -> Callable[[], str]:
    """A function naming the piecewise ``node`` for a message (made only when needed)."""
    return lambda: describe(type(node).__name__, node.args)


@dataclass(frozen=True)
class FloatJet:
    """Result of :func:`jet_float`: ``values`` (n,), ``jacobian`` (n, number of variables), and
    ``symbols``: the names of all symbols met in the expressions."""

    values: np.ndarray
    jacobian: np.ndarray
    symbols: frozenset[str]


def jet_float(exprs: Sequence[Expr] | Graph, variables: Sequence[se.Symbol],
              values: Mapping[str, float], differentiate: Sequence[bool] | None = None
              ) -> FloatJet:
    """Numbers and first derivatives of ``exprs`` with respect to ``variables`` at a numeric
    point: forward mode in floating point with dense NumPy gradients, each shared node once.

    ``exprs`` may be a prebuilt :class:`Graph` (to evaluate the same expressions at many
    points). ``values`` maps every symbol name of the expressions (variables included) to a
    number. Only the expressions marked in ``differentiate`` are differentiated (all when
    None); the rows of the others in the Jacobian are zero.
    """
    g = exprs if isinstance(exprs, Graph) else Graph(exprs)
    mask = ([True] * len(g.roots) if differentiate is None
            else [bool(d) for d in differentiate])
    with no_gc():
        return _jet_float(g, variables, values, mask)


def _jet_float(g: Graph, variables: Sequence[se.Symbol], values: Mapping[str, float],
               mask: list[bool]) -> FloatJet:
    nv = len(variables)
    unit = np.eye(nv)
    var_index = {str(v): i for i, v in enumerate(variables)}
    value = _float_values(g, values)
    grad: dict[int, np.ndarray | None] = {}
    for ka, a in g.atoms.items():
        i = var_index.get(str(a)) if a.is_Symbol else None
        grad[ka] = None if i is None else unit[i]
    atom_keys = set(g.atoms)

    # nodes that need a gradient (a product with two vanishing factors needs none)
    need = needed_gradients(g, value, mask, atom_keys, lambda v: v == 0.0)

    # gradients (None: does not depend on the variables)
    prod = math.prod
    for k in g.order:
        if k not in need:
            continue
        kids = g.children[k]
        grads = [grad.get(c) for c in kids]
        if all(x is None for x in grads):
            grad[k] = None
            continue
        vals = [value[c] for c in kids]
        node = g.node[k]
        name = g.kind[k]
        acc = None
        if name == "Add":
            for x in grads:
                if x is not None:
                    acc = x if acc is None else acc + x
        elif name == "Mul":
            n = len(vals)
            for i, x in enumerate(grads):
                if x is None:
                    continue
                c = prod(vals[j] for j in range(n) if j != i) if n > 2 else vals[1 - i]
                if c != 0.0:
                    acc = c * x if acc is None else acc + c * x
        elif name == "Pow":
            b, e = vals
            gb, ge = grads
            if gb is not None:
                acc = (e * b ** (e - 1.0)) * gb
            if ge is not None:
                term = (value[k] * math.log(b)) * ge
                acc = term if acc is None else acc + term
        else:
            if name in _DFLOAT:
                coeffs = [_DFLOAT[name](vals, value[k])]
            elif name in PIECEWISE:  # the branch at the point; refused at the switch
                what = _describer(node)
                coeffs = float_partials(name, vals, [x is not None for x in grads], what)
            elif name == "atan2":
                yy, xx = vals
                r2 = xx * xx + yy * yy
                coeffs = [xx / r2, -yy / r2]
            else:
                coeffs = [float(p) for p in partials(node, name,
                                                        [se.RealDouble(x) for x in vals],
                                                        se.RealDouble(value[k]))]
            for c, x in zip(coeffs, grads, strict=True):
                if x is not None and c != 0.0:
                    acc = c * x if acc is None else acc + c * x
        grad[k] = acc

    out_v = np.array([value[k] for k in g.roots], dtype=float)
    out_j = np.zeros((len(g.roots), nv))
    for i, k in enumerate(g.roots):
        gi = grad.get(k) if mask[i] else None
        if gi is not None:
            out_j[i] = gi
    return FloatJet(out_v, out_j, frozenset(g.symbol_names()))


# --- arrays ------------------------------------------------------------------------------------
_NUMPY: dict[str, Callable[..., Any]] = {
    "sin": np.sin, "cos": np.cos, "tan": np.tan, "exp": np.exp, "log": np.log, "Abs": np.abs,
    "asin": np.arcsin, "acos": np.arccos, "atan": np.arctan, "sinh": np.sinh, "cosh": np.cosh,
    "tanh": np.tanh, "sign": np.sign, "atan2": np.arctan2,
}


def evaluate_arrays(exprs: Sequence[Expr], values: Mapping[Expr, Any]) -> list[Any]:
    """Values of ``exprs`` for symbol values ``values`` (symbol -> number or NumPy array,
    broadcast), each node of the merged graph evaluated once (sums and products left to right
    in the order of the node's arguments). A symbol without a value raises
    :class:`EvaluationError`. Meant for checks at many random states at once (a joint's
    directions, reference comparisons); the matrices of whole systems are evaluated by the
    compiled code of :mod:`jourdain.numeric`."""
    given = {k: np.asarray(v, dtype=float) for k, v in values.items()}

    def atom(a: Expr) -> Any:
        if isinstance(a, se.Symbol):
            if a in given:
                return given[a]
            raise EvaluationError(f"no value for symbol {a}")
        return float(a)

    exprs = list(exprs)
    m = Graph(exprs).merged()
    val: dict[int, Any] = {}
    for i in m.order:
        args = [atom(a) if ia is None else val[ia]
                for a, ia in zip(m.args[i], m.arg_ids[i], strict=True)]
        val[i] = _apply_array(m.node[i], args)
    return [atom(e) if r is None else val[r] for e, r in zip(exprs, m.root_ids, strict=True)]


def _apply_array(node: Expr, args: list[Any]) -> Any:
    name = type(node).__name__
    if name == "Add":
        r = args[0]
        for x in args[1:]:
            r = r + x
        return r
    if name == "Mul":
        r = args[0]
        for x in args[1:]:
            r = r * x
        return r
    if name == "Pow":
        return np.power(args[0], args[1])
    if name in _NUMPY:
        return _NUMPY[name](*args)
    return np.vectorize(lambda *xs: float(node.func(*(se.Float(x) for x in xs))))(*args)
