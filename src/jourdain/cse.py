"""Common-subexpression elimination on shared expression graphs.

The recursive kinematics produces expressions that share sub-expressions (a DAG). Every node that
is used more than once becomes a temporary; nodes used once stay inline. One pass over the
distinct nodes, so the cost grows linearly with the size of the graph, where a tree-based CSE
(SymEngine's or SymPy's ``cse``) effectively expands the graph into trees.

Object identity (:class:`NodeIds`): the address of the C++ object a SymEngine wrapper holds. Two
wrappers of one shared node hold the same address. Neither alternative works: ``==`` is exact but
walks distinct-but-equal deep nodes as trees (exponential on a DAG), and SymEngine's hash of a sum
ignores the coefficients of its terms (``x + y``, ``2*x + 2*y`` and ``-x - y`` share one hash), so
hash keys would merge different expressions. Where the address cannot be read (another Python
implementation or SymEngine build, detected at import), identity falls back to the hash confirmed
by ``==``: exact, only slower.

An address identifies a node only while the node is alive; every structure here keeps the wrappers
it has keyed, and reuses the argument tuples it read (``.args`` of a sum builds fresh ``c*term``
nodes on each call, with new addresses).
"""

from __future__ import annotations

import ctypes
from collections.abc import Sequence
from dataclasses import dataclass

import symengine as se

Expr = se.Basic

# A SymEngine wrapper (a Cython object) holds one reference-counted pointer to its C++ node right
# after the Python object header.
_POINTER_OFFSET = object.__basicsize__
_read_pointer = ctypes.c_void_p.from_address


def _pointer(e: Expr) -> int:
    return _read_pointer(id(e) + _POINTER_OFFSET).value  # type: ignore[return-value]


def _pointers_work() -> bool:
    """Check the wrapper layout on a probe: shared children give equal addresses, others not."""
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
    except Exception:  # noqa: BLE001 - any failure means: do not use addresses
        return False


POINTERS = _pointers_work()


class NodeIds:
    """Integer identities of SymEngine nodes (see the module docstring). Keeps every node it has
    identified alive, so that an address cannot be reused while this object exists."""

    def __init__(self) -> None:
        self._alive: list[Expr] = []
        self._by_hash: dict[int, list[tuple[Expr, int]]] = {}
        self._count = 0

    def __call__(self, e: Expr) -> int:
        self._alive.append(e)
        if POINTERS:
            return _pointer(e)
        # fallback: the hash only picks the bucket, == decides, and the identity is a serial
        # number (never arithmetic on the hash: different nodes could then share a key)
        bucket = self._by_hash.setdefault(hash(e), [])
        for known, key in bucket:
            if known == e:
                return key
        key = self._count
        self._count += 1
        bucket.append((e, key))
        return key


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


class Graph:
    """The distinct non-atomic nodes of some expressions, children before parents.

    Nodes are *hash-consed*: a node's id is given by its type and the ids of its arguments
    (sorted for the commutative + and *; atoms by type and text), so equal sub-expressions built
    separately get one id, without ever comparing expressions with ``==``. Objects are first
    recognised by their address (:class:`NodeIds`) so each shared object is read once.

    ``order``: node ids in post-order; ``node[i]``: the node; ``args[i]``: its arguments as
    read once, with ``arg_ids[i]`` their ids (None for atoms); ``uses[i]``: number of references
    from distinct parents and from the roots; ``root_ids``: the ids of the given expressions (None
    for atoms).
    """

    def __init__(self, exprs: Sequence[Expr]) -> None:
        self.ids = NodeIds()
        self.uses: dict[int, int] = {}
        self.node: dict[int, Expr] = {}
        self.args: dict[int, tuple[Expr, ...]] = {}
        self.arg_ids: dict[int, tuple[int | None, ...]] = {}
        self.order: list[int] = []
        canon: dict[int, int] = {}  # object id -> node id
        by_structure: dict[tuple, int] = {}
        pending: dict[int, tuple[tuple[Expr, ...], tuple[int | None, ...]]] = {}
        roots: list[int | None] = []
        for root in exprs:
            if _is_atom(root):
                roots.append(None)
                continue
            r = self.ids(root)
            stack: list[tuple[Expr, int, bool]] = [(root, r, False)]
            while stack:
                e, p, done = stack.pop()
                if done:
                    args, pids = pending.pop(p)
                    cids = tuple(None if q is None else canon[q] for q in pids)
                    parts = [(1, *_atom_key(a)) if c is None else (0, c, "")
                             for a, c in zip(args, cids, strict=True)]
                    name = type(e).__name__
                    if name in ("Add", "Mul"):
                        parts.sort()
                    # undefined functions q(t), f(x, y) are told apart by their names
                    key = (name, e.get_name() if hasattr(e, "get_name") else "", tuple(parts))
                    c = by_structure.get(key)
                    if c is None:
                        c = len(self.order)
                        by_structure[key] = c
                        self.node[c], self.args[c], self.arg_ids[c] = e, args, cids
                        self.order.append(c)
                        for ci in cids:
                            if ci is not None:
                                self.uses[ci] = self.uses.get(ci, 0) + 1
                    canon[p] = c
                    continue
                if p in canon or p in pending:
                    # in a DAG an object being expanded cannot be reached again below itself
                    continue
                args = e.args
                pids = tuple(None if _is_atom(a) else self.ids(a) for a in args)
                pending[p] = (args, pids)
                stack.append((e, p, True))
                for a, q in zip(args, pids, strict=True):
                    if q is not None and q not in canon and q not in pending:
                        stack.append((a, q, False))
            c = canon[r]
            self.uses[c] = self.uses.get(c, 0) + 1
            roots.append(c)
        self.root_ids: tuple[int | None, ...] = tuple(roots)


def _atom_key(a: Expr) -> tuple[str, str]:
    """Exact identity of an atom: floats by their exact binary value (str keeps 15 digits)."""
    name = type(a).__name__
    if name == "RealDouble":
        return name, float(a).hex()
    return name, str(a)


def _worth_a_temporary(e: Expr) -> bool:
    # -x and 2*x of an atom are not worth a variable of their own
    if type(e).__name__ == "Mul" and len(e.args) == 2 and any(a.is_Number for a in e.args):
        return not all(_is_atom(a) for a in e.args)
    return True


def cse(exprs: Sequence[Expr], prefix: str = "x") -> CSE:
    """Graph CSE: every non-atomic node used more than once becomes a temporary."""
    exprs = list(exprs)
    g = Graph(exprs)
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
    ids = NodeIds()
    seen: set[int] = set()
    stack = [e for e in exprs if not _is_atom(e)]
    while stack and len(seen) <= cap:
        e = stack.pop()
        k = ids(e)
        if k in seen:
            continue
        seen.add(k)
        stack.extend(a for a in e.args if not _is_atom(a))
    return len(seen)


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
    return sum(node_ops(g.node[i]) for i in g.order)
