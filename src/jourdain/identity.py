"""Maps keyed by object identity, for grouping shared sub-expressions exactly and fast.

The recursive kinematics hands the same Python objects (Jacobian columns, frame tags, vectors)
to every body below a joint, so "is this the same column?" is a question of identity. Neither
``==`` (it walks deep expression DAGs as trees) nor SymEngine's hash (``x + y`` and ``-x - y``
share it) can answer it exactly and fast. ``id()`` can, under two rules that
:class:`IdentityMap` enforces:

* a key is the *tuple* of the ids of its objects, never arithmetic on them (a sum of two ids
  names many different pairs, and which pairs collide depends on the memory layout of the
  process: that once gave an indefinite mass matrix at f = 48);
* an id names an object only while the object lives, so the map holds a reference to every
  object it was keyed by, and a look-up confirms the match with ``is``.

Iteration follows insertion order, so results built from these maps do not depend on the
addresses the objects happen to get.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any, Generic, TypeVar

V = TypeVar("V")


class IdentityMap(Generic[V]):
    """A dict keyed by the identity of one object or of a tuple of objects.

    ``m[obj]`` / ``m[(a, b)]``: a key that is a tuple stands for its elements (the tuple object
    itself is not the key), any other key for itself. So a 3-vector of expressions is known by
    its three components, and a pair of vectors is written ``m[(*a, *b)]``.
    """

    __slots__ = ("_items",)

    def __init__(self) -> None:
        self._items: dict[tuple[int, ...], tuple[tuple[Any, ...], V]] = {}

    @staticmethod
    def _objects(key: Any) -> tuple[Any, ...]:
        return key if type(key) is tuple else (key,)

    def _find(self, objs: tuple[Any, ...]) -> tuple[tuple[int, ...], tuple | None]:
        k = tuple(map(id, objs))
        rec = self._items.get(k)
        # the stored objects keep their ids reserved, so a hit is always the same objects;
        # the check guards against misuse with tuples of different lengths only
        if rec is not None and all(a is b for a, b in zip(rec[0], objs, strict=True)):
            return k, rec
        return k, None

    def get(self, key: Any, default: V | None = None) -> V | None:
        _, rec = self._find(self._objects(key))
        return default if rec is None else rec[1]

    def __setitem__(self, key: Any, value: V) -> None:
        objs = self._objects(key)
        self._items[tuple(map(id, objs))] = (objs, value)

    def setdefault(self, key: Any, default: V) -> V:
        objs = self._objects(key)
        k, rec = self._find(objs)
        if rec is not None:
            return rec[1]
        self._items[k] = (objs, default)
        return default

    def get_or_make(self, key: Any, make: Callable[[], V]) -> V:
        """The value of ``key``, made by ``make()`` and stored on first use."""
        objs = self._objects(key)
        k, rec = self._find(objs)
        if rec is not None:
            return rec[1]
        value = make()
        self._items[k] = (objs, value)
        return value

    def values(self) -> Iterator[V]:
        return (v for _, v in self._items.values())
