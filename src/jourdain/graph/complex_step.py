"""Expressions evaluated in complex arithmetic for the complex step, ``∂F/∂x_j = Im F(x +
iη·e_j)/η`` (the linearization and the derivatives of closed systems,
:mod:`jourdain.loops.general`).

The complex step is exact only where every operation is the analytic extension of its real
counterpart *to first order in the imaginary part*. SymEngine's complex ``Lambdify`` is not:
it raises to integer powers through the complex logarithm, so ``(-0.7)**2`` comes out as
``0.49 - 1.2e-16i``, and ``1/x`` of a negative ``x`` likewise; divided by η = 1e-60 that
rounding becomes a derivative of 1e44. :class:`ComplexTape` walks the merged graph of the
expressions once per call with NumPy instead (integer powers by repeated multiplication,
exact), and gives the non-analytic functions their complex-step meaning on the branch of the
real part: ``|z| = ±z``, ``sign(z) = sign(Re z)``, ``max``/``min`` by the real parts,
``atan2`` to first order. Each node takes NumPy arrays, so many states (or all steps of a
Jacobian) go through one walk.

Floor: graph tools (imports only this package and :mod:`jourdain.errors`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import symengine as se

from ..errors import EvaluationError
from .identity import Expr
from .nodes import Graph


def _abs(z: Any) -> Any:
    return np.where(np.real(z) >= 0, z, -z)


def _sign(z: Any) -> Any:
    return np.sign(np.real(z)).astype(complex)


def _max(*a: Any) -> Any:
    r = a[0]
    for x in a[1:]:
        r = np.where(np.real(x) > np.real(r), x, r)
    return r


def _min(*a: Any) -> Any:
    r = a[0]
    for x in a[1:]:
        r = np.where(np.real(x) < np.real(r), x, r)
    return r


def _atan2(y: Any, x: Any) -> Any:
    """atan2 to first order in the imaginary parts (what the complex step reads)."""
    yr, xr, yi, xi = np.real(y), np.real(x), np.imag(y), np.imag(x)
    return np.arctan2(yr, xr) + 1j * (xr * yi - yr * xi) / (xr * xr + yr * yr)


_FUNCTIONS: dict[str, Callable[..., Any]] = {
    "sin": np.sin, "cos": np.cos, "tan": np.tan, "exp": np.exp, "log": np.log,
    "asin": np.arcsin, "acos": np.arccos, "atan": np.arctan, "sinh": np.sinh,
    "cosh": np.cosh, "tanh": np.tanh, "Abs": _abs, "sign": _sign, "Max": _max, "Min": _min,
    "atan2": _atan2,
}


def _power(b: Any, e: Any, integer: int | None) -> Any:
    if integer is not None:
        if integer == 0:
            return np.ones_like(b)
        r = b
        for _ in range(abs(integer) - 1):
            r = r * b
        return r if integer > 0 else 1.0 / r
    return np.power(b, e)


class ComplexTape:
    """The expressions ``exprs`` as a function of ``args`` (symbols) in complex arithmetic:
    ``tape(x)`` with ``x`` of shape ``(len(args), ...)`` gives ``(len(exprs), ...)``."""

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
            elif name in _FUNCTIONS:
                ops.append((name, refs, None))
            else:
                raise EvaluationError(f"the function {name} ({node}) has no complex-step "
                                      "evaluation in jourdain")
            slots[i] = len(ops) - 1
        self.ops = ops
        self.constants = constants
        self.roots = [ref(e, r) for e, r in zip(exprs, m.root_ids, strict=True)]

    def __call__(self, x: Any) -> np.ndarray:
        x = np.asarray(x, dtype=complex)
        vals: list[Any] = []
        consts = self.constants

        def get(r: tuple[str, int]) -> Any:
            kind, j = r
            return vals[j] if kind == "n" else x[j] if kind == "a" else consts[j]

        for name, refs, integer in self.ops:
            args = [get(r) for r in refs]
            if name == "Add":
                v = args[0]
                for a in args[1:]:
                    v = v + a
            elif name == "Mul":
                v = args[0]
                for a in args[1:]:
                    v = v * a
            elif name == "Pow":
                v = _power(args[0], args[1], integer)
            else:
                v = _FUNCTIONS[name](*args)
            vals.append(v)
        shape = x.shape[1:]
        return np.array([np.broadcast_to(get(r), shape) for r in self.roots], dtype=complex)


__all__ = ["ComplexTape"]
