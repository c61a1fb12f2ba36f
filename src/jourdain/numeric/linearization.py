"""The linearization in numbers (``docs/method.md`` §5–6): the symbolic results of
:mod:`jourdain.stages.linearization` evaluated at checked parameter values and times, or
compiled.

Floor: numeric. The stage below returns pure symbolic dataclasses; this module gives them
numbers, in two forms that agree:

* free functions, for any result of the stage: :func:`evaluate_linearization`,
  :func:`compile_linearization` (:class:`CompiledLinearization`), :func:`check_nominal`,
  :func:`evaluate_general_linearization`;
* subclasses with the same data and these functions as methods — :class:`Linearization`
  (``lin.evaluate(t, parameters)``, ``lin.compile()``, ``lin.check_nominal(t, parameters)``)
  and :class:`GeneralLinearization` (``glin.evaluate(y, yd, ydd, ...)``) — which
  :func:`linearization` and :func:`linearization_general` return, and with them
  ``jourdain.linearization``, ``jourdain.linearization_general`` and
  ``jourdain.System.linearize``. :func:`with_numbers` lifts a result of the stage into them.

Arguments are checked here (parameter names and values: :func:`parameter_vector`; the time:
:func:`time_value`; a state: :func:`state_vectors`) before the stage's expressions are walked
in floating point (:func:`jourdain.stages.linearization.result.evaluate_at`) or compiled
(:func:`lambdify`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from ..errors import EvaluationError, warn
from ..graph import evaluate_float
from ..graph.memo import Memo
from ..graph.piecewise import switches_at
from ..stages.linearization import formation as _formation
from ..stages.linearization import general as _general
from ..stages.linearization import result as _result
from ..stages.linearization.nominal import NominalCheck, NominalMotionWarning, _nominal
from ..stages.projection import EquationsOfMotion
from .compiled import lambdify
from .functions import CompiledFunction
from .state import parameter_vector, state_vectors, time_value


def evaluate_linearization(lin: _result.Linearization, t: float = 0.0,
                           parameters: Mapping[str, float] | None = None
                           ) -> dict[str, np.ndarray]:
    """NumPy arrays of ``M_tilde, P, Q, h, B`` (h 1-D) at time ``t``, and of ``D, G, K, N``
    for a time-invariant result (for a time-variant one these keys are left out).

    ``parameters`` overrides default parameter values by name (an unknown name, a value that
    is not a finite number or that makes the model unphysical: :class:`EvaluationError`). One
    evaluation walks the expression graph once in floating point (no compilation); for many
    evaluations use :func:`compile_linearization`.
    """
    p = parameter_vector(lin.system, parameters)
    return _result.evaluate_at(lin, _result.values_at(lin, time_value(t), p))


def check_nominal(lin: _result.Linearization, t: float = 0.0,
                  parameters: Mapping[str, float] | None = None) -> NominalCheck:
    """``h`` at time ``t`` against the forces at work at the nominal state
    (:class:`NominalCheck`; ``check.is_solution``, ``check.message()``)."""
    p = parameter_vector(lin.system, parameters)
    return _result.check_nominal_at(lin, _result.values_at(lin, time_value(t), p))


@dataclass(frozen=True)
class CompiledLinearization:
    """Compiled ``M_tilde, P, Q, h, B`` of a linearization; call with ``(t, parameters)`` for
    the same dict as :func:`evaluate_linearization`."""

    linearization: _result.Linearization
    function: CompiledFunction

    def __call__(self, t: float = 0.0,
                 parameters: Mapping[str, float] | None = None) -> dict[str, np.ndarray]:
        lin = self.linearization
        system = lin.system
        p = parameter_vector(system, parameters)
        f = system.f
        if lin.switches:  # a piecewise function exactly at its switching point: refused
            switches_at(lin.switches, _result.values_at(lin, time_value(t), p), evaluate_float)
        out = self.function(np.zeros(f), np.zeros(f), time_value(t), p,
                            np.zeros(len(system.inputs)))
        return _result.finish(self.linearization, dict(out))


def compile_linearization(lin: _result.Linearization) -> CompiledLinearization:
    """Machine code for ``M_tilde, P, Q, h, B`` as functions of t and the parameters
    (:func:`jourdain.numeric.lambdify`), for repeated evaluation (sweeps, time-variant
    systems), with :func:`monodromy_accel_source` for the Floquet analysis."""
    blocks = lin.blocks()
    return CompiledLinearization(lin, lambdify(lin.system, blocks,
                                               extra_source=monodromy_accel_source(blocks)))


def monodromy_accel_source(blocks: Mapping[str, Any]) -> str:
    """C of ``jd_monodromy_accel``: Φ̇ = A(t)·Φ (:mod:`jourdain.analysis.floquet`) as a
    problem of the compiled integrator, whose state is ``[y, ẏ, W]`` with ``ÿ`` from an
    ``accel`` function. The 2f columns of Φ = [H; Ḣ] are the "coordinates" ``y`` = H (f×2f,
    column after column) and ``ẏ`` = Ḣ; ``ÿ = −M̃⁻¹·(Q·H + P·Ḣ)`` with one Cholesky factor of
    ½(M̃ + M̃ᵀ) per evaluation for all columns (``jd_fn`` gives M̃, P, Q at t; its y and ẏ are
    not read: the matrices are those at the nominal motion). Returns 1 where M̃ is not positive
    definite, 2 where a number is not finite (the integrator's codes)."""
    names = list(blocks)
    offsets, at = {}, 0
    for n in names:
        rows, cols = blocks[n].shape
        offsets[n] = at
        at += rows * cols
    f = blocks["M_tilde"].shape[0]
    # scratch on the stack up to 32 kB, else on the heap
    heap = 8 * (at + f * f + f) > 32768
    decl = ("double *out = malloc(sizeof(double) * (JD_MO_SIZE + F * F + F));\n"
            "    if (!out) return 2;\n    double *L = out + JD_MO_SIZE, *z = L + F * F;\n"
            if heap else
            "double out[JD_MO_SIZE], L[F * F], z[F];\n")
    free = "free(out); " if heap else ""
    return f"""
/* the monodromy matrix's columns for the integrator (numeric/linearization.py) */
#define JD_MO_SIZE {at}
int jd_monodromy_accel(const double *y, const double *yd, double t, const double *p,
                       const double *u, double *ydd, double *power) {{
    enum {{ F = {f}, N = 2 * {f} }};
    {decl}    for (int i = 0; i < F; ++i) z[i] = 0.0;
    jd_fn(z, z, t, p, u, out);
    const double *M = out + {offsets["M_tilde"]}, *P = out + {offsets["P"]}, *Q = out + {offsets["Q"]};
    double dmax = 0.0, fin = 0.0;
    for (int i = 0; i < F * F; ++i) fin += (M[i] + P[i] + Q[i]) * 0.0;
    if (fin != 0.0) {{ {free}return 2; }}
    for (int i = 0; i < F; ++i) if (fabs(M[i * F + i]) > dmax) dmax = fabs(M[i * F + i]);
    for (int j = 0; j < F; ++j) {{  /* L·Lᵀ = ½(M̃ + M̃ᵀ); L's diagonal holds 1/l_jj */
        double d = M[j * F + j];
        for (int m = 0; m < j; ++m) d -= L[j * F + m] * L[j * F + m];
        if (!(d > 1e-13 * dmax)) {{ {free}return 1; }}
        double inv = 1.0 / sqrt(d);
        L[j * F + j] = inv;
        for (int i = j + 1; i < F; ++i) {{
            double s = 0.5 * (M[i * F + j] + M[j * F + i]);
            for (int m = 0; m < j; ++m) s -= L[i * F + m] * L[j * F + m];
            L[i * F + j] = s * inv;
        }}
    }}
    for (int c = 0; c < N; ++c) {{
        const double *h = y + c * F, *hd = yd + c * F;
        double *b = ydd + c * F;
        for (int i = 0; i < F; ++i) {{
            double s = 0.0;
            for (int k = 0; k < F; ++k) s -= Q[i * F + k] * h[k] + P[i * F + k] * hd[k];
            b[i] = s;
        }}
        for (int i = 0; i < F; ++i) {{
            double s = b[i];
            for (int k = 0; k < i; ++k) s -= L[i * F + k] * b[k];
            b[i] = s * L[i * F + i];
        }}
        for (int i = F - 1; i >= 0; --i) {{
            double s = b[i];
            for (int k = i + 1; k < F; ++k) s -= L[k * F + i] * b[k];
            b[i] = s * L[i * F + i];
        }}
    }}
    *power = 0.0;
    {free}return 0;
}}
"""


def evaluate_general_linearization(glin: _general.GeneralLinearization, y: Any, yd: Any,
                                   ydd: Any, t: float = 0.0,
                                   parameters: Mapping[str, float] | None = None,
                                   inputs: Mapping[str, float] | None = None
                                   ) -> dict[str, np.ndarray]:
    """Arrays of ``M_tilde, P, Q, h, B`` (h 1-D) of the general form at one state
    ``y, ẏ, ÿ`` (inputs by name where the system has inputs)."""
    system = glin.system
    yv, ydv, tv, pv, uv = state_vectors(system, y, yd, t, parameters, inputs)
    try:
        yddv = np.asarray(ydd, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise EvaluationError(f"ydd must be {system.f} finite numbers, got {ydd!r}") from None
    if yddv.size != system.f or not np.all(np.isfinite(yddv)):
        raise EvaluationError(f"ydd must be {system.f} finite numbers")
    values = {"t": tv}
    for syms, vals in ((system.y, yv), (system.yd, ydv), (system.ydd, yddv),
                       (system.parameter_symbols, pv), (system.inputs, uv)):
        values.update({str(s): float(v) for s, v in zip(syms, vals, strict=True)})
    return _general.evaluate_general_at(glin, values)


class Linearization(_result.Linearization):
    """The result of :func:`jourdain.linearization` (:class:`jourdain.stages.linearization.
    Linearization`: ``M̃·η̈ + P·η̇ + Q·η = h + B·Δu``, METHOD.md §5) with its numbers as
    methods: :meth:`evaluate`, :meth:`compile`, :meth:`check_nominal`."""

    def evaluate(self, t: float = 0.0,
                 parameters: Mapping[str, float] | None = None) -> dict[str, np.ndarray]:
        """NumPy arrays of ``M_tilde, P, Q, h, B`` (h 1-D) at time ``t``, and of ``D, G, K, N``
        for a time-invariant result; ``parameters`` overrides default values by name
        (:func:`evaluate_linearization`). For many evaluations use :meth:`compile`."""
        return evaluate_linearization(self, t, parameters)

    def compile(self) -> CompiledLinearization:
        """Machine code for ``M_tilde, P, Q, h, B`` as functions of t and the parameters
        (:func:`compile_linearization`)."""
        return compile_linearization(self)

    def check_nominal(self, t: float = 0.0,
                      parameters: Mapping[str, float] | None = None) -> NominalCheck:
        """Whether the nominal motion solves the equations of motion at ``t``
        (:func:`check_nominal`)."""
        return check_nominal(self, t, parameters)


class GeneralLinearization(_general.GeneralLinearization):
    """The result of :func:`jourdain.linearization_general` (the general form, functions of
    the state) with :meth:`evaluate`."""

    def evaluate(self, y: Any, yd: Any, ydd: Any, t: float = 0.0,
                 parameters: Mapping[str, float] | None = None,
                 inputs: Mapping[str, float] | None = None) -> dict[str, np.ndarray]:
        """Arrays of ``M_tilde, P, Q, h, B`` at one state
        (:func:`evaluate_general_linearization`)."""
        return evaluate_general_linearization(self, y, yd, ydd, t, parameters, inputs)


def with_numbers(lin: _result.Linearization) -> Linearization:
    """``lin`` (a result of the stage) as a :class:`Linearization` with the numeric methods
    (the same fields; ``lin`` itself where it is one already)."""
    if isinstance(lin, Linearization):
        return lin
    return Linearization(**{f.name: getattr(lin, f.name) for f in fields(lin)})


def linearization(eom: EquationsOfMotion, nominal: Mapping[Any, Any] | Any,
                  inputs: Mapping[Any, Any] | None = None) -> Linearization:
    """Linearize ``M·ÿ + k = q`` about a nominal motion (METHOD.md §5): the stage's
    :func:`jourdain.stages.linearization.linearization` (see it for the arguments, the
    errors and the :class:`NominalMotionWarning`), returned with its numeric methods.

    The result is immutable and depends only on the model and the nominal motion: it is
    formed once for each (:data:`LINEARIZATIONS`, keyed by the model's content and the
    nominal expressions), and a call again returns the same object (and the same warning)."""
    y_s, u_s = _nominal(eom.system, nominal, inputs)
    key = (eom.system, tuple(y_s), tuple(u_s))

    def make() -> tuple[Linearization, str | None]:
        lin = with_numbers(_formation.form(eom, y_s, u_s))
        return lin, _formation.nominal_warning(lin)

    lin, message = LINEARIZATIONS.get(key, make)
    if message is not None:
        warn(message, NominalMotionWarning)
    return lin


#: the linearizations formed, by (model, y_s, u_s): a loop that linearizes per case forms each
#: once (5 ms for a 2-DOF rotor, seconds for large models)
LINEARIZATIONS: Memo[tuple[Linearization, str | None]] = Memo("linearizations", 64)


def linearization_general(eom: EquationsOfMotion) -> GeneralLinearization:
    """M̃, P, Q, h, B as functions of the state (y, ẏ, ÿ, u, t): the stage's
    :func:`jourdain.stages.linearization.linearization_general`, returned with
    :meth:`GeneralLinearization.evaluate`."""
    glin = _general.linearization_general(eom)
    return GeneralLinearization(**{f.name: getattr(glin, f.name) for f in fields(glin)})


__all__ = ["CompiledLinearization", "GeneralLinearization", "Linearization", "check_nominal",
           "compile_linearization", "evaluate_general_linearization", "evaluate_linearization",
           "linearization", "linearization_general", "with_numbers"]
