"""First derivatives of shared expression graphs, evaluated at a point (forward mode).

The recursive kinematics builds M, k, q as graphs that share sub-expressions; SymEngine's
``diff`` walks them as trees, and expanding the derivative of every entry separately repeats the
work for every shared node. :func:`jet` instead visits each distinct node once, children before
parents, and carries for every node

* its *value at the point* (the node with the point's substitutions, e.g. ``y → y_s(t)``,
  ``ẏ → ẏ_s(t)``), and
* its *gradient at the point*: a sparse dict ``{variable index: ∂node/∂variable |_point}``.

This is the chain rule of dual numbers, with symbolic (parameter- and time-dependent) values.
Substituting while differentiating keeps the results short: at an equilibrium ``sin(0)`` and
``ẏ_s = 0`` collapse whole sub-graphs to numbers, and a product with two factors that vanish at
the point needs no gradient of its other factors at all (the *needed* pass below finds them
before any derivative is formed).

Nodes are identified by the address of the SymEngine object a wrapper holds ,
not by SymEngine's hash: that hash combines the terms of a sum by exclusive-or, so different sums
collide often (``cx5 + dx4`` and ``cx5 + dx0 + dx1 + dx2 + dx3 + dx4`` have the same hash), and a
collision confirmed only by the children's hashes would silently merge different expressions.
``==`` would be exact but walks distinct-but-equal deep nodes as trees. Where the address cannot be
read (another Python implementation), identity falls back to the hash confirmed by ``==``.
"""

from __future__ import annotations

import gc
import math
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

import numpy as np
import symengine as se

from .cse import _POINTER_OFFSET, POINTERS, NodeIds, _read_pointer
from .errors import JourdainError

Expr = se.Basic
ZERO = se.Integer(0)
ONE = se.Integer(1)


@dataclass(frozen=True)
class Jet:
    """Result of :func:`jet`: ``values[i]`` is ``exprs[i]`` at the point and ``gradients[i]``
    a dict ``{j: ∂exprs[i]/∂variables[j] at the point}`` (entries that vanish are left out)."""

    values: tuple[Expr, ...]
    gradients: tuple[dict[int, Expr], ...]

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


# --- identity of SymEngine nodes: the address of the C++ object (jourdain.cse), read inline in
# the walk below because it runs once per edge of the graph
_POINTERS = POINTERS


class Graph:
    """The distinct nodes of some expressions, identified by address (see the module docstring).

    ``order``: keys of the non-atomic nodes, children before parents; ``node``: key -> node;
    ``children``: key -> tuple of the children's keys (atoms included); ``atoms``: key -> atom
    (symbols and numbers). ``roots``: the keys of the expressions, in order. A graph is built
    once and may be walked many times (an equilibrium search evaluates the same equations at
    many points); it keeps every node alive, so the addresses stay valid.
    """

    def __init__(self, exprs: Sequence[Expr]) -> None:
        with _no_gc():
            self._build(list(exprs))

    def _build(self, exprs: list[Expr]) -> None:
        node: dict[int, Expr] = {}
        atoms: dict[int, Expr] = {}
        children: dict[int, tuple[int, ...]] = {}
        order: list[int] = []
        kind: dict[int, str] = {}
        if _POINTERS:
            rd, off = _read_pointer, _POINTER_OFFSET

            def key(e: Expr) -> int:
                return rd(id(e) + off).value  # type: ignore[return-value]
        else:
            key = NodeIds()
        roots = []
        for root in exprs:
            rk = key(root)
            roots.append(rk)
            if root.is_Atom:
                atoms[rk] = root
                continue
            if rk in node:
                continue
            stack: list[tuple[Expr, int, tuple[int, ...] | None]] = [(root, rk, None)]
            while stack:
                e, k, kids = stack.pop()
                if kids is not None:
                    if k not in node:
                        node[k] = e
                        kind[k] = type(e).__name__
                        children[k] = kids
                        order.append(k)
                    continue
                if k in node:
                    continue
                keys = []
                push = []
                for a in e.args:
                    # the address read inline: this loop runs once per edge of the graph
                    ka = rd(id(a) + off).value if _POINTERS else key(a)
                    keys.append(ka)
                    if ka in node or ka in atoms:
                        continue
                    if a.is_Atom:
                        atoms[ka] = a
                    else:
                        push.append((a, ka, None))
                stack.append((e, k, tuple(keys)))
                stack.extend(push)
        self.kind = kind
        self.node = node
        self.atoms = atoms
        self.children = children
        self.order = order
        self.roots = tuple(roots)
        self._exprs = exprs  # keeps the roots (and so every node) alive

    def symbol_names(self) -> set[str]:
        """Names of the symbols among the atoms."""
        return {str(a) for a in self.atoms.values() if a.is_Symbol}


