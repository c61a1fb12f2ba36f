"""Common-subexpression elimination on the merged graph, and operation counts.

Every node of the merged graph (:meth:`jourdain.graph.Graph.merged`) that is used more than once
becomes a temporary; nodes used once stay inline. One pass over the distinct nodes, so the cost
grows linearly with the size of the graph, where a tree-based CSE (SymEngine's or SymPy's
``cse``) effectively expands the graph into trees. The C code generator
(:mod:`jourdain.numeric.ccode`) walks the same merged graph.

Floor: graph tools (imports only this package).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import symengine as se

from .identity import Expr, NodeIds
from .nodes import Graph


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


def _worth_a_temporary(e: Expr) -> bool:
    # -x and 2*x of an atom are not worth a variable of their own
    if type(e).__name__ == "Mul" and len(e.args) == 2 and any(a.is_Number for a in e.args):
        return not all(_is_atom(a) for a in e.args)
    return True


def cse(exprs: Sequence[Expr], prefix: str = "x") -> CSE:
    """Graph CSE: every non-atomic node used more than once becomes a temporary."""
    exprs = list(exprs)
    g = Graph(exprs).merged()
    roots = {r for r in g.root_ids if r is not None}
    rebuilt: dict[int, Expr] = {}
    temps: list[tuple[se.Symbol, Expr]] = []
    for i in g.order:
        node = g.node[i]
        new_args = [a if ia is None else rebuilt[ia]
                    for a, ia in zip(g.args[i], g.arg_ids[i], strict=True)]
        changed = any(n is not a for n, a in zip(new_args, g.args[i], strict=True))
        new = node.func(*new_args) if changed else node
        if g.uses[i] > 1 and i not in roots and _worth_a_temporary(node):
            sym = se.Symbol(f"{prefix}{len(temps)}")
            temps.append((sym, new))
            rebuilt[i] = sym
        else:
            rebuilt[i] = new
    outputs = tuple(e if r is None else rebuilt[r] for e, r in zip(exprs, g.root_ids, strict=True))
    return CSE(tuple(temps), outputs)


def count_nodes(exprs: Sequence[Expr], cap: int) -> int:
    """Number of distinct non-atomic nodes of the expressions' graph (by identity), counted up
    to ``cap + 1``: a cheap test of whether a graph is small, whatever its full size."""
    return count_graph(exprs, cap)[0]


def count_graph(exprs: Sequence[Expr], cap: int) -> tuple[int, int]:
    """:func:`count_nodes`, and among those nodes the function calls whose argument is not a
    bare symbol (``sin(q0 + q1)``: a call of the C library each; the sines and cosines of
    argument symbols are computed together, vectorized, :mod:`jourdain.numeric.ccode`)."""
    ids = NodeIds()
    seen: set[int] = set()
    calls = 0
    stack = [e for e in exprs if not _is_atom(e)]
    while stack and len(seen) <= cap:
        e = stack.pop()
        k = ids(e)
        if k in seen:
            continue
        seen.add(k)
        if isinstance(e, se.Function) and not all(isinstance(a, se.Symbol) for a in e.args):
            calls += 1
        stack.extend(a for a in e.args if not _is_atom(a))
    return len(seen), calls


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
    """Operations of some expressions counting each distinct node of their merged graph once."""
    g = Graph(list(exprs)).merged()
    return sum(node_ops(g.node[i]) for i in g.order)
