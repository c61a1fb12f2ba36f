"""Immutable symbolic matrices: SymEngine inside, SymPy (LaTeX in Jupyter) on request.

Expressions from the recursive kinematics share sub-expressions (a DAG); converting them to SymPy
or counting their operations must visit each shared node once, which :func:`to_sympy` and
:func:`count_ops` do.

Display (``repr``, ``_repr_latex_`` in Jupyter, and the text and LaTeX exports of
:mod:`jourdain.io.export`) shows each matrix simplified for reading by :func:`simplified_sympy`:
SymPy's automatic evaluation cancels what SymEngine kept apart (``cos(-phi1 + phi1 + phi2)``,
``-(-a - b)``), every symbol is real (coordinates, rates, parameters, inputs and t are), so
``sqrt((x + 1)**2)`` reads ``|x + 1|``, and small entries go through trigonometric
simplification, all within a time budget. Matrices that need more than
:data:`MAX_DISPLAY_OPS` operations are summarized by their size instead.
"""

from __future__ import annotations

import re
import time
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any, TypeAlias, cast

import symengine as se

from .graph import Graph, graph_ops
from .graph import cse as graph_cse

#: a SymEngine expression (SymEngine has no type information: to the type checker, Any)
Expr: TypeAlias = se.Basic

#: Matrices whose entries need more operations (after CSE) are summarized, not printed.
MAX_DISPLAY_OPS = 600
#: Entries up to this many operations are simplified for display (trigonometric identities);
#: SymPy's trigsimp of one larger entry can take seconds and cannot be interrupted.
SIMPLIFY_OPS = 150
#: Time budget (seconds) for simplifying the entries of one matrix for display.
SIMPLIFY_SECONDS = 3.0
#: Time budget (seconds) of ``repr`` and ``_repr_latex_`` (which may run in a debugger or a
#: notebook at any moment).
REPR_SECONDS = 1.0
#: Matrices with more entries are summarized by ``repr`` without counting their operations.
REPR_MAX_ENTRIES = 400


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

    def _summary(self) -> str | None:
        """``<n×m matrix, k operations after CSE>`` when too large to print, else None."""
        n, m = self.shape
        if n * m > REPR_MAX_ENTRIES:
            return f"{n}×{m} matrix"
        ops = self.count_ops(cse=True)
        return f"{n}×{m} matrix, {ops} operations after CSE" if ops > MAX_DISPLAY_OPS else None

    def _repr_latex_(self) -> str:
        """LaTeX for Jupyter: simplified for reading (:func:`simplified_sympy`, within
        :data:`REPR_SECONDS`), rates ``<name>_d`` with a dot."""
        import sympy

        summary = self._summary()
        if summary is not None:
            text = summary.replace("×", "$\\times$")
            return f"$\\text{{{text}}}$"
        mat = simplified_sympy(self, deadline=time.perf_counter() + REPR_SECONDS)
        names = {s: _latex_name(s.name) for s in mat.free_symbols}
        return "$\\displaystyle " + sympy.latex(mat, symbol_names=names) + "$"

    def __repr__(self) -> str:
        """The entries simplified for reading (:func:`simplified_sympy`, within
        :data:`REPR_SECONDS`); a summary for matrices too large to print."""
        import sympy

        if not self.rows:
            return "SymMatrix([])"
        summary = self._summary()
        if summary is not None:
            return f"SymMatrix(<{summary}; .sympy() gives every entry>)"
        mat = simplified_sympy(self, deadline=time.perf_counter() + REPR_SECONDS)
        rows = ["[" + ", ".join(sympy.sstr(e) for e in mat.row(i)) + "]"
                for i in range(mat.rows)]
        if len(rows) == 1:
            return f"SymMatrix([{rows[0]}])"
        return "SymMatrix([\n" + ",\n".join(rows) + "])"


