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

Nodes are identified by the address of the SymEngine object a wrapper holds (:func:`node_id`),
not by SymEngine's hash: that hash combines the terms of a sum by exclusive-or, so different sums
collide often (``cx5 + dx4`` and ``cx5 + dx0 + dx1 + dx2 + dx3 + dx4`` have the same hash), and a
collision confirmed only by the children's hashes would silently merge different expressions.
``==`` would be exact but walks distinct-but-equal deep nodes as trees. Where the address cannot be
read (another Python implementation), identity falls back to the hash confirmed by ``==``.
"""

from __future__ import annotations

import ctypes
import gc
import math
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass

import symengine as se

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


# --- identity of SymEngine nodes -------------------------------------------------------------
# A SymEngine wrapper (a Cython object) holds one reference-counted pointer to the C++ node, right
# after the Python object header. Two wrappers of one shared node hold the same pointer; the
# pointer stays valid while some wrapper or parent keeps the node alive (the graph walks below keep
# every node they key in a dict).
_POINTER_OFFSET = object.__basicsize__
_read_pointer = ctypes.c_void_p.from_address


def _pointer(e: Expr) -> int:
    return _read_pointer(id(e) + _POINTER_OFFSET).value  # type: ignore[return-value]


def _pointers_work() -> bool:
    try:
        if se.Basic.__basicsize__ != _POINTER_OFFSET + ctypes.sizeof(ctypes.c_void_p):
            return False
        a, b = se.Symbol("_probe_a"), se.Symbol("_probe_b")
        e = se.sin(a + b) * (a - b)
        x1, y1 = e.args
        x2, y2 = e.args
        twin = se.sin(a + b) * (a - b)
        return (_pointer(x1) == _pointer(x2) and _pointer(y1) == _pointer(y2)
                and _pointer(x1) != _pointer(y1) and _pointer(e) != _pointer(twin)
                and _pointer(e) != 0)
    except Exception:  # noqa: BLE001 - any failure means: do not use pointers
        return False


_POINTERS = _pointers_work()


class _Identity:
    """Keys for nodes: the C++ address, or (fallback) the hash with ``==`` confirmation."""

    def __init__(self) -> None:
        self._by_hash: dict[int, list[tuple[Expr, int]]] = {}

    def __call__(self, e: Expr) -> int:
        if _POINTERS:
            return _pointer(e)
        h = hash(e)
        bucket = self._by_hash.setdefault(h, [])
        for known, key in bucket:
            if known == e:
                return key
        key = (h << 8) + len(bucket)
        bucket.append((e, key))
        return key


class _Graph:
    """Distinct non-atomic nodes of some expressions, children before parents."""

    def __init__(self, exprs: Sequence[Expr]) -> None:
        key = _Identity()
        self.key = key
        self.node: dict[int, Expr] = {}
        self.children: dict[int, tuple[tuple[Expr, int | None], ...]] = {}
        self.order: list[int] = []
        for root in exprs:
            if root.is_Atom or key(root) in self.node:
                continue
            stack: list[tuple[Expr, bool]] = [(root, False)]
            while stack:
                e, done = stack.pop()
                k = key(e)
                if k in self.node:
                    continue
                if done:
                    self.node[k] = e
                    self.order.append(k)
                    continue
                kids = tuple((a, None if a.is_Atom else key(a)) for a in e.args)
                self.children[k] = kids
                stack.append((e, True))
                for a, ka in kids:
                    if ka is not None and ka not in self.node:
                        stack.append((a, False))


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


def jet(exprs: Sequence[Expr], variables: Sequence[se.Symbol],
        point: Mapping[se.Symbol, Expr], n_gradients: int | None = None) -> Jet:
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
    n_gradients : int, optional
        Differentiate only the first ``n_gradients`` expressions; of the others only the values
        are wanted (their gradients come back empty).

    Returns
    -------
    Jet
        ``values`` (one per expression) and sparse ``gradients``.
    """
    with _no_gc():
        return _jet(list(exprs), variables, point,
                    len(exprs) if n_gradients is None else n_gradients)


