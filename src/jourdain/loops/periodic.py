"""The linearization of a closed system about a nominal motion of its independent coordinates
(METHOD.md §5 with §7), and its Floquet analysis when that motion is periodic.

The nominal motion gives the independent coordinates ``y_i,s(t)`` as expressions of t and the
parameters (the dependent ones follow on the manifold by Newton, started from the values
given for them and then from the last solution, so the branch is kept along the motion). At
each t, ``M̃(t), P(t), Q(t), h(t)`` are those of :func:`jourdain.loops.linearization.linearize_loop`
at the state ``(y_i,s, ẏ_i,s, ÿ_i,s)(t)`` (central differences of the compiled M, k, q on the
manifold): a linear time-variant system ``M̃·η̈ + P·η̇ + Q·η = h`` in the independent
coordinates. Over one period T the monodromy matrix ``Φ(t0 + T)`` of ``ẋ = A(t)·x`` with
``x = [η; η̇]`` gives the Floquet multipliers; they do not depend on the coordinates chosen
(a tree model of the same mechanism in other coordinates has the same multipliers).

The monodromy matrix is integrated by SciPy's DOP853 from Python (A(t) costs a few Newton
solves and M, k, q evaluations per call): jourdain's compiled monodromy integrator needs the
compiled symbolic linearization, which a closed system has not.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import symengine as se

from ..analysis.floquet import (
    Floquet,
    _verdict,
    check_period,
    monodromy_scipy,
    multipliers,
)
from ..errors import ClosedSystemError, EvaluationError, warn
from ..model import System
from ..stages.linearization import NominalMotionWarning
from ..stages.linearization.nominal import NOMINAL_RTOL
from .evaluator import LoopEvaluator
from .linearization import linearize_loop


@dataclass(frozen=True)
class ClosedLinearization:
    """``M̃(t)·η̈ + P(t)·η̇ + Q(t)·η = h(t)`` of a closed system about a nominal motion of its
    independent coordinates ``names`` (:func:`linearize_along`); :meth:`evaluate` gives the
    numbers at one t, :meth:`floquet` the Floquet analysis over a period."""

    system: System
    names: tuple[str, ...]
    nominal: tuple[se.Basic, ...]
    parameters: dict[str, float]
    _guess: dict[str, np.ndarray] = field(default_factory=dict, repr=False, compare=False)

    #: like a tree's time-variant linearization: frozen-time eigenvalues decide nothing
    is_time_invariant = False
    time_dependence = ("M_tilde", "P", "Q", "h")

    @property
    def coordinate_names(self) -> tuple[str, ...]:
        return self.names

    def _nominal_function(self) -> Any:
        fn = self._guess.get("fn")
        if fn is None:
            t = self.system.t
            exprs = [*self.nominal, *(se.diff(e, t) for e in self.nominal)]
            exprs += [se.diff(e, t) for e in exprs[len(self.nominal):]]
            fn = se.Lambdify([t, *self.system.parameter_symbols], exprs)
            self._guess["fn"] = fn
        return fn

    def state(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``y_i,s, ẏ_i,s, ÿ_i,s`` at ``t``."""
        p = [self.parameters[str(s)] for s in self.system.parameter_symbols]
        v = np.asarray(self._nominal_function()(float(t), *p), dtype=float).reshape(-1)
        g = len(self.names)
        return v[:g], v[g:2 * g], v[2 * g:]

    def matrices(self, t: float) -> dict[str, np.ndarray]:
        """``M_tilde, P, Q, h`` (in the independent coordinates) and the tree state ``y_s``
        on the manifold at ``t``."""
        y_i, yd_i, ydd_i = self.state(t)
        names = self.system.coordinate_names
        ind = [names.index(c) for c in self.names]
        z = self._guess["z"].copy()
        z[ind] = y_i
        zd = np.zeros(len(names))
        zd[ind] = yd_i
        lin = linearize_loop(self.system, z, zd, float(t), ydd_i, self.parameters)
        self._guess["z"] = lin.z_s.copy()  # the branch, followed along the motion
        return {"M_tilde": lin.M_tilde, "P": lin.P, "Q": lin.Q, "h": lin.h, "y_s": lin.z_s}

    def evaluate(self, t: float | None = None,
                 parameters: Mapping[str, float] | None = None) -> dict[str, np.ndarray]:
        """The numbers at ``t`` (0 by default) by the seed's names, D, G, K, N included."""
        if parameters:
            raise EvaluationError("a closed system's linearization holds one set of "
                                  "parameters; linearize again for others")
        m = self.matrices(0.0 if t is None else float(t))
        P, Q = m["P"], m["Q"]
        g = len(self.names)
        return {**m, "B": np.zeros((g, 0)), "D": (P + P.T) / 2, "G": (P - P.T) / 2,
                "K": (Q + Q.T) / 2, "N": (Q - Q.T) / 2}

    def state_matrix(self, t: float) -> np.ndarray:
        m = self.matrices(t)
        g = len(self.names)
        A = np.zeros((2 * g, 2 * g))
        A[:g, g:] = np.eye(g)
        try:
            A[g:] = -np.linalg.solve(m["M_tilde"], np.hstack([m["Q"], m["P"]]))
        except np.linalg.LinAlgError:
            raise EvaluationError(f"M_tilde is singular at t = {t:.6g}") from None
        return A

    def floquet(self, period: float, t0: float = 0.0,
                parameters: Mapping[str, float] | None = None, rtol: float = 1e-10,
                cyclic: Sequence[str] | None = None) -> Floquet:
        """Monodromy matrix, Floquet multipliers and exponents and the verdict over one
        ``period`` from ``t0`` (as :func:`jourdain.floquet` for trees)."""
        if parameters:
            raise EvaluationError("floquet: a closed system's linearization holds one set of "
                                  "parameters; linearize again for others")
        if cyclic:
            raise ClosedSystemError(self.system, "cyclic coordinates in Routh's sense are not "
                                    "found for closed systems")
        T = check_period(period, rtol)
        t0 = float(t0)
        reason_extra = self._check(t0, T)
        Phi = monodromy_scipy(self.state_matrix, 2 * len(self.names), t0, T, rtol)
        mu, lam, tol = multipliers(Phi, T, rtol)
        verdict, reason = _verdict(Phi, mu, tol)
        state = (*self.names, *(f"{c}_d" for c in self.names))
        return Floquet(period=T, t0=t0, monodromy=Phi, multipliers=mu, exponents=lam,
                       verdict=verdict, reason=reason + reason_extra, tolerance=tol,
                       state_names=state, cyclic=(), parameters=dict(self.parameters))

    def _check(self, t0: float, T: float) -> str:
        """The matrices must repeat with the period; the nominal motion should solve the
        equations (h ≈ 0 against the forces at work), else a warning."""
        at: dict[float, dict[str, np.ndarray]] = {}
        for a, b in ((t0, t0 + T), (t0 + T / 3, t0 + 4 * T / 3)):
            ma, mb = self.matrices(a), self.matrices(b)
            at[a] = ma
            for key in ("M_tilde", "P", "Q"):
                scale = max(1.0, float(np.abs(ma[key]).max(initial=0.0)))
                if np.abs(ma[key] - mb[key]).max(initial=0.0) > 1e-6 * scale:
                    raise EvaluationError(
                        f"floquet: the linearization of {self.system.name!r} is not periodic "
                        f"with T = {T:.6g}: {key} at t = {a:.6g} and t = {b:.6g} differ by "
                        f"{np.abs(ma[key] - mb[key]).max():.3g}")
        for t, m in at.items():  # at t0 and t0 + T/3, computed above
            _, _, ydd = self.state(t)
            scale = (np.abs(m["M_tilde"]) @ np.abs(ydd) + np.abs(m["Q"]).max(initial=0.0)
                     + np.abs(m["h"]))
            if np.any(np.abs(m["h"]) > NOMINAL_RTOL * 1e2 * np.maximum(scale, 1e-300)):
                text = (f"the nominal motion is not a solution of the closed system's equations "
                        f"at t = {t:.6g} (|h| = {np.abs(m['h']).max():.3g}): the verdict is "
                        "about the linear system only")
                warn(text, NominalMotionWarning)
                return f". WARNING: {text}"
        return ""


