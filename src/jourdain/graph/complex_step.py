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

import cmath
import math
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


#: the same functions on Python complex scalars (the one-point path)
_SCALAR: dict[str, Callable[..., Any]] = {
    "sin": cmath.sin, "cos": cmath.cos, "tan": cmath.tan, "exp": cmath.exp, "log": cmath.log,
    "asin": cmath.asin, "acos": cmath.acos, "atan": cmath.atan, "sinh": cmath.sinh,
    "cosh": cmath.cosh, "tanh": cmath.tanh, "Abs": _sabs, "sign": _ssign, "Max": _smax,
    "Min": _smin, "atan2": _satan2,
}

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

    def _scalar_function(self) -> Callable[[Any, list[complex]], list[complex]]:
        """The tape as one Python function of a vector of numbers (Python complex scalars:
        several times faster than NumPy's per operation). Its code is generated here from the
        tape's operations alone (slots, argument indices, the constants by index), never from
        text of a model, and compiled once."""
        fn = getattr(self, "_scalar", None)
        if fn is not None:
            return fn

        def name(r: tuple[str, int]) -> str:
            kind, j = r
            return f"v{j}" if kind == "n" else f"x[{j}]" if kind == "a" else f"c[{j}]"

        lines = ["def tape(x, c):"]
        for k, (op, refs, integer) in enumerate(self.ops):
            a = [name(r) for r in refs]
            if op in ("Add", "Mul"):
                sym = " + " if op == "Add" else " * "
                # long sums in chunks: a deep chain of binary operations in one expression
                # exhausts the compiler's recursion
                for at in range(0, len(a) - 32, 32):
                    lines.append(f"    v{k} = " + sym.join(([f"v{k}"] if at else []) + a[at:at + 32]))
                start = max(0, (len(a) - 1) // 32 * 32) if len(a) > 32 else 0
                rhs = sym.join(([f"v{k}"] if start else []) + a[start:])
            elif op == "Pow" and integer is not None:
                if integer == 0:
                    rhs = "1.0 + 0j"
                else:
                    prod = " * ".join([a[0]] * abs(integer))
                    rhs = prod if integer > 0 else f"1.0 / ({prod})"
            elif op == "Pow":
                rhs = f"{a[0]} ** {a[1]}"
            else:
                rhs = f"_F_{op}({', '.join(a)})"
            lines.append(f"    v{k} = {rhs}")
        lines.append(f"    return [{', '.join(name(r) for r in self.roots)}]")
        scope: dict[str, Any] = {f"_F_{k}": v for k, v in _SCALAR.items()}
        exec(compile("\n".join(lines), "<jourdain complex tape>", "exec"), scope)  # noqa: S102
        fn = scope["tape"]
        self._scalar = fn
        return fn

    def __call__(self, x: Any) -> np.ndarray:
        x = np.asarray(x, dtype=complex)
        if x.ndim == 1:  # one point: Python scalars
            out = self._scalar_function()(x.tolist(), self.constants)
            return np.array(out, dtype=complex)
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
