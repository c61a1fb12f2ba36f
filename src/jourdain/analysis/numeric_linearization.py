"""The linearization in numbers for given parameter values (``docs/method.md`` §5–6): M̃, P,
Q, h, B by the floating-point forward mode over the graphs of k, q and J̄
(:func:`jourdain.graph.jet_float`), the fast path to the eigenvalues of large systems
(:func:`linearize_numeric`, :class:`NumericLinearization`).

Floor: analysis, above the numeric layer whose parameter and time handling it uses; the
symbolic linearization is :mod:`jourdain.stages.linearization`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import symengine as se

from ..errors import EvaluationError, warn
from ..graph import Graph, evaluate_float, free_symbol_names, jet_float
from ..numeric import parameter_vector, time_value
from ..stages.kinematics import kinematics  # the model has no stage methods (issue 16)
from ..stages.linearization.nominal import (
    NOMINAL_RTOL,
    NominalCheck,
    NominalMotionWarning,
    TimeVariantError,
    _describe,
    _is_zero,
    _kind,
    _nominal,
    _nominal_check,
    force_scale,
    term_scale,
)
from ..stages.newton_euler import newton_euler
from ..stages.projection import EquationsOfMotion, projection

if TYPE_CHECKING:
    from ..model.system import System


@dataclass(frozen=True)
class NumericLinearization:
    """``M̃·η̈ + P·η̇ + Q·η = h + B·Δu`` in numbers, at one time and for given parameter values
    (:func:`linearize_numeric`): the fast path for eigen-analysis of large systems, which skips
    the symbolic matrices.

    Attributes
    ----------
    system : System
    M_tilde, P, Q : (f, f) arrays
    h : (f,) array
    B : (f, m) array
    t : float
    parameters : dict
        All parameter values used.
    time_dependence : tuple of str
        Names of the matrices among M̃, P, Q, B that change with t (tested at three times where
        t appears at all).
    nominal_check : NominalCheck or None
        Whether the nominal motion solves the equations of motion at ``t``
        (:meth:`check_nominal`).
    equations_of_motion : EquationsOfMotion or None
        The stage it came from (for the cyclic coordinates of a stability verdict).
    """

    system: System
    M_tilde: np.ndarray
    P: np.ndarray
    Q: np.ndarray
    h: np.ndarray
    B: np.ndarray
    t: float
    parameters: dict[str, float]
    time_dependence: tuple[str, ...]
    nominal_check: NominalCheck | None = None
    equations_of_motion: EquationsOfMotion | None = field(default=None, repr=False,
                                                          compare=False)

    @property
    def is_time_invariant(self) -> bool:
        return not self.time_dependence

    def check_nominal(self, t: float | None = None,
                      parameters: Mapping[str, float] | None = None) -> NominalCheck:
        """``h`` against the forces at work at the nominal state (:class:`NominalCheck`), at
        the one time and parameter values of this result."""
        if (t is not None and float(t) != self.t) or parameters:
            raise EvaluationError("a NumericLinearization holds numbers for one t and one set "
                                  "of parameters; call linearize_numeric again for others")
        if self.nominal_check is None:
            raise EvaluationError("this NumericLinearization was built without the check of its "
                                  "nominal motion; linearize_numeric makes one with it")
        return self.nominal_check

    def _split(self, what: str, A: np.ndarray, sign: int) -> np.ndarray:
        if self.time_dependence:
            raise TimeVariantError(f"{what}: the linearization is time-variant "
                                   f"({', '.join(self.time_dependence)} depend on t)")
        return 0.5 * (A + sign * A.T)

    @property
    def D(self) -> np.ndarray:
        return self._split("D", self.P, +1)

    @property
    def G(self) -> np.ndarray:
        return self._split("G", self.P, -1)

    @property
    def K(self) -> np.ndarray:
        return self._split("K", self.Q, +1)

    @property
    def N(self) -> np.ndarray:
        return self._split("N", self.Q, -1)

    def evaluate(self, t: float | None = None,
                 parameters: Mapping[str, float] | None = None) -> dict[str, np.ndarray]:
        """The arrays as a dict (like :meth:`Linearization.evaluate`); they exist for one time
        and one set of parameters only, so other values are refused."""
        if (t is not None and float(t) != self.t) or parameters:
            raise EvaluationError("a NumericLinearization holds numbers for one t and one set "
                                  "of parameters; call linearize_numeric again for others")
        out = {"M_tilde": self.M_tilde, "P": self.P, "Q": self.Q, "h": self.h, "B": self.B}
        if self.is_time_invariant:
            out.update(D=self.D, G=self.G, K=self.K, N=self.N)
        return out


def linearize_numeric(source: System | EquationsOfMotion, nominal: Mapping[Any, Any] | Any,
                      t: float = 0.0,
                      parameters: Mapping[str, float] | None = None,
                      inputs: Mapping[Any, Any] | None = None) -> NumericLinearization:
    """M̃, P, Q, h, B as numbers for given parameter values, by forward-mode differentiation in
    floating point over the graphs of k, q and J̄ (:func:`jourdain.graph.jet_float`),
    with ``M̃ = J̄ᵀ·M̄·J̄`` in numbers.

    Same equations, nominal motions, nominal inputs and :class:`NominalMotionWarning` as
    :func:`linearization` (here at ``t`` and for ``parameters``), without forming symbolic
    matrices: the way to eigenvalues of large systems (a spatial chain of 16 bodies in well
    under a second, derivation included).
    """

    eom = source if isinstance(source, EquationsOfMotion) else projection(newton_euler(kinematics(source)))
    system = eom.system
    tv = time_value(t)
    y_s, u_s = _nominal(system, nominal, inputs)
    ts = system.t
    yd_s = [se.diff(e, ts) for e in y_s]
    ydd_s = [se.diff(e, ts) for e in yd_s]
    p = parameter_vector(system, parameters)
    pars = {str(s): float(v) for s, v in zip(system.parameter_symbols, p, strict=True)}
    nominal_exprs = [*y_s, *yd_s, *ydd_s, *u_s]
    nominal_has_t = "t" in free_symbol_names(nominal_exprs)
    ydd_nonzero = [not _is_zero(a) for a in ydd_s]
    f, m = system.f, len(system.inputs)
    # M = J̄ᵀ·M̄·J̄ (METHOD.md §3) is formed in numbers from J̄: the graph of J̄ is a fraction of
    # the graph of M's f(f+1)/2 entries, and M̄ holds parameters only
    ne = eom.newton_euler
    J_bar = ne.J_bar.entries()
    n6 = ne.J_bar.shape[0]
    # raises if M̄ depended on more
    M_bar = np.array(evaluate_float(ne.M_bar.entries(), pars)).reshape(n6, n6)
    # q̄^c and q̄^e (values only) give the scale of the forces for the check of h
    exprs = [*eom.k.entries(), *eom.q.entries(), *J_bar, *ne.q_c.entries(), *ne.q_e.entries()]
    mask = [True] * (2 * f) + [any(ydd_nonzero)] * len(J_bar) + [False] * (2 * n6)
    graph = Graph(exprs)
    variables = [*system.y, *system.yd, *system.inputs]
    nv = len(variables)

    def at(time: float) -> dict[str, np.ndarray]:
        values = {**pars, "t": time}
        nums = evaluate_float(nominal_exprs, values)
        ys, yds, ydds, us = (nums[:f], nums[f:2 * f], np.array(nums[2 * f:3 * f]),
                             nums[3 * f:])
        values.update({str(s): v for s, v in zip(system.y, ys, strict=True)})
        values.update({str(s): v for s, v in zip(system.yd, yds, strict=True)})
        values.update({str(s): v for s, v in zip(system.inputs, us, strict=True)})
        J = jet_float(graph, variables, values, mask)
        nJ = 2 * f + n6 * f
        Jb = J.values[2 * f:nJ].reshape(n6, f)
        MJ = M_bar @ Jb
        Mt = Jb.T @ MJ
        Mt = 0.5 * (Mt + Mt.T)
        # r = M·ÿ_s + k − q
        r = Mt @ ydds + J.values[:f] - J.values[f:2 * f]
        dr = J.jacobian[:f] - J.jacobian[f:2 * f]
        if np.any(ydds != 0.0):
            # ∂(J̄ᵀM̄J̄·ÿ_s)/∂y_v = (∂J̄/∂y_v)ᵀ·M̄J̄ÿ_s + J̄ᵀM̄·(∂J̄/∂y_v)·ÿ_s
            dJ = J.jacobian[2 * f:nJ].reshape(n6, f, nv)
            dJa = np.einsum("rjv,j->rv", dJ, ydds)
            dr = dr + np.einsum("rjv,r->jv", dJ, MJ @ ydds) + MJ.T @ dJa
        scale = force_scale(Jb, J.values[nJ:nJ + n6], J.values[nJ + n6:], J.values[:f],
                            J.values[f:2 * f], M_bar, ydds)
        if np.any(np.abs(r) > NOMINAL_RTOL * scale):  # forces that cancel within a body?
            scale = scale + term_scale(exprs[:2 * f], values, f)
        return {"M_tilde": Mt, "Q": dr[:, :f], "P": dr[:, f:2 * f],
                "B": -dr[:, 2 * f:2 * f + m], "h": -r, "h_scale": scale,
                "u_s": np.array(us, dtype=float)}

    out = at(tv)
    dependence: tuple[str, ...] = ()
    if nominal_has_t or "t" in graph.symbol_names():
        others = [at(tv + dt) for dt in (0.37, 1.91)]
        dependence = tuple(
            n for n in ("M_tilde", "P", "Q", "B")
            if any(np.abs(o[n] - out[n]).max(initial=0.0)
                   > 1e-10 * max(1.0, np.abs(out[n]).max(initial=0.0)) for o in others))
    for name, arr in out.items():
        if not np.all(np.isfinite(arr)):
            raise EvaluationError(f"the linearization has non-finite entries in {name}")
    check = _nominal_check(out["h"], np.where(out["h"] == 0, 0.0, out["h_scale"]),
                           _kind(y_s, yd_s, ydd_s), tv, _describe(system, y_s), system,
                           out["u_s"], out["B"])
    if check.kind != "nominal motion" and not check.is_solution:
        warn(check.message(), NominalMotionWarning)
    return NumericLinearization(system=system, M_tilde=out["M_tilde"], P=out["P"], Q=out["Q"],
                                h=out["h"], B=out["B"], t=tv, parameters=pars,
                                time_dependence=dependence, nominal_check=check,
                                equations_of_motion=eom)
