"""Common-subexpression elimination on shared expression graphs.

The recursive kinematics produces expressions that share sub-expressions (a DAG). Every node that
is used more than once becomes a temporary; nodes used once stay inline. One pass over the
distinct nodes, so the cost grows linearly with the size of the graph, where a tree-based CSE
(SymEngine's or SymPy's ``cse``) effectively expands the graph into trees.

Nodes are identified by :func:`expr_key`, a structural fingerprint built from SymEngine's cached
hashes over three levels (node, children, grandchildren). ``==`` cannot be used: comparing two
distinct but equal deep nodes walks the whole tree (exponential on a DAG). The hash alone cannot
be used either: SymEngine's hash of a sum ignores the coefficients of its terms, so ``x + y``,
``2*x + 2*y`` and ``-x - y`` share one hash; their children (``2*x``, ``-x``) do not.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import symengine as se

from .errors import JourdainError

Expr = se.Basic


@dataclass(frozen=True)
class CSE:
    """``temporaries``: list of (symbol, expression) in dependency order; ``outputs``: the
    input expressions written in terms of the temporaries."""

    temporaries: tuple[tuple[se.Symbol, Expr], ...]
    outputs: tuple[Expr, ...]

    def count_ops(self) -> int:
        """Operations of the temporaries and the outputs (n-ary + and * count n-1)."""
        return sum(tree_ops(e) for _, e in self.temporaries) + sum(tree_ops(e) for e in self.outputs)


def _is_atom(e: Expr) -> bool:
    return not e.args


def _key2(e: Expr) -> tuple:
    args = e.args
    if not args:
        return (type(e).__name__, hash(e), str(e))
    return (type(e).__name__, hash(e), tuple(sorted(hash(a) for a in args)))


def expr_key(e: Expr) -> tuple:
    """Dictionary key identifying an expression by its structure (see the module docstring)."""
    args = e.args
    if not args:
        return (type(e).__name__, hash(e), str(e))
    return (type(e).__name__, hash(e), tuple(sorted(_key2(a) for a in args)))


class Graph:
    """The distinct non-atomic nodes of some expressions, children before parents."""

    def __init__(self, exprs: Sequence[Expr]) -> None:
        self.uses: dict[tuple, int] = {}
        self.node: dict[tuple, Expr] = {}
        self.children: dict[tuple, tuple[tuple, ...]] = {}
        self.order: list[tuple] = []  # post-order of keys
        for root in exprs:
            if not _is_atom(root):
                self._visit(root)

    def _visit(self, root: Expr) -> None:
        h = expr_key(root)
        self.uses[h] = self.uses.get(h, 0) + 1
        if h in self.node:
            self._confirm(h, root)
            return
        stack: list[tuple[Expr, tuple, bool]] = [(root, h, False)]
        while stack:
            e, h, done = stack.pop()
            if done:
                self.order.append(h)
                continue
            if h in self.node:
                self._confirm(h, e)
                continue
            args = e.args
            hs = tuple(expr_key(a) for a in args)
            self.node[h] = e
            self.children[h] = hs
            stack.append((e, h, True))
            for a, ha in zip(args, hs, strict=True):
                if _is_atom(a):
                    continue
                self.uses[ha] = self.uses.get(ha, 0) + 1
                if ha not in self.node:
                    stack.append((a, ha, False))

    def _confirm(self, h: tuple, e: Expr) -> None:
        known = self.node[h]
        if known is e:
            return
        # equal Add/Mul nodes may list their terms in different orders (hash-map storage)
        if type(known) is not type(e) or sorted(expr_key(a) for a in e.args) != sorted(
            self.children[h]
        ):
            raise JourdainError("structural key collision between two different expressions")


def _worth_a_temporary(e: Expr) -> bool:
    # -x and 2*x of an atom are not worth a variable of their own
    if type(e).__name__ == "Mul" and len(e.args) == 2 and any(a.is_Number for a in e.args):
        return not all(_is_atom(a) for a in e.args)
    return True


def cse(exprs: Sequence[Expr], prefix: str = "x") -> CSE:
    """Graph CSE: every non-atomic node used more than once becomes a temporary."""
    exprs = list(exprs)
    g = Graph(exprs)
    roots = {expr_key(e) for e in exprs}
    rebuilt: dict[tuple, Expr] = {}
    temps: list[tuple[se.Symbol, Expr]] = []
    for h in g.order:
        node = g.node[h]
        args = node.args
        changed = False
        new_args = []
        for a, ha in zip(args, g.children[h], strict=True):
            r = rebuilt.get(ha)
            if r is None or _is_atom(a):
                new_args.append(a)
            else:
                new_args.append(r)
                changed = True
        new = node.func(*new_args) if changed else node
        if g.uses[h] > 1 and h not in roots and _worth_a_temporary(node):
            sym = se.Symbol(f"{prefix}{len(temps)}")
            temps.append((sym, new))
            rebuilt[h] = sym
        else:
            rebuilt[h] = new
    outputs = tuple(e if _is_atom(e) else rebuilt[expr_key(e)] for e in exprs)
    return CSE(tuple(temps), outputs)


def node_ops(n: Expr) -> int:
    """Operations of one node: n-ary + and * count n-1, a function call or power one."""
    a = n.args
    if not a:
        return 0
    if type(n).__name__ in ("Add", "Mul"):
        return len(a) - 1
    return 1


def tree_ops(e: Expr) -> int:
    """Operations of an expression counted as a tree (shared nodes counted at each use)."""
    total = 0
    stack = [e]
    while stack:
        n = stack.pop()
        total += node_ops(n)
        stack.extend(n.args)
    return total


def graph_ops(exprs: Sequence[Expr]) -> int:
    """Operations of some expressions counting each distinct node of their graph once."""
    g = Graph(list(exprs))
    return sum(node_ops(g.node[h]) for h in g.order)
