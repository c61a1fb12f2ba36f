"""The internal record of one closed-system run (:class:`_Run`), filled by the drivers of
:mod:`jourdain.loops.simulate` (coordinate partitioning) and :mod:`jourdain.loops.redundant`
(the redundant-coordinate forms), and its conversion into the one :class:`jourdain.Results`
(:func:`_to_results`, with the work ``W`` of the applied forces) that
:func:`jourdain.loops.simulate.simulate_closed` returns. Not part of the API."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import EvaluationError
from ..model import System
from ..numeric import CompiledFunction, mkq_function, parameter_vector
from .closed_loop import SingularConfiguration
from .compiled import input_function


@dataclass
class _Run:
    """Time histories of one run: ``t`` (N,); ``y, yd, ydd`` (N, n) the tree's coordinates
    and their rates; ``Phi``, ``Phi_dot`` (N, m) the residuals of the closing rows; ``lam``
    (N, m) their multipliers (row names in ``labels``); ``partitions``: ``[(t_start, independent names), ...]``; ``singular``:
    the :class:`SingularConfiguration` that stopped the run, or None; ``method``: the
    integrator that ran."""

    system: System
    t: np.ndarray
    y: np.ndarray
    yd: np.ndarray
    ydd: np.ndarray
    Phi: np.ndarray
    Phi_dot: np.ndarray
    lam: np.ndarray
    labels: list[str]
    partitions: list[tuple[float, tuple[str, ...]]]
    status: str = "finished"
    message: str = ""
    nfev: int = 0
    wall_time: float = 0.0
    singular: SingularConfiguration | None = None
    parameters: dict[str, float] = field(default_factory=dict)
    method: str = "DOP853"
    #: the integrator's steps, accepted and rejected (0 where the stepper does not count them)
    steps: tuple[int, int, int] = (0, 0, 0)


def _input_values(loop: System, inputs: Any, fn_u: CompiledFunction | None,
                  parameters: Mapping[str, float] | None) -> Callable[[float], Any]:
    """The inputs as a function of time (for the evaluator and the SciPy engine)."""
    n_u = len(loop.tree.inputs)
    if fn_u is not None:  # expressions of t and the parameters, compiled
        p_u, zeros, u_zero = (parameter_vector(loop.tree, parameters), np.zeros(loop.f),
                              np.zeros(n_u))
        return lambda t: fn_u(zeros, zeros, t, p_u, u_zero)["u"][:, 0]
    if callable(inputs):
        return inputs
    u_const = np.zeros(n_u) if inputs is None else np.asarray(inputs, dtype=float)
    if u_const.size != n_u:
        raise EvaluationError(f"inputs must have {n_u} entries")
    return lambda _t: u_const


def _to_results(system: System, lr: _Run, parameters: Mapping[str, float] | None,
                inputs: Any, rtol: float, atol: Any) -> Any:
    """The run ``lr`` as :class:`jourdain.Results` of ``system``: the tree's coordinates, the
    inputs along the motion, the closing rows in :attr:`Results.constraints` and ``W``."""
    from ..simulation.results import Results
    from ..simulation.results.data import ConstraintHistories

    tree = system.tree
    n_u = len(tree.inputs)
    N = len(lr.t)
    U = np.zeros((N, n_u))
    if n_u and N:
        fn_u = input_function(system, inputs) if isinstance(inputs, Mapping) else None
        u_of = _input_values(system, inputs, fn_u, parameters)
        U = np.array([np.asarray(u_of(float(t)), dtype=float).reshape(n_u) for t in lr.t])
    cons = ConstraintHistories(tuple(lr.labels), lr.Phi, lr.Phi_dot, lr.lam,
                               tuple(lr.partitions), lr.singular)
    res = Results(system, lr.t, lr.y, lr.yd, lr.ydd, U, np.zeros(N), dict(lr.parameters),
                  method=lr.method, rtol=rtol, atol=atol, status=lr.status,
                  message=lr.message, nfev=lr.nfev, nsteps=lr.steps[0],
                  n_accepted=lr.steps[1], n_rejected=lr.steps[2], wall_time=lr.wall_time,
                  constraints=cons)
    res.W = _work(res, tree, parameters, inputs, system)
    return res


#: Gauss–Legendre nodes and weights on [0, 1] (exact for polynomials of degree 5)
_GAUSS_S = np.array([0.5 - np.sqrt(15) / 10, 0.5, 0.5 + np.sqrt(15) / 10])
_GAUSS_W = np.array([5.0, 8.0, 5.0]) / 18.0


def _work(res: Any, tree: System, parameters: Mapping[str, float] | None, inputs: Any,
          system: System) -> np.ndarray:
    """``W = ∫ẏᵀq dt`` since t0 along a closed system's motion (the constraint forces do no
    work on the manifold, so the tree's q is the closed system's applied forces), by
    three-point Gauss–Legendre on each step of the samples over their quintic Hermite
    interpolation (:meth:`Results.interpolate`): of order h⁶ like the interpolation, where
    the trapezoidal rule over the samples left 2.5e-4 of the four-bar's energy in its
    balance."""
    t = res.t
    N = len(t)
    W = np.zeros(N)
    if N < 2:
        return W
    h = np.diff(t)
    tg = (t[:-1, None] + h[:, None] * _GAUSS_S[None, :]).reshape(-1)
    m = res.interpolate(tg)
    n_u = len(tree.inputs)
    U = None
    if n_u:
        fn_u = input_function(system, inputs) if isinstance(inputs, Mapping) else None
        u_of = _input_values(system, inputs, fn_u, parameters)
        U = np.array([np.asarray(u_of(float(x)), dtype=float).reshape(n_u) for x in tg])
    q = mkq_function(tree).batch(m["y"], m["yd"], tg, parameter_vector(tree, parameters),
                                 U)["q"][:, :, 0]
    power = np.einsum("ij,ij->i", m["yd"], q).reshape(-1, 3)
    W[1:] = np.cumsum(h * (power @ _GAUSS_W))
    return W


__all__: list[str] = []
