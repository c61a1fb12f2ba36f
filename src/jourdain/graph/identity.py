"""Identity of SymEngine nodes: which wrappers hold the same node.

Object identity is the address of the C++ object a SymEngine wrapper holds: two wrappers of one
shared node hold the same address. Neither alternative works: ``==`` is exact but walks
distinct-but-equal deep nodes as trees (exponential on a DAG), and SymEngine's hash of a sum
combines its terms by exclusive-or and ignores their coefficients (``x + y``, ``2*x + 2*y`` and
``-x - y`` share one hash; ``cx5 + dx4`` and ``cx5 + dx0 + dx1 + dx2 + dx3 + dx4`` too), so hash
keys would merge different expressions. Where the address cannot be read (another Python
implementation or SymEngine build, detected at import), identity falls back to the hash
confirmed by ``==`` (:class:`NodeIds`): exact, only slower.

An address identifies a node only while the node is alive; every structure of this package keeps
the wrappers it has keyed, and reuses the argument tuples it read (``.args`` of a sum builds fresh
``c*term`` nodes on each call, with new addresses).

Floor: the graph tools (this package) import nothing of jourdain but :mod:`jourdain.errors`.
"""

from __future__ import annotations

import ctypes
import gc
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TypeAlias

import symengine as se

Expr: TypeAlias = se.Basic  # SymEngine has no type information: Any

# A SymEngine wrapper (a Cython object) holds one reference-counted pointer to its C++ node right
# after the Python object header.
POINTER_OFFSET = object.__basicsize__
read_pointer = ctypes.c_void_p.from_address


def pointer(e: Expr) -> int:
    """Address of the C++ node that the wrapper ``e`` holds (valid only when :data:`POINTERS`)."""
    return read_pointer(id(e) + POINTER_OFFSET).value  # type: ignore[return-value]  # never NULL


def _pointers_work() -> bool:
    """Check the wrapper layout on a probe: shared children give equal addresses, others not."""
    try:
        if se.Basic.__basicsize__ != POINTER_OFFSET + ctypes.sizeof(ctypes.c_void_p):
            return False
        a, b = se.Symbol("_probe_a"), se.Symbol("_probe_b")
        e = se.sin(a + b) * (a - b)
        x1, y1 = e.args
        x2, y2 = e.args
        twin = se.sin(a + b) * (a - b)
        return (pointer(x1) == pointer(x2) and pointer(y1) == pointer(y2)
                and pointer(x1) != pointer(y1) and pointer(e) != pointer(twin)
                and pointer(e) != 0)
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
            return pointer(e)
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


@contextmanager
def no_gc() -> Iterator[None]:
    """The cyclic garbage collector paused: the walks allocate hundreds of thousands of small
    objects but no reference cycles, and the collector would otherwise run hundreds of times and
    double the run time."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()
