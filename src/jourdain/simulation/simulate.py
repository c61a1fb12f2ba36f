"""Time integration of the equations of motion ``M(y,t)·ÿ + k(y,ẏ,t) = q(y,ẏ,t)``.

:func:`simulate` integrates from ``y(t0) = y0, ẏ(t0) = ẏ0`` and returns a
:class:`~jourdain.simulation.results.Results`. The default methods ``"DOP853"`` and ``"RK45"``
(Dormand–Prince 8(5,3) and 5(4), adaptive steps, continuous extension) and the stiff method
``"Radau"`` (Radau IIA, order 5) run their step loop in C (:mod:`jourdain.numeric.integrator_c`),
calling the generated ``M, k, q`` code and a Cholesky factorization of ``M`` in every
evaluation, without returning to Python between steps. ``"BDF"``, ``"LSODA"`` and
``"scipy:<method>"`` use :func:`scipy.integrate.solve_ivp` with the same compiled right-hand
side (one call from Python per evaluation).

Inputs ``u(t)`` are given per input name as

- a number (constant),
- a table ``(times, values)`` (linear interpolation, held constant outside; runs in C),
- an expression in ``t``, the coordinates, their rates and the parameters (compiled into the C
  loop; state feedback is allowed),
- a Python callable ``u(t) -> float`` or ``u(t, y, yd) -> float`` (state feedback), called back
  from C at every evaluation: much slower.

Events are :class:`Event` objects holding an expression in ``t``, ``y``, ``ẏ``, parameters and
inputs; the run records the times at which it crosses zero (located on the continuous extension)
and stops at the first crossing of a terminal event.

The run goes in chunks so that a long run shows progress, can write its results as it goes
(``output=``) and, when interrupted (Ctrl-C, an exception in an input callable), keeps what was
computed: the results say ``interrupted`` and why.

Place in the method: the time integration of the equations of motion (``docs/method.md``,
"Numbers, simulation, files").
This module is the entry point; the options and their checks are in :mod:`.options`, what the
compiled loop integrates (events, inputs, the C structure and library) in :mod:`.problem`, the
problem prepared once per system and options (memoized: a repeated call costs microseconds
outside its C loop) in :mod:`.template`, one run (C loop in chunks or SciPy, and the errors of
a run) in :mod:`.runs`; the names that other modules import from here stay importable from
here.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import EvaluationError
from ..numeric import CompiledFunction, _vector
from .options import (  # noqa: F401 - the import paths of the options stay those of this module
    ATOL_MAX,
    C_METHODS,
    DEFAULT_ATOL,
    DEFAULT_METHOD,
    DEFAULT_RTOL,
    DEFAULT_SAMPLES,
    DEFAULT_T_END,
    MAX_OUTPUT_BYTES,
    MAX_SAMPLES,
    MAX_STEPS,
    MAX_TIME,
    MIN_SAMPLES,
    OUTPUT_SUFFIXES,
    RTOL_MIN,
    SCIPY_METHODS,
    _real,
    _shown,
    check_atol,
    check_max_step,
    check_method,
    check_rtol,
    check_samples,
    check_t_end,
    check_t_eval,
    check_t_span,
    checked_options,
    max_samples,
    steps_per_call,
)
from .problem import (  # noqa: F401 - re-exported: the ensemble driver builds on them
    Event,
    _Problem,
    _Setup,
    integrator_library,
)
from .results import Results
from .runs import IntegrationError, _run_c, _run_scipy
from .template import RunTemplate, run_template

if TYPE_CHECKING:
    from ..model.system import System

__all__ = ["ATOL_MAX", "C_METHODS", "DEFAULT_ATOL", "DEFAULT_METHOD", "DEFAULT_RTOL",
           "DEFAULT_SAMPLES", "DEFAULT_T_END", "MAX_OUTPUT_BYTES",
           "MAX_SAMPLES", "MAX_STEPS", "MAX_TIME", "MIN_SAMPLES", "OUTPUT_SUFFIXES", "RTOL_MIN",
           "SCIPY_METHODS", "Event", "IntegrationError", "accelerations", "check_atol",
           "check_max_step", "check_method", "check_rtol", "check_samples", "check_t_end",
           "check_t_eval", "check_t_span", "integrator_library", "max_samples", "simulate",
           "steps_per_call"]


def simulate(system: System, t_span: tuple[float, float], y0: Any, yd0: Any,
             parameters: Mapping[str, float] | None = None,
             inputs: Mapping[str, Any] | None = None, method: str = DEFAULT_METHOD,
             rtol: float = DEFAULT_RTOL, atol: float | Sequence[float] = DEFAULT_ATOL,
             t_eval: Sequence[float] | None = None, events: Sequence[Event] = (),
             max_step: float = math.inf, first_step: float | None = None,
             progress: bool | Callable[[float, float], None] = False,
             output: str | None = None, raise_on_interrupt: bool = False,
             **closed_options: Any) -> Results:
    """Integrate ``M(y,t)·ÿ + k(y,ẏ,t) = q(y,ẏ,t)`` over ``t_span`` from ``y0, ẏ0``.

    Parameters
    ----------
    system : System
    t_span : (t0, t1) with t1 > t0, both within ±``MAX_TIME`` (1e9)
    y0, yd0 : initial coordinates and rates (f each, in the order of ``system.coordinates``)
    parameters : overrides of parameter values by name (no recompilation)
    inputs : input name -> number, table ``(times, values)``, expression or callable (see module)
    method : "DOP853" (default), "RK45", "Radau" (step loop in C) or "BDF", "LSODA",
        "scipy:Radau", "scipy:RK45", "scipy:DOP853" (SciPy's solve_ivp)
    rtol, atol : tolerances (default :data:`DEFAULT_RTOL` = 1e-8, :data:`DEFAULT_ATOL` =
        1e-10); the local error of each state component stays below ``atol + rtol·|x|``;
        ``RTOL_MIN`` (1e-14) <= rtol < 1; 0 < atol <= ``ATOL_MAX`` (1e3); ``atol`` may be a
        vector of length 2f (y then ẏ)
    t_eval : output times (continuous extension), finite, sorted, within ``t_span``, at most
        ``MAX_SAMPLES`` (and ``MAX_OUTPUT_BYTES`` of results); default: every accepted step
    events : :class:`Event` objects
    max_step, first_step : step size limits; ``max_step`` asks for at most ``MAX_STEPS`` steps
        over ``t_span``
    progress : True prints the progress to stderr (every 0.5 s); a callable gets ``(t, t1)``
        after every chunk of the C loop (about 0.1 s of work, at most 1024 output points)
    output : path of a results file (``.csv``, ``.h5``) written as the run goes (accepted steps
        or ``t_eval`` samples appended under ``status: running``), then complete
    raise_on_interrupt : re-raise KeyboardInterrupt after keeping the results
    closed_options : for a closed system only: ``formulation`` ("partitioned", "redundant",
        "penalty") and its options (:func:`jourdain.loops.simulate.simulate_closed`)

    Returns
    -------
    Results
        ``t`` (N,), ``y``, ``yd``, ``ydd`` (N, f), ``u`` (N, inputs), ``W`` (N,) the work of the
        generalized applied forces, ``events``, ``status`` and counters.

    Raises
    ------
    SingularMassMatrix
        ``M`` lost positive definiteness (the time and state are in the message).
    IntegrationError
        a NaN/inf in the state or a step size underflow (time and state in the message).
        Both carry the motion up to the failure as ``exc.results`` (C methods).
    EvaluationError
        bad arguments (wrong sizes, NaN initial values, unknown names).
    """
    if getattr(system, "is_general", False):  # velocity constraints (METHOD §7)
        from ..loops.general_sim import simulate_general

        if events or first_step is not None or closed_options:
            raise EvaluationError(f"{system.name}: events, first_step and the closed-loop "
                                  "options are not available for systems with velocity "
                                  "constraints yet")
        return simulate_general(system, t_span, y0, yd0, parameters=parameters,
                                inputs=inputs, method=method, rtol=rtol, atol=atol,
                                t_eval=t_eval, max_step=max_step,
                                progress=progress if callable(progress) else None,
                                output=output)
    if system.closing:  # a closed system moves on its constraint manifold (METHOD §7)
        from ..loops.simulate import simulate_closed

        return simulate_closed(system, t_span, y0, yd0, parameters=parameters, inputs=inputs,
                               method=method, rtol=rtol, atol=atol, t_eval=t_eval,
                               max_step=max_step, events=tuple(events), first_step=first_step,
                               progress=progress, output=output,
                               raise_on_interrupt=raise_on_interrupt, **closed_options)
    if closed_options:
        _tree_takes_no(system, closed_options)
    if getattr(system, "frictions", ()):  # friction forces fed back from the reactions
        from ..analysis.friction import friction_inputs  # with the analysis (issue 35)

        system, inputs = friction_inputs(system, inputs, parameters)
    f = system.f
    t0, t1 = check_t_span(t_span)
    x0 = _initial_state(y0, yd0, f, system)
    method, rtol, atol_x = checked_options(method, rtol, atol, 2 * f)
    max_step = check_max_step(max_step, t0, t1)
    if first_step is not None:
        first_step = _real(first_step, "first_step")
        if not (first_step > 0 and math.isfinite(first_step)):
            raise EvaluationError(f"first_step must be a positive number, got {first_step!r}")
    te = None if t_eval is None else check_t_eval(t_eval, t0, t1, f, len(system.inputs))
    if output is not None and not str(output).lower().endswith(OUTPUT_SUFFIXES):
        raise EvaluationError(f"output = {_shown(str(output))}: a results file ends in "
                              f"{', '.join(OUTPUT_SUFFIXES)}")
    # the problem and the results' constant fields, memoized per system and options
    template = run_template(system, parameters, inputs, events, method, rtol, atol_x,
                            max_step, first_step or 0.0)
    setup = template.setup
    integrator_library()  # built or loaded once per process, outside the timed run
    wall = time.perf_counter()
    if method in C_METHODS:
        run = _run_c(setup, t0, t1, x0, te, progress, output)
    else:
        run = _run_scipy(setup, method, t0, t1, x0, te, rtol, atol_x, max_step, first_step)
    run["wall_time"] = time.perf_counter() - wall
    res = _results(template, run)
    if output is not None:
        res.save(output)
    if run.get("error") is not None:
        # the motion up to the failure is kept on the exception (and in ``output``)
        run["error"].results = res
        raise run["error"]
    if res.interrupted and raise_on_interrupt and isinstance(run.get("exception"),
                                                             KeyboardInterrupt):
        raise run["exception"]
    return res


#: options of :func:`simulate` for closed systems only (:func:`jourdain.loops.simulate.simulate_closed`)
CLOSED_OPTIONS = frozenset({"formulation", "samples", "repartition", "cond_limit", "alpha",
                            "beta", "xi", "omega", "iterations"})


def _tree_takes_no(system: System, options: Mapping[str, Any]) -> None:
    """A tree given options of closed systems: an error naming them; any other keyword is
    misspelt, a TypeError as Python gives (never ignored)."""
    unknown = sorted(set(options) - CLOSED_OPTIONS)
    if unknown:
        raise TypeError(f"simulate() got an unexpected keyword argument {unknown[0]!r}")
    if options:
        raise EvaluationError(f"simulate: {', '.join(sorted(options))}: options of closed "
                              f"systems; {system.name!r} has no closing joints")


#: the work W at the start of a run (the state's last entry); the dtype of native doubles (a
#: singleton: compared by identity, where ``==`` converts its operand first)
_W0, _F8 = np.zeros(1), np.dtype(np.float64)


def _initial_state(y0: Any, yd0: Any, f: int, system: System) -> np.ndarray:
    """The initial state ``[y0, ẏ0, W = 0]`` from ``f`` finite numbers each. Vectors of f
    doubles are taken as they are when the sum of their entries is finite (NaN or inf wherever
    an entry is; summed as Python floats, which overflow to inf without NumPy's warning); any
    other argument, and a sum that overflows, go the long way, which forms the names of the
    coordinates for the message of a bad entry."""
    if (type(y0) is np.ndarray and type(yd0) is np.ndarray and y0.dtype is _F8
            and yd0.dtype is _F8 and y0.shape == yd0.shape == (f,)):
        x0 = np.concatenate((y0, yd0, _W0))
        if math.isfinite(sum(x0.tolist())):
            return x0
    names = system.coordinate_names
    return np.concatenate((_vector(y0, f, "y0", names),
                           _vector(yd0, f, "yd0", [f"{n}_d" for n in names]), _W0))


def _results(template: RunTemplate, run: dict) -> Results:
    setup = template.setup
    f = len(template.coordinate_names)
    t, x = run["t"], run["x"]
    U = template.inputs_at(t, x) if len(t) else np.zeros((0, len(template.input_names)))
    ydd = run.get("ydd")
    if ydd is not None and len(ydd) == len(t):  # from the C loop (NaN where M was singular)
        ydd = np.ascontiguousarray(ydd)
    else:
        ydd = accelerations(setup.mkq, x[:, :f], x[:, f:2 * f], t, setup.p, U)
    events: dict[str, dict[str, np.ndarray]] = {}
    if setup.events:
        found: dict[str, list[tuple[float, np.ndarray, np.ndarray]]] = {
            ev.label: [] for ev in setup.events}
        for tt, xx, k in zip(*run["events"], strict=True):
            found[setup.events[int(k)].label].append((float(tt), xx[:f].copy(),
                                                      xx[f:2 * f].copy()))
        events = {k: _event_arrays(v, f) for k, v in found.items()}
    # positional: binding two dozen keywords took 0.7 µs of a call's 20
    return Results(  # system, t, y, yd, ydd, u, W, parameters, method, rtol, atol, status,
        # message, nfev, nsteps, n_accepted, n_rejected, wall_time, events, exception,
        # coordinate_names, input_names, units, energies, name
        setup.system, t, x[:, :f].copy(), x[:, f:2 * f].copy(), ydd, U, x[:, 2 * f].copy(),
        dict(template.parameters), template.method, template.rtol, template.atol.copy(),
        run["status"], run["message"], run["nfev"], run["nstep"], run["naccept"],
        run["nreject"], run["wall_time"], events, run["exception"], template.coordinate_names,
        template.input_names, template.units, None, template.name)


def _event_arrays(items: list, f: int) -> dict[str, np.ndarray]:
    return {"t": np.array([i[0] for i in items]),
            "y": np.array([i[1] for i in items]).reshape(-1, f),
            "yd": np.array([i[2] for i in items]).reshape(-1, f)}


def accelerations(mkq: CompiledFunction, y: np.ndarray, yd: np.ndarray, t: np.ndarray,
                  p: np.ndarray, u: np.ndarray) -> np.ndarray:
    """``ÿ = M⁻¹(q - k)`` at many states (one batched evaluation, one batched solve)."""
    n, f = y.shape
    if n == 0:
        return np.zeros((0, f))
    out = mkq.batch(y, yd, t, p, u if u.shape[1] else None)
    M, k, q = out["M"], out["k"][:, :, 0], out["q"][:, :, 0]
    try:
        return np.linalg.solve(M, (q - k)[:, :, None])[:, :, 0]
    except np.linalg.LinAlgError:  # a singular state (kept by a failed run): NaN there
        ydd = np.full((n, f), np.nan)
        for i in range(n):
            try:
                ydd[i] = np.linalg.solve(M[i], q[i] - k[i])
            except np.linalg.LinAlgError:
                pass
        return ydd
