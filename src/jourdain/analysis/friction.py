"""Joint friction from reaction forces in numbers (METHOD.md §7; the element and its law:
:mod:`jourdain.model.friction`): the equations of motion and the reactions solved together.

A system with :class:`~jourdain.model.friction.JointFriction` elements is evaluated as its
*friction model* (:func:`friction_model`): the same system with each element replaced by a
generalized force on its coordinate whose value is an input named after the element (φ_k).
Everything is affine in φ: ``q = q_0 + E·φ``, ``q̄^e = q̄^e_0 + B·φ`` and, from
``N̂·g = k̂ − q̂`` (§4), ``g = g_0 − D·φ``. One evaluation of the compiled Newton–Euler matrices
at φ = 0 and at each unit φ_k (one batched call) gives g_0, D and E; the friction forces then
solve the m equations ``φ_k + μ_k·r_k·tanh(ċ_k/v_eps)·|N_k(g_0 − D·φ)| = 0`` (Newton's method:
piecewise linear for single normal components, exact once their signs settle), and
``M·ÿ + k = q_0 + E·φ`` gives ÿ. Where the Newton matrix is not positive at the solution (or
no solution is found) the friction force is not determined by the normal force it causes
(Painlevé's paradox, ``μ·r·|∂N/∂φ| ≥ 1``): an :class:`EvaluationError` names the elements.

:func:`evaluate_friction` is ``System.evaluate`` of such a system (every key of the method's
numbers, with the friction in ``q_e``, ``q``, ``q_hat`` and ``g``, plus ``q_f``, ``ydd`` and
``friction``); :func:`friction_inputs` is what ``simulate`` runs: the friction model with the
friction forces as state-feedback inputs, computed from the state at every evaluation.
"""

from __future__ import annotations

import numbers
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING, Any

import numpy as np
import symengine as se

from ..errors import EvaluationError, JourdainError, ModelError
from ..model.expressions import as_expr, values_at
from ..model.forces import GeneralizedForce
from ..numeric import evaluate as evaluate_eom
from ..numeric import lambdify, parameter_vector, state_vectors
from ..simulation.problem import takes_state  # the integrator's rule for an input law
from ..symbolic import SymMatrix
from .reactions import ReactionLayout, _reactions_function, evaluate_keys, projected_reactions
from .reactions import solve_g as _solve_g

if TYPE_CHECKING:
    from ..model.system import System

#: Newton iterations allowed for the friction forces at one state
MAX_ITERATIONS = 50


