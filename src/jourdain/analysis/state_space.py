"""State-space form of a linearized system (METHOD.md §6, "the natural next steps").

With the state ``x = [η; η̇]`` (2f) the linear equations ``M̃·η̈ + P·η̇ + Q·η = h + B·Δu`` read

    ẋ = A·x + B_x·Δu + E·h,   A = [[0, I], [−M̃⁻¹Q, −M̃⁻¹P]],  B_x = [[0], [M̃⁻¹B]],  E = [[0], [M̃⁻¹]]

M̃ is factored numerically (Cholesky), never inverted symbolically.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ..errors import EvaluationError, JourdainError, SingularMassMatrix
from ..extras import MissingDependency as MissingDependency
from ..extras import require
from ..numeric import parameter_vector
from ..numeric.linearization import (
    CompiledLinearization,
    check_nominal,
    evaluate_linearization,
)
from ..stages.linearization import Linearization, NominalCheck, TimeVariantError
from .numeric_linearization import NumericLinearization

#: real parts (and, in tables, imaginary parts) below this fraction of the largest |λ| (at
#: least 1) count as zero: the default ``rtol`` of :func:`jourdain.analysis.stability`, and the
#: tolerance of a zero column of A (a cyclic coordinate)
ZERO_RTOL = 1e-8

AnyLinearization = Linearization | CompiledLinearization | NumericLinearization


@dataclass(frozen=True)
class StateSpace:
    """Numeric state-space form ``ẋ = A·x + B·Δu + E·h`` of a linearization at one time.

    Attributes
    ----------
    A : (2f, 2f) array
        System matrix for the state ``x = [η; η̇]``.
    B : (2f, m) array
        Input matrix for the input deviations ``Δu``.
    E : (2f, f) array
        Input matrix of the generalized excitation h.
    M_tilde, P, Q : (f, f) arrays
        The second-order matrices they came from; ``B_u`` (f, m) and ``h`` (f,) likewise.
    coordinate_names, input_names : tuple of str
    state_names : tuple of str
        ``η`` names then ``η̇`` names (``<coordinate>_d``).
    t : float
        The time at which the matrices were evaluated.
    parameters : dict
        All parameter values used.
    nominal_check : NominalCheck or None
        Whether the nominal motion solves the equations of motion at ``t`` (None where not
        known, e.g. in sweeps); :func:`jourdain.analysis.stability` warns when it does not.
    """

    A: np.ndarray
    B: np.ndarray
    E: np.ndarray
    M_tilde: np.ndarray
    P: np.ndarray
    Q: np.ndarray
    B_u: np.ndarray
    h: np.ndarray
    coordinate_names: tuple[str, ...]
    input_names: tuple[str, ...]
    t: float
    parameters: dict[str, float]
    nominal_check: NominalCheck | None = None

    @property
    def state_names(self) -> tuple[str, ...]:
        return (*self.coordinate_names, *(f"{n}_d" for n in self.coordinate_names))

    @property
    def f(self) -> int:
        return len(self.coordinate_names)

    def to_control(self, outputs: Sequence[str] | None = None, name: str | None = None) -> Any:
        """This system as a named ``control.StateSpace`` (python-control, the extra
        ``jourdain[control]``): A, B, C selecting ``outputs`` among the states (all when None),
        D = 0; see :func:`jourdain.analysis.python_control.to_control`."""
        control = _control()
        C, out_names = output_matrix(self, outputs)
        D = np.zeros((C.shape[0], self.B.shape[1]))
        kw = {} if name is None else {"name": str(name)}
        return control.ss(self.A, self.B, C, D, states=list(self.state_names),
                          inputs=list(self.input_names), outputs=list(out_names), **kw)


def _control() -> Any:
    return require("control", "python-control (to_control, state_feedback)", "control")


def output_matrix(ss: StateSpace, outputs: Sequence[str] | None = None
                  ) -> tuple[np.ndarray, tuple[str, ...]]:
    """``C`` (p, 2f) selecting ``outputs`` among the states ``[η; η̇]`` (all of them, C = I,
    when None), and the output names."""
    names = ss.state_names
    if outputs is None:
        return np.eye(len(names)), tuple(names)
    if isinstance(outputs, str):
        outputs = [outputs]
    chosen = list(outputs)
    unknown = [o for o in chosen if o not in names]
    if unknown:
        raise EvaluationError(f"to_control: unknown output(s) {unknown}; outputs are states: "
                              f"{', '.join(names)}")
    if len(set(chosen)) != len(chosen):
        raise EvaluationError(f"to_control: outputs {chosen} name a state twice")
    C = np.zeros((len(chosen), len(names)))
    for row, o in enumerate(chosen):
        C[row, names.index(o)] = 1.0
    return C, tuple(chosen)


def numbers(lin: AnyLinearization, t: float | None = None,
            parameters: Mapping[str, float] | None = None) -> dict[str, np.ndarray]:
    """``M_tilde, P, Q, h, B`` (and D, G, K, N) as arrays, from a symbolic, compiled or numeric
    result (``t`` defaults to 0, or to the time of a numeric result)."""
    if isinstance(lin, CompiledLinearization):
        return lin(0.0 if t is None else t, parameters)
    if isinstance(lin, Linearization):
        return evaluate_linearization(lin, 0.0 if t is None else t, parameters)
    if isinstance(lin, NumericLinearization):
        return lin.evaluate(t, parameters)
    raise EvaluationError(f"expected a Linearization, CompiledLinearization or "
                          f"NumericLinearization, got {type(lin).__name__}")


def _linearization_of(lin: Any) -> Linearization | NumericLinearization:
    return lin.linearization if isinstance(lin, CompiledLinearization) else lin


#: ``nominal_check`` of :func:`state_space` when not given: computed there
_COMPUTED = object()


def state_space(lin: AnyLinearization, t: float | None = None,
                parameters: Mapping[str, float] | None = None,
                allow_time_variant: bool = False, nominal_check: Any = _COMPUTED
                ) -> StateSpace:
    """State-space matrices of a linearization for numeric parameter values.

    Parameters
    ----------
    lin : Linearization, CompiledLinearization or NumericLinearization
    t : float, optional
        Time at which to evaluate (matters for time-variant results only); 0 by default (a
        numeric result has its own time).
    parameters : mapping name -> value, optional
        Overrides of the default parameter values.
    allow_time_variant : bool
        A time-variant result is refused (its eigenvalues at a frozen time say nothing about
        stability) unless this is True.
    nominal_check : NominalCheck or None, optional
        The check of the nominal motion at these ``t`` and ``parameters`` where the caller has
        it (or None where it wants none); by default it is computed (``lin.check_nominal``,
        most of the time of this function for a symbolic linearization).

    Raises
    ------
    TimeVariantError
        For a time-variant result without ``allow_time_variant``.
    SingularMassMatrix
        When M̃ is not positive definite at these values.
    """
    own = getattr(lin, "state_space", None)
    if callable(own):  # a closed system's linearization: numbers at one state already
        if parameters:
            raise EvaluationError("state_space: a closed system's linearization holds numbers "
                                  "for one set of parameters; pass them to linearize instead")
        return own()
    base = _linearization_of(lin)
    if not base.is_time_invariant and not allow_time_variant:
        raise TimeVariantError(
            f"state_space: the linearization of {base.system.name!r} is time-variant "
            f"({', '.join(base.time_dependence)} depend on t); frozen-time eigenvalues do not "
            "decide stability. Pass allow_time_variant=True to get A(t) at one t anyway."
        )
    num = numbers(lin, t, parameters)
    if isinstance(base, NumericLinearization):
        ss = _from_numbers(base, num, base.t, base.parameters)
        return replace(ss, nominal_check=base.nominal_check)
    ss = _from_numbers(base, num, 0.0 if t is None else float(t), parameters)
    if nominal_check is not _COMPUTED:
        return replace(ss, nominal_check=nominal_check)
    try:
        check = check_nominal(base, ss.t, parameters)
    except JourdainError:  # the matrices have numbers, so this is not expected; no verdict on h
        check = None
    return replace(ss, nominal_check=check)


def _from_numbers(base: Linearization | NumericLinearization, num: Mapping[str, np.ndarray],
                  t: float, parameters: Mapping[str, float] | None) -> StateSpace:

    M, P, Q, Bu, h = num["M_tilde"], num["P"], num["Q"], num["B"], num["h"]
    f = M.shape[0]
    try:
        L = np.linalg.cholesky(0.5 * (M + M.T))
    except np.linalg.LinAlgError:
        ev = np.linalg.eigvalsh(0.5 * (M + M.T))
        raise SingularMassMatrix(
            f"M_tilde of {base.system.name!r} is not positive definite at t = {t} "
            f"(eigenvalues {np.array2string(ev, precision=4)})"
        ) from None

    def solve(X: np.ndarray) -> np.ndarray:
        return np.linalg.solve(L.T, np.linalg.solve(L, X))

    m = Bu.shape[1]
    A = np.zeros((2 * f, 2 * f))
    A[:f, f:] = np.eye(f)
    A[f:, :f] = -solve(Q)
    A[f:, f:] = -solve(P)
    B = np.zeros((2 * f, m))
    if m:
        B[f:] = solve(Bu)
    E = np.zeros((2 * f, f))
    E[f:] = solve(np.eye(f))
    pv = parameter_vector(base.system, parameters)
    pars = {str(s): float(v) for s, v in zip(base.system.parameter_symbols, pv, strict=True)}
    return StateSpace(A=A, B=B, E=E, M_tilde=M, P=P, Q=Q, B_u=Bu, h=np.asarray(h),
                      coordinate_names=tuple(base.system.coordinate_names),
                      input_names=tuple(base.system.input_names), t=t, parameters=pars)