@contextmanager
def _no_gc() -> Iterator[None]:
    # the walks allocate hundreds of thousands of small objects but no reference cycles; the
    # cyclic collector would otherwise run hundreds of times and double the run time
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


def _needed(g: Graph, value: Mapping[int, Any], mask: list[bool], atom_keys: set[int],
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
    with _no_gc():
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
    need = _needed(g, value, mask, atom_keys, _is_zero)

    # 3. gradients of the needed nodes, bottom-up
    for k in g.order:
        if k not in need:
            continue
        kids = g.children[k]
        grads = [grad.get(c, {}) for c in kids]
        if not any(grads):
            grad[k] = {}
            continue
        grad[k] = _chain(g.node[k], [value[c] for c in kids], grads, value[k])

    values = tuple(value[k] for k in g.roots)
    gradients = tuple(dict(grad.get(k, {})) if m else {}
                      for k, m in zip(g.roots, mask, strict=True))
    return Jet(values, gradients)


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
           value: Expr) -> dict[int, Expr]:
    """Gradient of ``node`` from its arguments' values and gradients (chain rule)."""
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
    coeffs = _partials(node, name, vals, value)
    for c, gk in zip(coeffs, grads, strict=True):
        if gk:
            _accumulate(terms, c, gk)
    return _collect(terms)


def _partials(node: Expr, name: str, v: list[Expr], value: Expr) -> list[Expr]:
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
    if name == "Abs":
        return [se.sign(v[0])]
    if name == "sign":
        return [ZERO]
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


# --- numbers -------------------------------------------------------------------------------------
_FLOAT_FUNCS = {
    "sin": math.sin, "cos": math.cos, "tan": math.tan, "asin": math.asin, "acos": math.acos,
    "atan": math.atan, "sinh": math.sinh, "cosh": math.cosh, "tanh": math.tanh, "log": math.log,
    "Abs": abs, "atan2": math.atan2, "sign": lambda x: float((x > 0) - (x < 0)),
}


def evaluate_float(exprs: Sequence[Expr], values: Mapping[str, float]) -> list[float]:
    """Numbers of some expressions for numbers of their symbols, visiting each shared node once.

    For a single evaluation this is faster than compiling (no code generation); for many
    evaluations compile with :func:`jourdain.numeric.lambdify`. ``values`` maps symbol names to
    numbers; a symbol without a value raises :class:`JourdainError`.
    """
    g = Graph(exprs)
    with _no_gc():
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
    fsum, prod = math.fsum, math.prod
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
                v = math.exp(e) if g.atoms.get(children[k][0]) == se.E else b**e
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


def free_symbol_names(exprs: Sequence[Expr]) -> set[str]:
    """Names of the symbols in some expressions, visiting each shared node once (SymEngine's
    ``free_symbols`` walks a shared graph as a tree)."""
    return Graph(exprs).symbol_names()


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
    "Abs": lambda v, val: float((v[0] > 0) - (v[0] < 0)),
    "sign": lambda v, val: 0.0,
}


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
    with _no_gc():
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
    need = _needed(g, value, mask, atom_keys, lambda v: v == 0.0)

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
                partials = [_DFLOAT[name](vals, value[k])]
            elif name == "atan2":
                yy, xx = vals
                r2 = xx * xx + yy * yy
                partials = [xx / r2, -yy / r2]
            else:
                partials = [float(p) for p in _partials(node, name,
                                                        [se.RealDouble(x) for x in vals],
                                                        se.RealDouble(value[k]))]
            for c, x in zip(partials, grads, strict=True):
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
