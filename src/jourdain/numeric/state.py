"""States as argument vectors (checked and located), parameter vectors, and :func:`evaluate`:
the numbers of the Newton–Euler equations and the equations of motion at one state.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import EvaluationError, ModelError
from ..graph.memo import Memo
from ..model.bodies import check_values
from .diagnose import nonfinite_message

if TYPE_CHECKING:
    from ..model.system import System

from .compiled import _eom_function


def state_vectors(system: System, y: Any, yd: Any, t: float,
                  parameters: Mapping[str, float] | None,
                  inputs: Mapping[str, float] | Sequence[float] | None
                  ) -> tuple[np.ndarray, np.ndarray, float, np.ndarray, np.ndarray]:
    """Check and convert a state to the argument vectors of compiled functions."""
    f = system.f
    yv = _vector(y, f, "y", system.coordinate_names)
    ydv = _vector(yd, f, "yd", [f"{n}_d" for n in system.coordinate_names])
    tv = time_value(t)
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


def time_value(t: Any) -> float:
    """``t`` as a finite float (EvaluationError otherwise)."""
    try:
        tv = float(t)
    except (TypeError, ValueError):
        raise EvaluationError(f"t must be a number, got {t!r}") from None
    if not math.isfinite(tv):
        raise EvaluationError(f"t = {t!r} is not finite")
    return tv


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
        # the model's numbers must stay physical at the new values, as at the defaults (a
        # negative mass would give a negative definite M without a word); checked once per
        # model and values (one jd.stability call asks five times), and only where a value
        # that the bodies' data use was given (the defaults passed when the model was made)
        problem = None
        if not CHECKED_NAMES.get(system, lambda: _checked_names(system)).isdisjoint(parameters):
            problem = CHECKS.get((system, tuple(values.items())),
                                 lambda: _problem(system, values))
        if problem is not None:
            given = ", ".join(f"{k}={v}" for k, v in parameters.items())
            raise EvaluationError(f"with the parameters {given}: {problem}") from None
    return np.array(list(values.values()), dtype=float)


#: what is wrong with a model's numbers at parameter values (None: nothing), by the model
#: (its content; its hash is computed once) and the values by name
CHECKS: Memo[str | None] = Memo("parameter checks", 256)


#: the parameters that the checks of a model's numbers read (bodies' mass data, joints' frames
#: and axes), by the model
CHECKED_NAMES: Memo[frozenset[str]] = Memo("checked parameters", 256)


def _checked_names(system: System) -> frozenset[str]:
    names: set[str] = set()
    for b in system.bodies:
        j = b.joint
        exprs = [b.mass, *b.com, *(x for row in b.inertia for x in row), *j.position,
                 *(x for row in j.orientation for x in row),
                 *(c for s in j.steps if s.axis is not None for c in s.axis)]
        names.update(str(s) for e in exprs for s in e.free_symbols)
    return frozenset(names)


def _problem(system: System, values: Mapping[str, float]) -> str | None:
    try:
        check_values(system.bodies, values)
    except ModelError as exc:
        return str(exc)
    return None


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
    """``M_bar, J_bar, q_c, q_e, M, k, q`` (and ``Q_bar`` where the joints give it) as NumPy
    arrays at one state (vectors 1-D).

    Raises :class:`EvaluationError` when any of them holds NaN or inf, naming the quantities,
    the state and the joint, body or force element at fault (:mod:`.diagnose`).
    """
    args = state_vectors(system, y, yd, t, parameters, inputs)
    out = _eom_function(system)(*args)
    bad = [k for k, v in out.items() if not np.all(np.isfinite(v))]
    if bad:
        raise EvaluationError(nonfinite_message(system, bad, *args))
    # vectors (q_c, q_e, k, q) come back 1-D, matrices keep their shape even when 1x1
    return {k: (v.reshape(-1) if k in _VECTORS else v) for k, v in out.items()}


_VECTORS = frozenset({"q_c", "q_e", "k", "q"})

