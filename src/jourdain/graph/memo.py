"""Bounded caches of what does not change between calls (issue 38, item 7: per-call overhead).

A user who loops in Python (``jd.stability(lin, parameters=...)`` per case) pays for every
call what the call rebuilds: the graph of the same expressions, the same model's cyclic
coordinates, the same linearization. These caches keep such results, explicitly and bounded,
keyed by content, never by hidden state in the model's objects:

* :class:`Memo`: a thread-safe LRU map for keys that are hashable values (a model
  :class:`~jourdain.model.System` is an immutable value with equality by content, a tuple of
  parameter values, a nominal motion as expressions);
* :func:`graph_of`: the :class:`~jourdain.graph.Graph` of a sequence of expressions, keyed by
  the identity of the expression objects (held by the entry, so the ids stay theirs; the
  match is confirmed with ``is``: no expression is compared with ``==``, which walks a shared
  DAG as a tree).

Every cache has :meth:`Memo.clear`; :func:`clear_all` empties all of them (tests, a long
session that wants its memory back).

Floor: graph tools (imports only this package).
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Callable, Hashable, Sequence
from typing import Generic, TypeVar

from .identity import Expr
from .nodes import Graph

V = TypeVar("V")

_ALL: list[Memo] = []


class Memo(Generic[V]):
    """A least-recently-used map of at most ``size`` entries, safe to share between threads.

    ``get(key, make)`` returns the entry of ``key``, made by ``make()`` on a miss (outside the
    lock: two threads may both make it; the first one stored wins, so all callers get one
    object). A key that cannot be hashed (a model holding an unhashable value) is no key:
    ``make()`` is called and nothing is kept. ``hits`` and ``misses`` count the look-ups."""

    def __init__(self, name: str, size: int) -> None:
        self.name = name
        self.size = size
        self._data: OrderedDict[Hashable, V] = OrderedDict()
        self._lock = threading.Lock()
        self.hits = 0
        self.misses = 0
        _ALL.append(self)

    def get(self, key: Hashable, make: Callable[[], V]) -> V:
        try:
            hash(key)
        except TypeError:
            return make()
        with self._lock:
            if key in self._data:
                self._data.move_to_end(key)
                self.hits += 1
                return self._data[key]
            self.misses += 1
        value = make()
        with self._lock:
            if key in self._data:  # made meanwhile by another thread
                return self._data[key]
            self._data[key] = value
            while len(self._data) > self.size:
                self._data.popitem(last=False)
        return value

    def __len__(self) -> int:
        return len(self._data)

    def clear(self) -> None:
        with self._lock:
            self._data.clear()
            self.hits = self.misses = 0


class _Exprs:
    """A key of expression objects by identity: hashes the ids, equal only to the same
    objects (``is``), and holds them so that their ids cannot be reused."""

    __slots__ = ("exprs", "_hash")

    def __init__(self, exprs: Sequence[Expr]) -> None:
        self.exprs = tuple(exprs)
        self._hash = hash(tuple(map(id, self.exprs)))

    def __hash__(self) -> int:
        return self._hash

    def __eq__(self, other: object) -> bool:
        return (isinstance(other, _Exprs) and len(other.exprs) == len(self.exprs)
                and all(a is b for a, b in zip(self.exprs, other.exprs, strict=True)))


#: graphs of expressions evaluated again and again (a linearization's matrices, its checks)
GRAPHS: Memo[Graph] = Memo("graphs", 32)


def graph_of(exprs: Sequence[Expr]) -> Graph:
    """The :class:`Graph` of ``exprs``, built once for the same expression objects."""
    exprs = list(exprs)
    return GRAPHS.get(_Exprs(exprs), lambda: Graph(exprs))


def clear_all() -> None:
    """Empty every cache of this module's kind (those made with :class:`Memo`)."""
    for memo in _ALL:
        memo.clear()


__all__ = ["GRAPHS", "Memo", "clear_all", "graph_of"]