@dataclass(frozen=True)
class FrictionModel:
    """A system with joint friction, prepared for its numbers: ``model`` is the system with
    each friction element a generalized force driven by the input of its name (the last m
    inputs); ``normal`` the indices in g of each element's normal components, ``coordinate``
    the index in y of its coordinate."""

    system: System
    model: System
    layout: ReactionLayout
    fn: Any
    normal: tuple[tuple[int, ...], ...]
    coordinate: tuple[int, ...]

    @property
    def names(self) -> list[str]:
        return [fr.name for fr in self.system.frictions]

    def coefficients(self, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``μ·r`` and ``v_eps`` of each element at the parameter values ``p``."""
        values = dict(zip((k for k, _ in self.system.parameters), p.tolist(), strict=True))
        frs = self.system.frictions
        mu_r = np.array(values_at([fr.mu * fr.radius for fr in frs], values))
        v_eps = np.array(values_at([fr.v_eps for fr in frs], values))
        for fr, a, v in zip(frs, mu_r, v_eps, strict=True):
            if not (a >= 0 and v > 0):
                raise EvaluationError(f'joint friction "{fr.name}": mu·radius = {a:g} and '
                                      f"v_eps = {v:g} at these parameters; they must be ≥ 0 "
                                      "and > 0")
        return mu_r, v_eps


@lru_cache(maxsize=32)
def friction_model(system: System) -> FrictionModel:
    """The friction model of ``system`` (see the module docstring), its reactions' layout and
    compiled Newton–Euler matrices; ModelError naming the element whose normal components
    are not reaction components of the model."""
    frs = system.frictions
    forces = [*system.forces,
              *(GeneralizedForce(fr.name, fr.coordinate, se.Symbol(fr.name)) for fr in frs)]
    model = type(system)(system.coordinates, system.bodies, forces, dict(system.parameters),
                         [*system.input_names, *(fr.name for fr in frs)], dict(system.units),
                         system.name)
    try:
        lay, fn = _reactions_function(model)
    except JourdainError as exc:
        raise ModelError(f"joint friction {', '.join(fr.name for fr in frs)}: the reaction "
                         f"forces are needed and cannot be formed: {exc}") from None
    normal = []
    for fr in frs:
        missing = [n for n in fr.normal if n not in lay.g_names]
        if missing:
            raise ModelError(f'joint friction "{fr.name}": {", ".join(missing)} is not a '
                             f"reaction component; the model's are {', '.join(lay.g_names)}")
        normal.append(tuple(lay.g_names.index(n) for n in fr.normal))
    names = system.coordinate_names
    return FrictionModel(system, model, lay, fn, tuple(normal),
                         tuple(names.index(str(fr.coordinate)) for fr in frs))


@dataclass(frozen=True)
class FrictionState:
    """The friction forces ``phi`` at one state with what they were solved with: the normal
    loads ``normal``, the reactions ``g`` (friction included), ``q_f = E·φ``."""

    phi: np.ndarray
    normal: np.ndarray
    g: np.ndarray
    q_f: np.ndarray


def solve_friction(fm: FrictionModel, y: np.ndarray, yd: np.ndarray, t: float, p: np.ndarray,
                   u: np.ndarray, mu_r: np.ndarray, v_eps: np.ndarray) -> FrictionState:
    """The friction forces at one state (``u``: the system's own inputs)."""
    m = len(fm.coordinate)
    nu = u.size
    U = np.zeros((m + 1, nu + m))
    U[:, :nu] = u
    U[1:, nu:] = np.eye(m)
    out = fm.fn.batch(np.tile(y, (m + 1, 1)), np.tile(yd, (m + 1, 1)), float(t), p, U)
    qc, qe = out["q_c"][:, :, 0], out["q_e"][:, :, 0]
    N, kh, qh = projected_reactions(fm.layout, out["M_bar"], out["Q_bar"], qc, qe)
    G = _reactions(fm, out["Q_bar"][0], N[0], kh[0], qh, qc[0], qe)
    g0, D = G[0], (G[0] - G[1:]).T
    q = out["q"][:, :, 0]
    E = q[1:] - q[0]
    c = mu_r * np.tanh(yd[list(fm.coordinate)] / v_eps)
    phi = _newton(fm, g0, D, c, t)
    return FrictionState(phi, _normal(fm, g0 - D @ phi)[0], g0 - D @ phi, E.T @ phi)


def _reactions(fm: FrictionModel, Q: np.ndarray, N: np.ndarray, kh: np.ndarray,
               qh: np.ndarray, qc: np.ndarray, qe: np.ndarray) -> np.ndarray:
    """g at each row of ``qh``/``qe`` (φ = 0 and the unit φ_k): one Cholesky factor of N̂,
    or the bordered system of bodies without inertia row by row."""
    lay = fm.layout
    if not lay.singular_rows:
        try:
            C = np.linalg.cholesky(N)
            return np.linalg.solve(C.T, np.linalg.solve(C, (kh - qh).T)).T
        except np.linalg.LinAlgError:
            pass
    G = np.array([_solve_g(Q, N, kh, qh[i], qc, qe[i], lay.singular_rows, lay.g_names)[0]
                  for i in range(qh.shape[0])])
    used = sorted({i for idx in fm.normal for i in idx})
    if not np.isfinite(G[:, used]).all():
        raise EvaluationError(f"joint friction {', '.join(fm.names)}: a normal component is "
                              "undetermined at this state (redundant reaction directions)")
    return G


def _normal(fm: FrictionModel, g: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each element's normal load |N_k(g)| and its gradient with respect to g (m × q)."""
    n = np.zeros(len(fm.normal))
    dn = np.zeros((len(fm.normal), g.size))
    for k, idx in enumerate(fm.normal):
        gs = g[list(idx)]
        n[k] = abs(gs[0]) if len(idx) == 1 else float(np.sqrt(gs @ gs))
        if n[k] > 0:
            dn[k, list(idx)] = np.sign(gs) if len(idx) == 1 else gs / n[k]
    return n, dn


def _newton(fm: FrictionModel, g0: np.ndarray, D: np.ndarray, c: np.ndarray,
            t: float) -> np.ndarray:
    """φ with ``φ + c·|N(g0 − D·φ)| = 0``, from the friction of the loads without it."""
    phi = -c * _normal(fm, g0)[0]
    if not c.any():
        return phi
    eps = np.finfo(float).eps
    for _ in range(MAX_ITERATIONS):
        n, dn = _normal(fm, g0 - D @ phi)
        J = np.eye(c.size) - (c[:, None] * dn) @ D
        F = phi + c * n
        try:
            step = np.linalg.solve(J, F)
        except np.linalg.LinAlgError:
            break
        phi = phi - step
        scale = max(float(np.abs(phi).max()), float(np.abs(c * n).max()), 1e-300)
        if np.abs(step).max() <= 8 * eps * scale:
            n, dn = _normal(fm, g0 - D @ phi)
            J = np.eye(c.size) - (c[:, None] * dn) @ D
            if np.linalg.det(J) > 0 and np.abs(phi + c * n).max() <= 64 * eps * c.size * scale:
                return phi
            break
    raise EvaluationError(
        f"joint friction {', '.join(fm.names)}: no friction force is consistent with the "
        f"normal force it causes at t = {t:.9g} (μ·r·|∂N/∂F_friction| ≥ 1, Painlevé's "
        "paradox): the rigid-body model with Coulomb friction has no unique motion here")


def evaluate_friction(system: System, y: Any, yd: Any, t: float = 0.0,
                      parameters: Mapping[str, float] | None = None,
                      inputs: Mapping[str, float] | Any = None) -> dict[str, Any]:
    """``System.evaluate`` of a system with joint friction: the keys of
    :func:`jourdain.numeric.evaluate` and of the reactions with the friction forces in
    ``q_e``, ``q``, ``q_hat`` and ``g`` (the friction model's numbers at the solved forces),
    and ``q_f`` (the friction's generalized forces), ``ydd`` (from ``M·ÿ + k = q``) and
    ``friction``: ``{name: {"force", "normal", "rate", "limit"}}`` (the force or torque on its
    coordinate, the normal load |N|, the coordinate's rate, and μ·r·|N|)."""
    fm = friction_model(system)
    yv, ydv, tv, pv, uv = state_vectors(system, y, yd, t, parameters, inputs)
    mu_r, v_eps = fm.coefficients(pv)
    st = solve_friction(fm, yv, ydv, tv, pv, uv, mu_r, v_eps)
    u_all = np.concatenate([uv, st.phi])
    out: dict[str, Any] = dict(evaluate_eom(fm.model, yv, ydv, t=tv, parameters=parameters,
                                            inputs=u_all.tolist()))
    eom = dict(out)
    out.update(evaluate_keys(fm.model, yv, ydv, tv, parameters, u_all.tolist(), eom=eom))
    out["q_f"] = st.q_f
    out["ydd"] = np.linalg.solve(np.atleast_2d(out["M"]), out["q"] - out["k"])
    out["friction"] = {
        name: {"force": float(st.phi[k]), "normal": float(st.normal[k]),
               "rate": float(ydv[fm.coordinate[k]]), "limit": float(mu_r[k] * st.normal[k])}
        for k, name in enumerate(fm.names)}
    return out


def friction_inputs(system: System, inputs: Mapping[str, Any] | Any,
                    parameters: Mapping[str, float] | None) -> tuple[System, dict[str, Any]]:
    """What ``simulate`` integrates for a system with joint friction: its friction model and
    the inputs, the system's own and, for each element, a state feedback ``φ_k(t, y, ẏ)``
    solved from the reactions at every evaluation (the results carry the friction forces as
    these inputs' columns, and the reactions along the motion with them)."""
    fm = friction_model(system)
    p = parameter_vector(system, parameters)
    mu_r, v_eps = fm.coefficients(p)
    names = system.input_names
    if inputs is not None and not isinstance(inputs, Mapping):
        seq = list(inputs)
        if len(seq) != len(names):
            raise EvaluationError(f"inputs: expected {len(names)} values for {names}, got "
                                  f"{len(seq)}")
        inputs = dict(zip(names, seq, strict=True))
    given = dict(inputs or {})
    own = _input_function(system, given, p)
    last: dict[str, Any] = {}

    def forces(t: float, y: np.ndarray, yd: np.ndarray) -> np.ndarray:
        key = (float(t), y.tobytes(), yd.tobytes())
        if last.get("key") != key:
            last["phi"] = solve_friction(fm, y, yd, t, p, own(t, y, yd), mu_r, v_eps).phi
            last["key"] = key
        return last["phi"]

    out = dict(given)
    for k, fr in enumerate(system.frictions):
        if fr.name in out:
            raise EvaluationError(f'inputs: "{fr.name}" is a joint friction, not an input')

        def phi_k(t: float, y: np.ndarray, yd: np.ndarray, k: int = k) -> float:
            return float(forces(t, y, yd)[k])

        out[fr.name] = phi_k
    return fm.model, out


def _input_function(system: System, given: Mapping[str, Any], p: np.ndarray
                    ) -> Callable[[float, np.ndarray, np.ndarray], np.ndarray]:
    """The system's own inputs as a function of (t, y, ẏ), for the friction forces (the
    integrator evaluates them itself for the equations of motion): numbers, tables
    ``(times, values)``, callables ``u(t)`` or ``u(t, y, yd)`` and expressions."""
    names = system.input_names
    missing = [n for n in names if n not in given]
    if missing:
        example = ", ".join(f"{m!r}: 0.0" for m in missing)
        raise EvaluationError(f"input(s) {missing} not given: pass inputs={{{example}}} or a "
                              "function of time, an expression in t or a table (times, values)")
    parts = [_one_input(system, name, given[name], p) for name in names]

    def values(t: float, y: np.ndarray, yd: np.ndarray) -> np.ndarray:
        return np.array([part(t, y, yd) for part in parts])

    return values


def _one_input(system: System, name: str, v: Any, p: np.ndarray
               ) -> Callable[[float, np.ndarray, np.ndarray], float]:
    """One input of the system as a function of (t, y, ẏ)."""
    if isinstance(v, numbers.Real) and not isinstance(v, bool):
        value = float(v)
        return lambda t, y, yd: value
    if isinstance(v, tuple) and len(v) == 2:
        tt, vv = np.asarray(v[0], float), np.asarray(v[1], float)
        return lambda t, y, yd: float(np.interp(t, tt, vv))
    if callable(v) and not isinstance(v, se.Basic):
        fn = v
        if takes_state(fn):
            return lambda t, y, yd: float(fn(t, y.copy(), yd.copy()))
        return lambda t, y, yd: float(fn(t))
    compiled = lambdify(system, {"u": SymMatrix.column([as_expr(v, f'input "{name}"')])})
    zero = np.zeros(len(system.inputs))
    return lambda t, y, yd: float(compiled(y, yd, t, p, zero)["u"][0, 0])


__all__ = ["FrictionModel", "FrictionState", "evaluate_friction", "friction_inputs",
           "friction_model", "solve_friction"]
