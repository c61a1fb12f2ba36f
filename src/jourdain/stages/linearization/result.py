"""The symbolic linearization (``docs/method.md`` §5–6): :class:`Linearization` holds M̃, P, Q,
h, B about a nominal motion and, when time-invariant, splits them into damping ``D``,
gyroscopic ``G``, stiffness ``K`` and circulatory ``N`` parts.

Floor: stages. The result is symbolic; :func:`evaluate_at` and :func:`check_nominal_at` walk
its expressions in floating point (:func:`jourdain.graph.evaluate_float`) at values that are
already checked. The public way to numbers — ``lin.evaluate(t, parameters)``,
``lin.compile()``, ``lin.check_nominal(t, parameters)``, which check their arguments and
compile — is on the numeric floor above: :mod:`jourdain.numeric.linearization` (its
``Linearization`` subclass, which :func:`jourdain.linearization` and
``jourdain.System.linearize`` return, and the free functions ``evaluate_linearization``,
``compile_linearization``, ``check_nominal``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import symengine as se

from ...errors import EvaluationError, JourdainError
from ...graph import evaluate_float, free_symbol_names
from ...graph.piecewise import Switch, switches_at
from ...symbolic import SymMatrix

if TYPE_CHECKING:
    from ...model.system import System
    from ..projection import EquationsOfMotion
from .nominal import (
    HALF,
    NOMINAL_RTOL,
    ZERO,
    NominalCheck,
    TimeVariantError,
    _describe,
    _kind,
    _nominal_check,
    _perturbed,
    force_scale,
    term_scale,
)


@dataclass(frozen=True)
class Linearization:
    """Result of :func:`linearization`: ``M̃·η̈ + P·η̇ + Q·η = h + B·Δu`` (METHOD.md §5).

    Attributes
    ----------
    equations_of_motion : EquationsOfMotion
        The stage it came from.
    y_s, yd_s, ydd_s : SymMatrix (f×1)
        The nominal motion, its velocity and acceleration (expressions in ``t`` and the
        parameters).
    u_s : SymMatrix (m×1)
        Nominal inputs (zero unless given).
    M_tilde : SymMatrix (f×f)
        ``M(y_s, t)``, symmetric.
    P : SymMatrix (f×f)
        Velocity matrix ``(∂k/∂ẏ − ∂q/∂ẏ)|_s``.
    Q : SymMatrix (f×f)
        Position matrix ``(∂(M·ÿ_s)/∂y + ∂k/∂y − ∂q/∂y)|_s``.
    h : SymMatrix (f×1)
        Excitation ``(q − k − M·ÿ_s)|_s``: zero when the nominal motion solves the equations of
        motion.
    B : SymMatrix (f×m)
        Input matrix ``∂q/∂u|_s`` for the input deviations ``Δu`` (m = number of inputs).
    time_dependence : tuple of str
        Names of the matrices among M̃, P, Q, B that depend on t (empty for a time-invariant
        result). Where t appears but cancels (a symmetric rotor turning at Ω t), numeric tests
        at several times and parameter values decide, and the matrices are stored at t = 0.
    switches : tuple of (str, expression)
        The piecewise functions of the model (max, min, abs, sign) whose branch at the nominal
        motion depends on the parameters or t: the matrices hold the derivative of the active
        branch, and numbers where an expression is exactly zero (the switching point) are
        refused (:class:`jourdain.graph.piecewise.SwitchingPoint`).
    """

    equations_of_motion: EquationsOfMotion
    y_s: SymMatrix
    yd_s: SymMatrix
    ydd_s: SymMatrix
    u_s: SymMatrix
    M_tilde: SymMatrix
    P: SymMatrix
    Q: SymMatrix
    h: SymMatrix
    B: SymMatrix
    time_dependence: tuple[str, ...]
    switches: tuple[Switch, ...] = ()

    # --- context -----------------------------------------------------------------------------
    @property
    def system(self) -> System:
        return self.equations_of_motion.system

    @property
    def f(self) -> int:
        return self.system.f

    @property
    def nominal(self) -> dict[str, se.Basic]:
        """The nominal motion by coordinate name (and nominal inputs by input name)."""
        out = {n: self.y_s[i] for i, n in enumerate(self.system.coordinate_names)}
        out.update({n: self.u_s[i] for i, n in enumerate(self.system.input_names)})
        return out

    # --- time dependence and the split of §6 ---------------------------------------------------
    @property
    def is_time_invariant(self) -> bool:
        """True when M̃, P, Q and B do not depend on t (h may: a time-dependent excitation)."""
        return not self.time_dependence

    def _require_time_invariant(self, what: str) -> None:
        dep = self.time_dependence
        if dep:
            raise TimeVariantError(
                f"{what}: the linearization about the nominal motion "
                f"{_describe_nominal(self)} is time-variant ({', '.join(dep)} depend on t); the "
                "split into D, G, K, N (METHOD.md §6) holds for time-invariant systems only. "
                "Use M_tilde, P, Q, h as functions of t (evaluate(t=...))."
            )

    @property
    def D(self) -> SymMatrix:
        """Damping matrix ``D = ½(P + Pᵀ)`` (symmetric); time-invariant results only."""
        self._require_time_invariant("D")
        return _sym_part(self.P, +1)

    @property
    def G(self) -> SymMatrix:
        """Gyroscopic matrix ``G = ½(P − Pᵀ)`` (skew-symmetric); time-invariant results only."""
        self._require_time_invariant("G")
        return _sym_part(self.P, -1)

    @property
    def K(self) -> SymMatrix:
        """Stiffness matrix ``K = ½(Q + Qᵀ)`` (symmetric); time-invariant results only."""
        self._require_time_invariant("K")
        return _sym_part(self.Q, +1)

    @property
    def N(self) -> SymMatrix:
        """Circulatory matrix ``N = ½(Q − Qᵀ)`` (skew-symmetric); time-invariant results only."""
        self._require_time_invariant("N")
        return _sym_part(self.Q, -1)

    @property
    def is_conservative(self) -> bool:
        """True when ``D = 0``, ``N = 0`` and ``h = 0`` (METHOD.md §6).

        Entries that are not zero as written are tested numerically (an identity test): at the
        default parameter values and at two random perturbations of them (each value scaled by a
        factor in [0.7, 1.3], zeros replaced by values in [0.2, 1]), and for h at several times.
        It is a property of the symbolic system, for all parameter values; "zero" means below
        1e-9 relative to the size of M̃, P, Q. Time-invariant results only.
        """
        self._require_time_invariant("is_conservative")
        names = ("D", "N", "h")
        exprs = {"D": self.D.entries(), "N": self.N.entries(), "h": self.h.entries()}
        if all(e.is_Number and e == 0 for n in names for e in exprs[n]):
            return True
        rng = np.random.default_rng(20240601)
        base = self.system.parameter_values
        trials = [base] + [_perturbed(base, rng) for _ in range(2)]
        times = (0.0, 0.37, 1.91) if "t" in free_symbol_names(exprs["h"]) else (0.0,)
        for values in trials:
            for t in times:
                num = evaluate_at(self, values_at(self, t, np.array(list(values.values()))))
                scale = max(1.0, np.abs(num["P"]).max(), np.abs(num["Q"]).max(),
                            np.abs(num["M_tilde"]).max())
                for n in names:
                    if np.abs(num[n]).max(initial=0.0) > 1e-9 * scale:
                        return False
        return True

    # --- numbers at checked values (the pure core; the checks and the public methods are on
    #     the numeric floor: jourdain.numeric.linearization) --------------------------------
    def blocks(self) -> dict[str, SymMatrix]:
        """The matrices that have numbers: ``M_tilde, P, Q, h`` and ``B`` where the system has
        inputs (the order of :func:`evaluate_at`'s result)."""
        out = {"M_tilde": self.M_tilde, "P": self.P, "Q": self.Q, "h": self.h}
        if self.system.inputs:
            out["B"] = self.B
        return out

    def __repr__(self) -> str:
        kind = "time-invariant" if self.is_time_invariant else "time-variant"
        return (f"Linearization({self.system.name!r} about {_describe_nominal(self)}: f={self.f}, "
                f"inputs={self.system.input_names}, {kind})")


def values_at(lin: Linearization, t: float, p: np.ndarray) -> dict[str, float]:
    """The values of the parameters (``p``, in the order of the system's parameters) and of
    ``t`` by name, as :func:`evaluate_at` and :func:`check_nominal_at` read them."""
    system = lin.system
    values = {str(s): float(v) for s, v in zip(system.parameter_symbols, p, strict=True)}
    values["t"] = float(t)
    return values


def evaluate_at(lin: Linearization, values: Mapping[str, float]) -> dict[str, np.ndarray]:
    """NumPy arrays of ``M_tilde, P, Q, h, B`` (h 1-D), and of ``D, G, K, N`` for a
    time-invariant result, at ``values`` (every parameter and ``t`` by name, already checked:
    :func:`values_at`). One walk over the expression graph in floating point
    (:func:`jourdain.graph.evaluate_float`); the public form that checks its arguments is
    ``lin.evaluate(t, parameters)`` (:mod:`jourdain.numeric.linearization`)."""
    blocks = lin.blocks()
    flat = [e for m in blocks.values() for e in m.entries()]
    switches_at(lin.switches, values, evaluate_float)
    try:
        nums = evaluate_float(flat, dict(values))
    except EvaluationError:
        raise
    except JourdainError as exc:
        raise EvaluationError(f"linearization of {lin.system.name!r} at t = {values['t']}: "
                              f"{exc}") from None
    out: dict[str, np.ndarray] = {}
    i = 0
    for name, m in blocks.items():
        n, c = m.shape
        out[name] = np.asarray(nums[i:i + n * c], dtype=float).reshape(n, c)
        i += n * c
    return finish(lin, out)


def finish(lin: Linearization, out: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The arrays of :meth:`Linearization.blocks` (by name, 2-D) completed: finite (else an
    :class:`EvaluationError`), ``h`` 1-D, ``B`` (f×0 without inputs) and, for a
    time-invariant result, the split ``D, G, K, N`` of §6."""
    bad = [k for k, v in out.items() if not np.all(np.isfinite(v))]
    if bad:
        raise EvaluationError(f"the linearization has non-finite entries in {bad} at these "
                              "parameter values (a singular position of the nominal motion?)")
    out["h"] = out["h"].reshape(-1)
    if "B" not in out:
        out["B"] = np.zeros((lin.f, 0))
    if lin.is_time_invariant:
        P, Q = out["P"], out["Q"]
        out["D"] = 0.5 * (P + P.T)
        out["G"] = 0.5 * (P - P.T)
        out["K"] = 0.5 * (Q + Q.T)
        out["N"] = 0.5 * (Q - Q.T)
    return out


def check_nominal_at(lin: Linearization, values: Mapping[str, float]) -> NominalCheck:
    """``h`` at ``values`` (every parameter and ``t`` by name, already checked:
    :func:`values_at`) against the forces at work at the nominal state
    (:class:`NominalCheck`); the public form is ``lin.check_nominal(t, parameters)``
    (:mod:`jourdain.numeric.linearization`)."""
    system = lin.system
    f, m = system.f, len(system.inputs)
    values = dict(values)
    tv = values["t"]
    nums = np.array(evaluate_float(
        [*lin.y_s.entries(), *lin.yd_s.entries(), *lin.ydd_s.entries(),
         *lin.u_s.entries(), *lin.h.entries(), *lin.B.entries()], values))
    ys, yds, ydds, us, h = (nums[:f], nums[f:2 * f], nums[2 * f:3 * f],
                            nums[3 * f:3 * f + m], nums[3 * f + m:4 * f + m])
    B = nums[4 * f + m:].reshape(f, m)
    scale = np.zeros(f)
    if np.any(h != 0):
        ne = lin.equations_of_motion.newton_euler
        state = dict(values)
        for syms, vals in ((system.y, ys), (system.yd, yds), (system.inputs, us)):
            state.update({str(s): float(v) for s, v in zip(syms, vals, strict=True)})
        # k = J̄ᵀq̄^c and q = J̄ᵀq̄^e add nothing to the bound (Cauchy–Schwarz); M̄ (36p²
        # entries) only where the nominal motion accelerates
        mats = (ne.J_bar, ne.q_c, ne.q_e, *((ne.M_bar,) if np.any(ydds != 0) else ()))
        flat = np.array(evaluate_float([e for mat in mats for e in mat.entries()], state))
        parts, i = [], 0
        for mat in mats:
            r, c = mat.shape
            parts.append(flat[i:i + r * c].reshape(r, c))
            i += r * c
        zero = np.zeros(f)
        scale = force_scale(parts[0], parts[1][:, 0], parts[2][:, 0], zero, zero,
                            parts[3] if len(parts) > 3 else None, ydds)
        if np.any(np.abs(h) > NOMINAL_RTOL * scale):  # forces that cancel within a body?
            eom = lin.equations_of_motion
            scale = scale + term_scale([*eom.k.entries(), *eom.q.entries()], state, f)
    return _nominal_check(h, scale, _kind(lin.y_s.entries(), lin.yd_s.entries(),
                                          lin.ydd_s.entries()),
                          tv, _describe_nominal(lin), system, us, B)


def _sym_part(A: SymMatrix, sign: int) -> SymMatrix:
    n = A.shape[0]
    rows = [[ZERO] * n for _ in range(n)]
    for i in range(n):
        for j in range(n):
            a, b = A[i, j], A[j, i]
            e = a + b if sign > 0 else a - b
            rows[i][j] = ZERO if e.is_Number and e == 0 else HALF * e
    return SymMatrix.from_rows(rows)


def _describe_nominal(lin: Linearization) -> str:
    return _describe(lin.system, lin.y_s.entries())
