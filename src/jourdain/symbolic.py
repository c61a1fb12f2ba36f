"""Immutable symbolic matrices: SymEngine inside, SymPy (LaTeX in Jupyter) on request.

Expressions from the recursive kinematics share sub-expressions (a DAG); converting them to SymPy
or counting their operations must visit each shared node once, which :func:`to_sympy` and
:func:`count_ops` do.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import symengine as se

Expr = se.Basic


@dataclass(frozen=True)
class SymMatrix:
    """An immutable matrix of SymEngine expressions (vectors are n×1).

    ``M.sympy()`` gives a :class:`sympy.Matrix`; ``M.symengine()`` a SymEngine DenseMatrix;
    ``M[i, j]`` an entry; Jupyter shows it as LaTeX.
    """

    rows: tuple[tuple[Expr, ...], ...]

    @classmethod
    def from_rows(cls, rows: Iterable[Iterable[Expr]]) -> SymMatrix:
        return cls(tuple(tuple(r) for r in rows))

    @classmethod
    def column(cls, entries: Iterable[Expr]) -> SymMatrix:
        return cls(tuple((e,) for e in entries))

    @classmethod
    def symmetric_from_terms(cls, terms: Sequence[Sequence[Sequence[Expr]]]) -> SymMatrix:
        """An exactly symmetric n×n matrix whose entry (i, j), i ≤ j, is the sum of
        ``terms[i][j]`` (the lower triangle of ``terms`` is not read)."""
        n = len(terms)
        zero = se.Integer(0)
        rows = [[zero] * n for _ in range(n)]
        for i in range(n):
            for j in range(i, n):
                e = se.Add(*terms[i][j]) if terms[i][j] else zero
                rows[i][j] = rows[j][i] = e
        return cls.from_rows(rows)

    @classmethod
    def zeros(cls, n: int, m: int) -> SymMatrix:
        z = se.Integer(0)
        return cls(tuple((z,) * m for _ in range(n)))

    @property
    def shape(self) -> tuple[int, int]:
        return (len(self.rows), len(self.rows[0]) if self.rows else 0)

    def __getitem__(self, idx: Any) -> Expr:
        if isinstance(idx, tuple):
            i, j = idx
            return self.rows[i][j]
        if self.shape[1] == 1:
            return self.rows[idx][0]
        return self.rows[idx]

    def __len__(self) -> int:
        return len(self.rows)

    @property
    def T(self) -> SymMatrix:
        return SymMatrix(tuple(zip(*self.rows, strict=True))) if self.rows else self

    def entries(self) -> list[Expr]:
        """All entries, row by row."""
        return [e for r in self.rows for e in r]

    def symengine(self) -> se.DenseMatrix:
        n, m = self.shape
        return se.DenseMatrix(n, m, self.entries())

    def sympy(self) -> Any:
        """The matrix as a :class:`sympy.Matrix` (shared sub-expressions converted once)."""
        import sympy

        n, m = self.shape
        return sympy.Matrix(n, m, to_sympy_many(self.entries()))

    def subs(self, mapping: dict) -> SymMatrix:
        return SymMatrix(tuple(tuple(e.subs(mapping) for e in r) for r in self.rows))

    @property
    def free_symbols(self) -> set:
        out: set = set()
        for e in self.entries():
            out |= e.free_symbols
        return out

    def count_ops(self, cse: bool = True) -> int:
        """Number of operations (additions, multiplications, function calls, powers), after
        common-subexpression elimination when ``cse``."""
        return count_ops(self.entries(), cse=cse)

    def _repr_latex_(self) -> str:
        import sympy

        return "$\\displaystyle " + sympy.latex(self.sympy()) + "$"

    def __repr__(self) -> str:
        n, m = self.shape
        if n * m <= 16:
            return f"SymMatrix({[list(r) for r in self.rows]})"
        return f"SymMatrix(<{n}x{m}>)"


_SYMPY_FUNCS = {
    "Add": "Add", "Mul": "Mul", "Pow": "Pow", "sin": "sin", "cos": "cos", "tan": "tan",
    "cot": "cot", "asin": "asin", "acos": "acos", "atan": "atan", "atan2": "atan2",
    "exp": "exp", "log": "log", "Abs": "Abs", "sign": "sign", "sinh": "sinh", "cosh": "cosh",
    "tanh": "tanh", "Max": "Max", "Min": "Min", "sec": "sec", "csc": "csc",
}


def to_sympy(expr: Expr, memo: dict | None = None) -> Any:
    """Convert a SymEngine expression to SymPy, visiting shared sub-expressions once.

    ``memo`` is accepted for compatibility and not used: node identities are only valid within
    one graph, so convert many expressions together with :func:`to_sympy_many`.
    """
    del memo
    return to_sympy_many([expr])[0]


def to_sympy_many(exprs: Sequence[Expr]) -> list[Any]:
    """Convert SymEngine expressions to SymPy; nodes shared between them are converted once.

    One :class:`jourdain.cse.Graph` over all of them: node ids are only meaningful within one
    graph, which keeps every node it has seen alive.
    """
    import sympy

    from .cse import Graph

    g = Graph(list(exprs))
    memo: dict[int, Any] = {}
    for i in g.order:
        node = g.node[i]
        args = [a._sympy_() if ia is None else memo[ia]
                for a, ia in zip(g.args[i], g.arg_ids[i], strict=True)]
        name = type(node).__name__
        if name in _SYMPY_FUNCS:
            memo[i] = getattr(sympy, _SYMPY_FUNCS[name])(*args)
        else:
            memo[i] = node._sympy_()
    return [e._sympy_() if r is None else memo[r] for e, r in zip(exprs, g.root_ids, strict=True)]


def count_ops(exprs: Sequence[Expr], cse: bool = True) -> int:
    """Operation count of a list of expressions (n-ary + and * count n-1, functions and powers
    one), after common-subexpression elimination (:mod:`jourdain.cse`) when ``cse``, else
    counting each distinct node of the shared graph once."""
    from .cse import cse as graph_cse
    from .cse import graph_ops

    exprs = list(exprs)
    return graph_cse(exprs).count_ops() if cse else graph_ops(exprs)
