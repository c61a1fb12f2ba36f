"""Equilibria: positions ``y_s`` with ``q(y_s, 0, t) − k(y_s, 0, t) = 0`` for given parameters.

Solved by Levenberg–Marquardt (any equilibrium) or by regularized Newton steps that go downhill
in the potential (stable ones), both with the exact Jacobian ``∂(k − q)/∂y`` at ``ẏ = 0`` (the
stiffness part of the linearization), obtained together with the residual in one pass over the
expression graph (:func:`jourdain.graph.jet_float`, in floating point). A system usually has
several equilibria (a pendulum hangs or stands); the starting guess says which one is meant,
:func:`find_equilibria` collects the distinct ones reached from several guesses.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .errors import EvaluationError, JourdainError
from .graph import Graph, jet_float
from .numeric import parameter_vector
from .stages.kinematics import kinematics
from .stages.newton_euler import newton_euler
from .stages.projection import projection

if TYPE_CHECKING:
    from .model.system import System
    from .stages.projection import EquationsOfMotion


class NoEquilibrium(JourdainError, ArithmeticError):
    """Newton's method did not reach an equilibrium from the guess given."""



def equations_of_motion(system: System) -> EquationsOfMotion:
    """M·ÿ + k = q of ``system`` by the stages (kinematics → Newton–Euler → projection)."""
    return projection(newton_euler(kinematics(system)))

@dataclass(frozen=True)
class Equilibrium:
    """An equilibrium position of a system for given parameter values.

    Attributes
    ----------
    y : (f,) array
        The coordinates at equilibrium.
    coordinate_names : tuple of str
    residual : float
        ``max |q − k|`` at ``y`` over the coordinates not fixed (in the units of q).
    iterations : int
    parameters : dict
        All parameter values used (defaults with overrides).
    inputs : dict
        The constant input values used.
    t : float
    """

    y: np.ndarray
    coordinate_names: tuple[str, ...]
    residual: float
    iterations: int
    parameters: dict[str, float]
    inputs: dict[str, float]
    t: float

    @property
    def nominal(self) -> dict[str, float]:
        """``{coordinate: value}`` plus the inputs, ready for :meth:`System.linearize`."""
        out = {n: float(v) for n, v in zip(self.coordinate_names, self.y, strict=True)}
        out.update(self.inputs)
        return out

    def __repr__(self) -> str:
        vals = ", ".join(f"{n}={v:.6g}" for n, v in zip(self.coordinate_names, self.y,
                                                         strict=True))
        return f"Equilibrium({vals}; residual {self.residual:.2e})"


