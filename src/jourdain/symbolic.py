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

        memo: dict = {}
        return sympy.Matrix([[to_sympy(e, memo) for e in r] for r in self.rows])

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
    """Convert a SymEngine expression to SymPy, visiting shared sub-expressions once."""
    import sympy

    # keyed structurally (jourdain.cse.expr_key): == on distinct but equal deep nodes walks the
    # whole tree, and SymEngine's hash alone confuses x + y with -x - y
    from .cse import expr_key

    if memo is None:
        memo = {}
    stack = [expr]
    while stack:
        node = stack[-1]
        h = expr_key(node)
        if h in memo:
            stack.pop()
            continue
        args = node.args
        name = type(node).__name__
        if not args or name not in _SYMPY_FUNCS:
            memo[h] = node._sympy_() if hasattr(node, "_sympy_") else sympy.sympify(str(node))
            stack.pop()
            continue
        pending = [a for a in args if expr_key(a) not in memo]
        if pending:
            stack.extend(pending)
            continue
        f = getattr(sympy, _SYMPY_FUNCS[name])
        memo[h] = f(*(memo[expr_key(a)] for a in args))
        stack.pop()
    return memo[expr_key(expr)]


def count_ops(exprs: Sequence[Expr], cse: bool = True) -> int:
    """Operation count of a list of expressions (n-ary + and * count n-1, functions and powers
    one), after common-subexpression elimination (:mod:`jourdain.cse`) when ``cse``, else
    counting each distinct node of the shared graph once."""
    from .cse import cse as graph_cse
    from .cse import graph_ops

    exprs = list(exprs)
    return graph_cse(exprs).count_ops() if cse else graph_ops(exprs)