def linearize_along(system: System, nominal: Mapping[Any, Any],
                    parameters: Mapping[str, float] | None = None) -> ClosedLinearization:
    """The closed ``system`` linearized about the nominal motion ``nominal``: ``{coordinate:
    expression of t and the parameters}`` for the independent coordinates (those of
    ``system.independent``, else of the partition at the values given at t = 0), numbers for
    the dependent ones (Newton's start at t = 0, which selects the branch)."""
    names = system.coordinate_names
    f = system.f
    exprs: dict[str, se.Basic] = {}
    allowed = {"t", *system.parameter_values}
    for k, v in nominal.items():
        key = str(k)
        if key not in names:
            raise EvaluationError(f'nominal: unknown coordinate "{key}"; coordinates are '
                                  f"{', '.join(names)} (rates follow from the expressions)")
        exprs[key] = se.sympify(v) if isinstance(v, int | float) else v
        if not isinstance(exprs[key], se.Basic):
            raise EvaluationError(f"nominal {key}: expected a number or a SymEngine "
                                  f"expression (jourdain.t, jourdain.cos, ...), got {v!r}")
        unknown = sorted({str(s) for s in exprs[key].free_symbols} - allowed)
        if unknown:
            raise EvaluationError(f"nominal {key}: unknown name(s) {', '.join(unknown)}; the "
                                  "nominal motion may use t and the parameters")
    pars = system.parameter_values
    pars.update({k: float(v) for k, v in (parameters or {}).items()})
    subs = {se.Symbol(k): v for k, v in pars.items()}
    z0 = np.zeros(f)
    for i, c in enumerate(names):
        if c in exprs:
            z0[i] = float(exprs[c].subs({**subs, system.t: 0.0}))
    ev = LoopEvaluator(system, z0, 0.0, parameters)
    ind = tuple(ev.independent_names)
    missing = [c for c in ind if c not in exprs]
    if missing:
        raise EvaluationError(f"nominal: the independent coordinates {', '.join(ind)} need "
                              f"their motion; missing: {', '.join(missing)}")
    closed = system if system.independent == ind else system.tree.closed_by(
        system.closing, independent=ind, name=system.name)
    lin = ClosedLinearization(closed, ind, tuple(exprs[c] for c in ind), pars)
    lin._guess["z"] = ev.assemble(z0, None, 0.0).z.copy()
    return lin


__all__ = ["ClosedLinearization", "linearize_along"]