def find_equilibrium(system: System, guess: Mapping[str, float] | Sequence[float] | None = None,
                     parameters: Mapping[str, float] | None = None,
                     inputs: Mapping[str, float] | None = None, t: float = 0.0,
                     fixed: Sequence[str] = (), tol: float = 1e-10, max_iterations: int = 50,
                     method: str = "any",
                     eom: EquationsOfMotion | None = None) -> Equilibrium:
    """Solve ``q(y, 0, t) − k(y, 0, t) = 0`` for ``y`` near ``guess``.

    Parameters
    ----------
    system : System
    guess : mapping name -> value or sequence of f values, optional
        Starting point; it selects which equilibrium is found (zeros when omitted; names not
        given start at zero).
    parameters : mapping, optional
        Parameter values overriding the defaults.
    inputs : mapping, optional
        Constant input values (zero when not given).
    t : float
        Time, for systems with explicitly time-dependent forces.
    fixed : sequence of str
        Coordinates held at their guess as by a lock: their own equations are not solved (e.g.
        a cyclic rotor angle that any value satisfies, or a joint held by a brake).
    max_iterations : int
        Iteration limit (Levenberg–Marquardt: evaluations per free coordinate; "stable": four
        times this many steps).
    tol : float
        Convergence when ``max |q − k|`` is below ``tol`` times the largest generalized force
        seen at the guess (at least 1).
    method : "any" or "stable"
        ``"any"``: Levenberg–Marquardt on ``|q − k|²``, which converges to the equilibrium near
        the guess whatever its stability (an upright pendulum). ``"stable"``: Newton steps on
        ``(J + μ·E)·Δy = −(k − q)`` with ``μ`` at least the most negative eigenvalue of the
        symmetric part of ``J = ∂(k − q)/∂y``; for potential forces (``k − q = ∂V/∂y``) every
        step lowers V, so the iteration settles in a minimum of the potential near the guess
        (a hanging chain).
    eom : EquationsOfMotion, optional
        Reuse equations already derived.

    Raises
    ------
    NoEquilibrium
        When the iteration ends away from an equilibrium (with the last residual and position).
    """
    names = system.coordinate_names
    f = system.f
    y0 = _start(guess, names)
    unknown = [n for n in fixed if n not in names]
    if unknown:
        raise EvaluationError(f"fixed: unknown coordinate(s) {unknown}; coordinates are {names}")
    free = [i for i, n in enumerate(names) if n not in set(fixed)]
    pv = parameter_vector(system, parameters)
    pars = {str(s): float(v) for s, v in zip(system.parameter_symbols, pv, strict=True)}
    u_names = system.input_names
    uvals = {n: 0.0 for n in u_names}
    for k, v in (inputs or {}).items():
        if k not in uvals:
            raise EvaluationError(f"unknown input {k!r}; inputs are {u_names}")
        uvals[k] = float(v)
    eom = eom if eom is not None else equations_of_motion(system)
    # the graph of k − q is built once and evaluated (values and exact Jacobian, in floating
    # point) at every iterate
    graph = Graph([*eom.k.entries(), *eom.q.entries()])
    fixed_values = {**pars, **uvals, "t": float(t), **{str(s): 0.0 for s in system.yd}}

    def evaluate(y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        values = dict(fixed_values)
        values.update({str(s): float(v) for s, v in zip(system.y, y, strict=True)})
        J = jet_float(graph, system.y, values)
        r = J.values[:f] - J.values[f:]
        Jm = J.jacobian[:f] - J.jacobian[f:]
        # a fixed coordinate is held as by a lock: its own equation is not solved
        return r[free], Jm[np.ix_(free, free)]

    # Levenberg–Marquardt on ||q - k||²: a trust region keeps the steps short where the
    # Jacobian is nearly singular (nearly cyclic coordinates), so the iteration stays with the
    # equilibrium near the guess instead of jumping to another one
    from scipy.optimize import least_squares

    cache: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}

    def full(x: np.ndarray) -> np.ndarray:
        y = y0.copy()
        y[free] = x
        return y

    def at(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        key = x.tobytes()
        if key not in cache:
            cache.clear()
            cache[key] = evaluate(full(x))
        return cache[key]

    if not free:
        raise EvaluationError("all coordinates are fixed: there is nothing to solve for")
    r0, _ = at(y0[free])
    scale = max(1.0, float(np.abs(r0).max()))
    if method == "any":
        sol = least_squares(lambda x: at(x)[0], y0[free], jac=lambda x: at(x)[1],
                            method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15,
                            max_nfev=max_iterations * (len(free) + 1))
        x, nfev = sol.x, int(sol.nfev)
    elif method == "stable":
        x, nfev = _descend(at, y0[free], tol * scale, max_iterations)
    else:
        raise EvaluationError(f'method must be "any" or "stable", got {method!r}')
    y = full(x)
    r, Jm = evaluate(y)
    # polish with plain Newton steps (least squares stops at its own tolerances)
    for _ in range(3):
        err = float(np.abs(r).max())
        if err <= tol * scale:
            break
        step = np.linalg.lstsq(Jm, -r, rcond=None)[0]
        trial = y.copy()
        trial[free] += step
        rt, Jt = evaluate(trial)
        if np.abs(rt).max() >= err:
            break
        y, r, Jm = trial, rt, Jt
    err = float(np.abs(r).max())
    if err <= tol * scale:
        return Equilibrium(y=y, coordinate_names=tuple(names), residual=err,
                           iterations=nfev, parameters=pars, inputs=uvals, t=float(t))
    raise NoEquilibrium(
        f"no equilibrium of {system.name!r} found from the guess "
        f"{_show(names, y0)}: max |q - k| = {err:.3e} at {_show(names, y)} (a local minimum "
        "of the residual; try another guess)"
    )


def _descend(at: Any, x: np.ndarray, tol: float,
             max_iterations: int) -> tuple[np.ndarray, int]:
    """Regularized Newton steps (J + μE)Δ = −r that go downhill in the potential."""
    n = x.size
    for it in range(max_iterations * 4):
        r, Jf = at(x)
        if np.abs(r).max() <= tol:
            return x, it + 1
        lmin = float(np.linalg.eigvalsh(0.5 * (Jf + Jf.T))[0])
        mu = max(0.0, -lmin) + float(np.linalg.norm(r))
        try:
            x = x - np.linalg.solve(Jf + mu * np.eye(n), r)
        except np.linalg.LinAlgError:
            x = x - np.linalg.lstsq(Jf + mu * np.eye(n), r, rcond=None)[0]
    return x, max_iterations * 4


def _show(names: list[str], y: np.ndarray) -> str:
    text = ", ".join(f"{n}={v:.4g}" for n, v in zip(names, y, strict=True))
    return "{" + (text if len(text) < 300 else text[:297] + "...") + "}"


def find_equilibria(system: System, guesses: Sequence[Mapping[str, float] | Sequence[float]],
                    parameters: Mapping[str, float] | None = None,
                    inputs: Mapping[str, float] | None = None, t: float = 0.0,
                    fixed: Sequence[str] = (), tol: float = 1e-10,
                    distinct: float = 1e-6, method: str = "any") -> list[Equilibrium]:
    """The distinct equilibria reached from several guesses (guesses that fail are skipped);
    two are the same when their coordinates differ by less than ``distinct``."""
    eom = equations_of_motion(system)
    found: list[Equilibrium] = []
    for g in guesses:
        try:
            e = find_equilibrium(system, g, parameters, inputs, t, fixed, tol, method=method,
                                 eom=eom)
        except NoEquilibrium:
            continue
        if all(np.abs(e.y - o.y).max() > distinct for o in found):
            found.append(e)
    return found


def _start(guess: Any, names: list[str]) -> np.ndarray:
    f = len(names)
    if guess is None:
        return np.zeros(f)
    if isinstance(guess, Mapping):
        unknown = [k for k in guess if k not in names]
        if unknown:
            raise EvaluationError(f"guess: unknown coordinate(s) {unknown}; coordinates are {names}")
        y = np.array([float(guess.get(n, 0.0)) for n in names])
    else:
        y = np.asarray(guess, dtype=float).reshape(-1)
        if y.size != f:
            raise EvaluationError(f"guess must have {f} values ({', '.join(names)}), got {y.size}")
    if not np.all(np.isfinite(y)):
        raise EvaluationError("guess contains NaN or inf")
    return y
