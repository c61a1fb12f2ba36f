"""The node store: the distinct nodes of some SymEngine expressions, children before parents.

The recursive kinematics produces M, k, q as expressions that share sub-expressions (a DAG);
SymEngine walks them as trees. :class:`Graph` reads every distinct node once and keeps

* ``order``: the keys of the non-atomic nodes in post-order (children before parents),
* ``node``/``kind``/``children``: each node, its type name and its children's keys (atoms
  included), and ``atoms``: the symbols and numbers,
* ``roots``: the keys of the given expressions, in order.

Keys are node identities by address (:mod:`jourdain.graph.identity`): cheap, exact, and what the
walks of differentiation and evaluation (:mod:`.forward`, :mod:`.numbers`) need. Common-
subexpression elimination and code generation also need equal sub-expressions *built separately*
to be one node: :meth:`Graph.merged` gives that view (:class:`Merged`), hash-consed over the same
store: a node's class is its type and its children's classes (sorted for the commutative + and
*; atoms by type and exact text), so no expression is ever compared with ``==``.

Floor: model → **graph tools** (this package: imports only :mod:`jourdain.errors`) → stages →
numeric. The stages, the numeric layer and the analyses build on it.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

from . import identity
from .identity import POINTER_OFFSET, Expr, NodeIds, no_gc, read_pointer


class Graph:
    """The distinct nodes of some expressions, identified by address (see the module docstring).

    A graph is built once and may be walked many times (an equilibrium search evaluates the same
    equations at many points); it keeps every node alive, so the addresses stay valid.
    """

    def __init__(self, exprs: Sequence[Expr]) -> None:
        self.kind: dict[int, str] = {}
        self.node: dict[int, Expr] = {}
        self.atoms: dict[int, Expr] = {}
        self.children: dict[int, tuple[int, ...]] = {}
        self.order: list[int] = []
        self._exprs = list(exprs)  # keeps the roots (and so every node) alive
        self._merged: Merged | None = None
        with no_gc():
            self.roots: tuple[int, ...] = self._build(self._exprs)

    def _build(self, exprs: list[Expr]) -> tuple[int, ...]:
        node, atoms, children, order, kind = (self.node, self.atoms, self.children, self.order,
                                              self.kind)
        rd, off = read_pointer, POINTER_OFFSET
        pointers = identity.POINTERS  # read at each build: a test may switch the fallback on
        key: Callable[[Expr], int]
        if pointers:
            def key(e: Expr) -> int:
                return rd(id(e) + off).value  # type: ignore[return-value]  # never NULL
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
                    ka: int = rd(id(a) + off).value if pointers else key(a)  # type: ignore[assignment]
                    keys.append(ka)
                    if ka in node or ka in atoms:
                        continue
                    if a.is_Atom:
                        atoms[ka] = a
                    else:
                        push.append((a, ka, None))
                stack.append((e, k, tuple(keys)))
                stack.extend(push)
        return tuple(roots)

    def symbol_names(self) -> set[str]:
        """Names of the symbols among the atoms."""
        return {str(a) for a in self.atoms.values() if a.is_Symbol}

    def merged(self) -> Merged:
        """The hash-consed view of this graph (built once, on first use)."""
        if self._merged is None:
            with no_gc():
                self._merged = Merged.of(self)
        return self._merged


def atom_key(a: Expr) -> tuple[str, str]:
    """Exact identity of an atom: floats by their exact binary value (str keeps 15 digits)."""
    name = type(a).__name__
    if name == "RealDouble":
        return name, float(a).hex()
    return name, str(a)


@dataclass(frozen=True)
class Merged:
    """Equal sub-expressions of a :class:`Graph` as one node each (hash-consing).

    Class ids count from 0 in post-order. ``order``: the class ids; ``node[i]``: the first node
    of the class; ``args[i]``: its arguments as read once, with ``arg_ids[i]`` their classes
    (None for atoms); ``uses[i]``: references from distinct parent classes and from the roots;
    ``root_ids``: the classes of the given expressions (None for atoms).
    """

    order: list[int]
    node: dict[int, Expr]
    args: dict[int, tuple[Expr, ...]]
    arg_ids: dict[int, tuple[int | None, ...]]
    uses: dict[int, int]
    root_ids: tuple[int | None, ...]

    @classmethod
    def of(cls, g: Graph) -> Merged:
        atoms, store = g.atoms, g.node
        canon: dict[int, int] = {}  # address key -> class id
        by_structure: dict[tuple[object, ...], int] = {}
        order: list[int] = []
        node: dict[int, Expr] = {}
        args: dict[int, tuple[Expr, ...]] = {}
        arg_ids: dict[int, tuple[int | None, ...]] = {}
        uses: dict[int, int] = {}
        for k in g.order:
            e = store[k]
            kids = g.children[k]
            cids = tuple(None if c in atoms else canon[c] for c in kids)
            a = tuple(atoms[c] if c in atoms else store[c] for c in kids)
            parts = [(1, *atom_key(x)) if c is None else (0, c, "")
                     for x, c in zip(a, cids, strict=True)]
            name = g.kind[k]
            if name in ("Add", "Mul"):
                parts.sort()
            # undefined functions q(t), f(x, y) are told apart by their names
            skey = (name, e.get_name() if hasattr(e, "get_name") else "", tuple(parts))
            i = by_structure.get(skey)
            if i is None:
                i = len(order)
                by_structure[skey] = i
                node[i], args[i], arg_ids[i] = e, a, cids
                order.append(i)
                for ci in cids:
                    if ci is not None:
                        uses[ci] = uses.get(ci, 0) + 1
            canon[k] = i
        roots: list[int | None] = []
        for r in g.roots:
            if r in atoms:
                roots.append(None)
                continue
            i = canon[r]
            uses[i] = uses.get(i, 0) + 1
            roots.append(i)
        return cls(order, node, args, arg_ids, uses, tuple(roots))
