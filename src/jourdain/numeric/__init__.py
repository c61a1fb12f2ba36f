"""Numeric evaluation of symbolic results.

:func:`lambdify` compiles named symbolic matrices of a system to one machine-code function of
``(y, ẏ, t, parameters, inputs)`` with SymEngine's LLVM backend after common-subexpression
elimination. :func:`evaluate` gives the numbers of the Newton–Euler equations and the equations of
motion at one state. Compiled functions are memoized by the (immutable, content-compared) system;
:func:`clear_cache` empties that memo.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING, Any

import numpy as np
import symengine as se

from ..errors import EvaluationError
from ..symbolic import SymMatrix

if TYPE_CHECKING:
    from ..model.system import System


@dataclass(frozen=True)
class CompiledFunction:
    """Machine code for named matrices of one system.

    Call ``fn(y, yd, t, p, u)`` with NumPy vectors (``p`` in the order of
    ``system.parameter_symbols``, ``u`` in the order of ``system.inputs``); returns a dict of
    arrays with the shapes of the symbolic matrices.
    """

    names: tuple[str, ...]
    shapes: tuple[tuple[int, int], ...]
    args: tuple[se.Symbol, ...]
    _fn: Any

    def __call__(self, y: np.ndarray, yd: np.ndarray, t: float, p: np.ndarray,
                 u: np.ndarray) -> dict[str, np.ndarray]:
        x = np.concatenate([np.asarray(y, float), np.asarray(yd, float), [float(t)],
                            np.asarray(p, float), np.asarray(u, float)])
        out = self._fn(x)
        if len(self.names) == 1:
            out = [out]
        return {n: np.asarray(o, dtype=float).reshape(s)
                for n, o, s in zip(self.names, out, self.shapes, strict=True)}


def arguments(system: System) -> tuple[se.Symbol, ...]:
    """The argument symbols, in order: y, ẏ, t, parameters, inputs."""
    return (*system.y, *system.yd, system.t, *system.parameter_symbols, *system.inputs)


def lambdify(system: System, matrices: Mapping[str, SymMatrix]) -> CompiledFunction:
    """Compile the named matrices of ``system`` to machine code (LLVM, with CSE)."""
    args = arguments(system)
    names = tuple(matrices)
    shapes = tuple(matrices[n].shape for n in names)
    exprs = [matrices[n].symengine() for n in names]
    try:
        fn = se.Lambdify(list(args), *exprs, backend="llvm", cse=True, real=True)
    except (RuntimeError, ValueError):  # LLVM unavailable in this SymEngine build
        fn = se.Lambdify(list(args), *exprs, backend="lambda", cse=True, real=True)
    return CompiledFunction(names, shapes, args, fn)


@lru_cache(maxsize=32)
def _eom_function(system: System) -> CompiledFunction:
    eom = system.equations_of_motion()
    ne = eom.newton_euler
    return lambdify(system, {"M_bar": ne.M_bar, "J_bar": ne.J_bar, "q_c": ne.q_c,
                             "q_e": ne.q_e, "M": eom.M, "k": eom.k, "q": eom.q})


def clear_cache() -> None:
    """Forget the compiled functions memoized by :func:`evaluate`."""
    _eom_function.cache_clear()


def state_vectors(system: System, y: Any, yd: Any, t: float,
                  parameters: Mapping[str, float] | None,
                  inputs: Mapping[str, float] | Sequence[float] | None
                  ) -> tuple[np.ndarray, np.ndarray, float, np.ndarray, np.ndarray]:
    """Check and convert a state to the argument vectors of compiled functions."""
    f = system.f
    yv = _vector(y, f, "y", system.coordinate_names)
    ydv = _vector(yd, f, "yd", [f"{n}_d" for n in system.coordinate_names])
    try:
        tv = float(t)
    except (TypeError, ValueError):
        raise EvaluationError(f"t must be a number, got {t!r}") from None
    if not math.isfinite(tv):
        raise EvaluationError(f"t = {t!r} is not finite")
    pv = parameter_vector(system, parameters)
    names = system.input_names
    if inputs is None:
        if names:
            raise EvaluationError(f"inputs {names} must be given")
        uv = np.zeros(0)
    elif isinstance(inputs, Mapping):
        unknown = set(inputs) - set(names)
        if unknown:
            raise EvaluationError(f"unknown input(s) {sorted(unknown)}; inputs are {names}")
        missing = [n for n in names if n not in inputs]
        if missing:
            raise EvaluationError(f"input(s) {missing} not given")
        uv = np.array([float(inputs[n]) for n in names])
    else:
        uv = _vector(inputs, len(names), "inputs", names)
    if not np.all(np.isfinite(uv)):
        raise EvaluationError(f"inputs contain NaN or inf: {dict(zip(names, uv, strict=True))}")
    return yv, ydv, tv, pv, uv


def parameter_vector(system: System, parameters: Mapping[str, float] | None) -> np.ndarray:
    """Default parameter values with the overrides in ``parameters`` (by name)."""
    values = system.parameter_values
    if parameters:
        unknown = set(parameters) - set(values)
        if unknown:
            raise EvaluationError(
                f"unknown parameter(s) {sorted(unknown)}; parameters are {sorted(values)}"
            )
        for k, v in parameters.items():
            try:
                fv = float(v)
            except (TypeError, ValueError):
                raise EvaluationError(f'parameter "{k}": expected a number, got {v!r}') from None
            if not math.isfinite(fv):
                raise EvaluationError(f'parameter "{k}" = {v!r} is not finite')
            values[k] = fv
    return np.array(list(values.values()), dtype=float)


def _vector(x: Any, n: int, what: str, names: Sequence[str]) -> np.ndarray:
    try:
        v = np.asarray(x, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise EvaluationError(f"{what} must be a sequence of {n} numbers, got {x!r}") from None
    if v.size != n:
        raise EvaluationError(f"{what} must have {n} entries ({', '.join(names)}), got {v.size}")
    bad = [names[i] for i in range(n) if not math.isfinite(v[i])]
    if bad:
        raise EvaluationError(f"{what} contains NaN or inf in {bad}")
    return v


def evaluate(system: System, y: Any, yd: Any, t: float = 0.0,
             parameters: Mapping[str, float] | None = None,
             inputs: Mapping[str, float] | Sequence[float] | None = None) -> dict[str, np.ndarray]:
    """``M_bar, J_bar, q_c, q_e, M, k, q`` as NumPy arrays at one state (vectors 1-D)."""
    args = state_vectors(system, y, yd, t, parameters, inputs)
    out = _eom_function(system)(*args)
    # vectors (q_c, q_e, k, q) come back 1-D, matrices keep their shape even when 1x1
    return {k: (v.reshape(-1) if k in _VECTORS else v) for k, v in out.items()}


_VECTORS = frozenset({"q_c", "q_e", "k", "q"})