def _jet(exprs: list[Expr], variables: Sequence[se.Symbol], point: Mapping[se.Symbol, Expr],
         n_gradients: int) -> Jet:
    # symbols are told apart by name (their hashes may collide too)
    var_index = {str(v): i for i, v in enumerate(variables)}
    sub = {str(k): as_basic(v) for k, v in point.items()}
    g = _Graph(exprs)

    def atom_value(a: Expr) -> Expr:
        return sub.get(str(a), a) if a.is_Symbol else a

    def atom_grad(a: Expr) -> dict[int, Expr]:
        i = var_index.get(str(a)) if a.is_Symbol else None
        return {} if i is None else {i: ONE}

    value: dict[int, Expr] = {}
    grad: dict[int, dict[int, Expr]] = {}

    def val(a: Expr, ka: int | None) -> Expr:
        return atom_value(a) if ka is None else value[ka]

    # 1. values at the point, bottom-up; a node whose children keep their values is kept as is
    for k in g.order:
        node = g.node[k]
        changed = False
        vals = []
        for a, ka in g.children[k]:
            v = val(a, ka)
            if v is not a:
                changed = True
            vals.append(v)
        value[k] = _rebuild(node, vals) if changed else node

    # 2. which nodes need a gradient, top-down (reverse post-order): a factor of a product
    #    whose other factors vanish at the point contributes nothing
    need: set[int] = {g.key(e) for e in exprs[:n_gradients] if not e.is_Atom}
    for k in reversed(g.order):
        if k not in need:
            continue
        kids = g.children[k]
        if type(g.node[k]).__name__ == "Mul":
            zeros = [i for i, (a, ka) in enumerate(kids) if _is_zero(val(a, ka))]
            if len(zeros) >= 2:
                continue
            if len(zeros) == 1:
                ka = kids[zeros[0]][1]
                if ka is not None:
                    need.add(ka)
                continue
        for _, ka in kids:
            if ka is not None:
                need.add(ka)

    # 3. gradients of the needed nodes, bottom-up
    for k in g.order:
        if k not in need:
            continue
        kids = g.children[k]
        grads = [atom_grad(a) if ka is None else grad.get(ka, {}) for a, ka in kids]
        if not any(grads):
            grad[k] = {}
            continue
        vals = [val(a, ka) for a, ka in kids]
        grad[k] = _chain(g.node[k], vals, grads, value[k])

    values = []
    gradients = []
    for i, e in enumerate(exprs):
        if not e.is_Atom:
            k = g.key(e)
            values.append(value[k])
            gradients.append(dict(grad[k]) if i < n_gradients else {})
        else:
            values.append(atom_value(e))
            gradients.append(atom_grad(e) if i < n_gradients else {})
    return Jet(tuple(values), tuple(gradients))


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
    with _no_gc():
        exprs = list(exprs)
        g = _Graph(exprs)
        num: dict[int, float] = {}

        def atom(a: Expr) -> float:
            if a.is_Symbol:
                name = str(a)
                if name not in values:
                    raise JourdainError(f'no value for the symbol "{name}"')
                return float(values[name])
            return float(a)

        for k in g.order:
            node = g.node[k]
            args = [atom(a) if ka is None else num[ka] for a, ka in g.children[k]]
            name = type(node).__name__
            if name == "Add":
                num[k] = math.fsum(args) if len(args) > 8 else sum(args)
            elif name == "Mul":
                num[k] = math.prod(args)
            elif name == "Pow":
                num[k] = math.exp(args[1]) if node.args[0] == se.E else args[0] ** args[1]
            elif name in _FLOAT_FUNCS:
                num[k] = _FLOAT_FUNCS[name](*args)
            else:
                num[k] = float(node.func(*(se.RealDouble(x) for x in args)))
        return [atom(e) if e.is_Atom else num[g.key(e)] for e in exprs]


def free_symbol_names(exprs: Sequence[Expr]) -> set[str]:
    """Names of the symbols in some expressions, visiting each shared node once (SymEngine's
    ``free_symbols`` walks a shared graph as a tree)."""
    with _no_gc():
        exprs = list(exprs)
        g = _Graph(exprs)
        out: set[str] = set()
        for e in exprs:
            if e.is_Symbol:
                out.add(str(e))
        for kids in g.children.values():
            for a, ka in kids:
                if ka is None and a.is_Symbol:
                    out.add(str(a))
        return out
