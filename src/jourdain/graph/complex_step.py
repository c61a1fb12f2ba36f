"""Expressions evaluated in complex arithmetic for the complex step, ``∂F/∂x_j = Im F(x +
iη·e_j)/η`` (the linearization and the derivatives of closed systems,
:mod:`jourdain.loops.general`).

The complex step is exact only where every operation is the analytic extension of its real
counterpart *to first order in the imaginary part*. SymEngine's complex ``Lambdify`` is not:
it raises to integer powers through the complex logarithm, so ``(-0.7)**2`` comes out as
``0.49 - 1.2e-16i``, and ``1/x`` of a negative ``x`` likewise; divided by η = 1e-60 that
rounding becomes a derivative of 1e44. :class:`ComplexTape` reads the merged graph of the
expressions once and evaluates it as one Python function of complex scalars (integer powers
by repeated multiplication, exact), with the non-analytic functions given their complex-step
meaning on the branch of the real part: ``|z| = ±z``, ``sign(z) = sign(Re z)``,
``max``/``min`` by the real parts, ``atan2`` to first order.

Floor: graph tools (imports only this package and :mod:`jourdain.errors`).
"""

from __future__ import annotations

import cmath
import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import symengine as se

from ..errors import EvaluationError
from .identity import Expr
from .nodes import Graph


def _sabs(z: complex) -> complex:
    return z if z.real >= 0 else -z


def _ssign(z: complex) -> complex:
    return complex((z.real > 0) - (z.real < 0))


def _smax(*a: complex) -> complex:
    r = a[0]
    for x in a[1:]:
        if x.real > r.real:
            r = x
    return r


def _smin(*a: complex) -> complex:
    r = a[0]
    for x in a[1:]:
        if x.real < r.real:
            r = x
    return r


def _satan2(y: complex, x: complex) -> complex:
    yr, xr = y.real, x.real
    return complex(math.atan2(yr, xr), (xr * y.imag - yr * x.imag) / (xr * xr + yr * yr))


#: the functions on Python complex scalars
_SCALAR: dict[str, Callable[..., Any]] = {
    "sin": cmath.sin, "cos": cmath.cos, "tan": cmath.tan, "exp": cmath.exp, "log": cmath.log,
    "asin": cmath.asin, "acos": cmath.acos, "atan": cmath.atan, "sinh": cmath.sinh,
    "cosh": cmath.cosh, "tanh": cmath.tanh, "Abs": _sabs, "sign": _ssign, "Max": _smax,
    "Min": _smin, "atan2": _satan2,
}

class ComplexTape:
    """The expressions ``exprs`` as a function of ``args`` (symbols) in complex arithmetic:
    ``tape(x)`` with ``x`` of ``len(args)`` numbers gives the ``len(exprs)`` values.

    The graph's operations become one Python function, generated here from the operations
    alone (slots, argument indices, constants by index), never from text of a model, and
    compiled once: Python complex scalars are several times faster than NumPy's per
    operation."""

    def __init__(self, args: Sequence[se.Symbol], exprs: Sequence[Expr]) -> None:
        exprs = list(exprs)
        index = {str(a): i for i, a in enumerate(args)}
        m = Graph(exprs).merged()
        self.n_args = len(args)
        self.n_out = len(exprs)
        slots: dict[int, int] = {}
        ops: list[tuple[Any, ...]] = []
        constants: list[complex] = []

        def ref(a: Expr, ia: int | None) -> tuple[str, int]:
            if ia is not None:
                return ("n", slots[ia])
            if isinstance(a, se.Symbol):
                if str(a) not in index:
                    raise EvaluationError(f"no value for the symbol {a}")
                return ("a", index[str(a)])
            try:
                constants.append(complex(a))
            except (TypeError, RuntimeError):
                raise EvaluationError(f"the constant {a} has no numeric value") from None
            return ("c", len(constants) - 1)

        for i in m.order:
            node = m.node[i]
            name = type(node).__name__
            refs = [ref(a, ia) for a, ia in zip(m.args[i], m.arg_ids[i], strict=True)]
            if name == "Pow":
                e = m.args[i][1]
                integer = int(e) if isinstance(e, se.Integer) and abs(int(e)) <= 64 else None
                ops.append(("Pow", refs, integer))
            elif name in ("Add", "Mul"):
                ops.append((name, refs, None))
            elif name in _SCALAR:
                ops.append((name, refs, None))
            else:
                raise EvaluationError(f"the function {name} ({node}) has no complex-step "
                                      "evaluation in jourdain")
            slots[i] = len(ops) - 1
        root_refs = [ref(e, r) for e, r in zip(exprs, m.root_ids, strict=True)]

        def text(r: tuple[str, int]) -> str:
            kind, j = r
            return f"v{j}" if kind == "n" else f"x[{j}]" if kind == "a" else f"c[{j}]"

        lines = ["def tape(x, c):"]
        for k, (op, refs, integer) in enumerate(ops):
            a = [text(r) for r in refs]
            if op in ("Add", "Mul"):
                # in chunks of 32 terms: a long chain of binary operations in one expression
                # exhausts the compiler's recursion
                sym = " + " if op == "Add" else " * "
                lines.append(f"    v{k} = " + sym.join(a[:32]))
                lines.extend(f"    v{k} = " + sym.join([f"v{k}", *a[at:at + 32]])
                             for at in range(32, len(a), 32))
                continue
            if op == "Pow" and integer == 0:
                rhs = "1.0 + 0j"
            elif op == "Pow" and integer is not None:
                prod = " * ".join([a[0]] * abs(integer))
                rhs = prod if integer > 0 else f"1.0 / ({prod})"
            elif op == "Pow":
                rhs = f"{a[0]} ** {a[1]}"
            else:
                rhs = f"_F_{op}({', '.join(a)})"
            lines.append(f"    v{k} = {rhs}")
        lines.append(f"    return [{', '.join(text(r) for r in root_refs)}]")
        scope: dict[str, Any] = {f"_F_{k}": v for k, v in _SCALAR.items()}
        exec(compile("\n".join(lines), "<jourdain complex tape>", "exec"), scope)  # noqa: S102
        self._fn: Callable[[list[complex], list[complex]], list[complex]] = scope["tape"]
        self.constants = constants

    def __call__(self, x: Any) -> np.ndarray:
        x = np.asarray(x, dtype=complex)
        if x.ndim != 1 or x.size != self.n_args:
            raise EvaluationError(f"the complex tape takes {self.n_args} numbers, got an "
                                  f"array of shape {x.shape}")
        return np.array(self._fn(x.tolist(), self.constants), dtype=complex)


__all__ = ["ComplexTape"]