def _latex_name(name: str) -> str:
    """LaTeX of a symbol name: ``phi1`` → ``\\phi_{1}`` (SymPy's), the rate ``phi1_d`` →
    ``\\dot{\\phi}_{1}``, the acceleration ``phi1_dd`` → ``\\ddot{\\phi}_{1}``."""
    import sympy

    m = re.match(r"^(.+?)_(dd?)$", name)
    if m is None:
        return sympy.latex(sympy.Symbol(name))
    base, dots = m.group(1), "\\dot" if m.group(2) == "d" else "\\ddot"
    parts = re.match(r"^([A-Za-z]+)(\d*)$", base)
    if parts is None:
        return f"{dots}{{{sympy.latex(sympy.Symbol(base))}}}"
    letters = sympy.latex(sympy.Symbol(parts.group(1)))
    return f"{dots}{{{letters}}}" + (f"_{{{parts.group(2)}}}" if parts.group(2) else "")


def simplified_sympy(m: SymMatrix, simplify: bool = True, deadline: float | None = None) -> Any:
    """The matrix as a SymPy ``ImmutableMatrix`` simplified for reading.

    Conversion to SymPy cancels what SymEngine kept apart and distributes numbers over sums;
    every symbol is then taken as real, so ``sqrt(x**2)`` becomes ``|x|``; entries of at most
    :data:`SIMPLIFY_OPS` operations are expanded and trigonometrically simplified, the result
    kept where it is not longer (when ``simplify``). Simplification stops at ``deadline`` (a
    ``time.perf_counter()`` value; default :data:`SIMPLIFY_SECONDS` from now), after which the
    remaining entries are shown as converted; the result is memoized per matrix (a later call
    reuses it, whatever its deadline). For display only: the derivation never uses it.
    """
    key = (m, simplify)
    hit = _SIMPLIFIED.get(key)
    if hit is None:
        if deadline is None:
            deadline = time.perf_counter() + SIMPLIFY_SECONDS
        hit = _simplified(m, simplify, deadline)
        if len(_SIMPLIFIED) >= 64:
            _SIMPLIFIED.pop(next(iter(_SIMPLIFIED)))
        _SIMPLIFIED[key] = hit
    return hit


#: memo of :func:`simplified_sympy` (matrices are immutable and compared by content)
_SIMPLIFIED: dict[tuple[SymMatrix, bool], Any] = {}


def _simplified(m: SymMatrix, simplify: bool, deadline: float) -> Any:
    import sympy

    n, k = m.shape
    entries = to_sympy_many(m.entries())
    symbols = set().union(*(e.free_symbols for e in entries)) if entries else set()
    real = {s: sympy.Symbol(s.name, real=True) for s in symbols}
    back = {v: k for k, v in real.items()}
    out = []
    for e in entries:
        # xreplace rebuilds every node, so SymPy's evaluation sees real symbols: |x| for √x²
        s = e.xreplace(real)
        if simplify and s.free_symbols and time.perf_counter() < deadline:
            ops = sympy.count_ops(s)
            if ops <= SIMPLIFY_OPS:
                short = sympy.trigsimp(sympy.expand(s))
                s = short if sympy.count_ops(short) <= ops else s
        out.append(s.xreplace(back))
    return sympy.ImmutableMatrix(n, k, out)


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

    One merged :class:`jourdain.graph.Graph` over all of them: node ids are only meaningful within one
    graph, which keeps every node it has seen alive.
    """
    import sympy

    g = Graph(list(exprs)).merged()
    memo: dict[int, Any] = {}
    for i in g.order:
        node: Any = g.node[i]  # SymEngine objects (no type information)
        args = [cast(Any, a)._sympy_() if ia is None else memo[ia]
                for a, ia in zip(g.args[i], g.arg_ids[i], strict=True)]
        name = type(node).__name__
        if name in _SYMPY_FUNCS:
            memo[i] = getattr(sympy, _SYMPY_FUNCS[name])(*args)
        else:
            memo[i] = node._sympy_()
    return [e._sympy_() if r is None else memo[r] for e, r in zip(exprs, g.root_ids, strict=True)]


def count_ops(exprs: Sequence[Expr], cse: bool = True) -> int:
    """Operation count of a list of expressions (n-ary + and * count n-1, functions and powers
    one), after common-subexpression elimination (:func:`jourdain.graph.cse`) when ``cse``, else
    counting each distinct node of the shared graph once."""
    exprs = list(exprs)
    return graph_cse(exprs).count_ops() if cse else graph_ops(exprs)
