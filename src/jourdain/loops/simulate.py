"""Simulation of closed systems: :func:`simulate_closed` is what
:meth:`jourdain.System.simulate` and :func:`jourdain.simulate` call for a system with closing
joints; it returns the one :class:`jourdain.Results`. ``formulation`` picks the method:
"partitioned" (the default: coordinate partitioning on the constraint manifold, this module),
"redundant" (the index-1 Lagrange-multiplier form in all tree coordinates, with Baumgarte's
``alpha``, ``beta``) or "penalty" (the augmented-Lagrangian form, which passes singular
positions; ``alpha``, ``xi``, ``omega``, ``iterations``), both in
:mod:`jourdain.loops.redundant`.

The state is the independent ``(y, ẏ)`` (here ``z`` names the tree's coordinates, ``y`` the
independent ones); at every evaluation the dependent coordinates are solved by Newton on
``Φ(y, d, t) = 0`` (stopped by a backward error per row, independent of the units of length:
:meth:`LoopEvaluator.solve_positions`; warm-started from the last solution plus the
first-order prediction along the manifold) and the dependent rates from
``Φ̇ = 0`` by a linear solve with ``Φ_d``, so every reported state lies on the manifold to
rounding, whatever the integrator's error: the error of the integration is an error *along*
the manifold (in y), never a drift off it. ``ÿ`` comes from ``M(y, ẏ, t)·ÿ = q − k`` in the
independent coordinates.

**Engine.** By default (``engine="c"``) the whole right-hand side is one C function
(:mod:`jourdain.loops.compiled`: Newton, the LU of Φ_d and its condition number, ``J_z``, the
convective term, the tree's compiled ``M, k, q``, ``M = J_zᵀ M_tree J_z`` and Cholesky) that
jourdain's C integrator (DOP853, RK45, Radau IIA: :mod:`jourdain.numeric.integrator_c`) calls
through its ``jd_accel`` hook: no Python per step. The samples are evaluated on the manifold
by the same C code. ``engine="scipy"`` (and BDF, and inputs given as Python functions of time)
steps SciPy's integrators from Python with :class:`LoopEvaluator` (:mod:`.scipy_run`).
Measured side by side by ``python benchmarks/loops.py`` (four-bar, 5 s, DOP853, best of 3,
shared 2-core machine at load 5): the C engine took 1.8–3.1 ms at rtol 1e-8 and 1e-10
(errors 1.9e-7, 9.7e-10, |Φ| ≤ 1.1e-15), 140–150× less than the sympy + SciPy route with
dependent speeds at equal or larger error (2.7e-7, 3.4e-9) and 340–380× less than this
module's own SciPy engine.

Singular configurations: the 1-norm condition number of ``Φ_d`` (Hager's estimate from its
LU) is computed at every evaluation. When it has grown tenfold over its value at the partition
(``repartition=True``, the default) a new partition is chosen by pivoting at the last accepted
state and the run goes on in it (:mod:`.charts`); when it passes ``cond_limit`` (default 1e6)
and no better partition exists there — ``Φ_z`` itself has lost rank, a singular position of
the mechanism — or re-partitioning is off, the run stops with status "singular" and a
:class:`SingularConfiguration` naming the time, the state, the condition number, the rank of
``Φ_z`` and a partition that would serve (if any). The augmented-Lagrangian form
(``formulation="penalty"``) passes singular positions.

Why not SUNDIALS IDA (scikit-sundae) here, measured (``python benchmarks/loops.py``, the
four-bar of :func:`jourdain.models.loops.four_bar` over 5 s, on the shared 2-core development
machine): IDA 1.2.0 on the index-1 redundant form in (z, ż, λ), with jourdain's compiled tree
and constraints in its Python residual and its own finite-difference Jacobian, took 18.5 s at
rtol 1e-8 (error 1.2e-3, |Φ(5 s)| = 1.2e-4: the index-1 form lets the positions drift), against
milliseconds for coordinate partitioning at a smaller error; keeping IDA on the manifold would
need the index-2 (GGL) or projected form on top.
"""

from __future__ import annotations

import math
import signal
import sys
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np
import symengine as se

from ..errors import EvaluationError
from ..model import System
from ..numeric import CompiledFunction
from ..simulation.options import check_t_span, steps_per_call
from .c_run import C_METHODS, FAILED, Segment
from .charts import decide
from .closed_loop import (
    LoopEvaluator,
    SingularConfiguration,
)
from .compiled import REASONS, LoopKernel, build_loop_library_soon, input_function
from .redundant import _simulate_redundant_form
from .results import _input_values, _Run, _to_results
from .scipy_run import SOLVERS, run_scipy

_KEYS = ("z", "zd", "zdd", "Phi", "Phi_dot", "lam")


def _simulate_partitioned(loop: System, t_span: tuple[float, float], z0: Any,
                          zd0: Any = None, *, t_eval: Sequence[float] | None = None,
                          samples: int = 501, rtol: float = 1e-10, atol: float = 1e-12,
                          method: str = "DOP853",
                          parameters: Mapping[str, float] | None = None,
                          inputs: Callable[[float], Any] | Sequence[float] | Mapping[str, Any]
                          | None = None,
                          repartition: bool = True, cond_limit: float = 1e6,
                          max_step: float = math.inf, engine: str = "c",
                          progress: bool | Callable[[float, float], None] = False) -> _Run:
    """Integrate a closed-loop system from approximate ``z0, zd0`` (assembled first, the
    independent coordinates of the partition held) over ``t_span``.

    Returns the run's record (:class:`~jourdain.loops.results._Run`) at ``t_eval`` (default: ``samples`` equally spaced times).
    A singular configuration stops the run with ``status="singular"`` and the exception in
    ``singular`` (the results up to there are kept) unless a new partition resolves it.
    ``inputs``: constants (in the order of the tree's inputs), a mapping of input names to
    numbers or expressions of t and the parameters (compiled; the C engine evaluates them at
    every right-hand side), or a Python function of t (the SciPy engine).
    ``engine``: "c" (the compiled right-hand side in jourdain's C integrator; methods
    DOP853, RK45, Radau) or "scipy" (SciPy's steppers from Python; also BDF).
    """
    t0, t1 = check_t_span(t_span)
    if not cond_limit > 1:
        raise EvaluationError(f"cond_limit must be > 1, got {cond_limit}")
    if method not in SOLVERS:
        raise EvaluationError(f"method must be one of {', '.join(SOLVERS)}, got {method!r}")
    if engine not in ("c", "scipy"):
        raise EvaluationError(f'engine must be "c" or "scipy", got {engine!r}')
    c_engine = engine == "c" and method in C_METHODS and not callable(inputs)
    if c_engine:  # the loop kernel compiled while the tree's functions are
        build_loop_library_soon(loop)
    fn_u = input_function(loop, inputs) if isinstance(inputs, Mapping) else None
    u_of = _input_values(loop, inputs, fn_u, parameters)
    ev = LoopEvaluator(loop, z0, t0, parameters, u_of(t0))
    asm = ev.assemble(z0, zd0, t0)
    tev = (np.linspace(t0, t1, samples) if t_eval is None
           else np.asarray(t_eval, dtype=float))
    if tev.size and (tev[0] < t0 or tev[-1] > t1 or np.any(np.diff(tev) <= 0)):
        raise EvaluationError("t_eval must increase within t_span")
    started = time.perf_counter()
    ind = list(ev.part.independent)
    x = np.concatenate([asm.z[ind], asm.zd[ind]])
    if c_engine:
        run = _run_c(ev, t0, t1, x, tev, method, rtol, atol, max_step, repartition, cond_limit,
                     fn_u, progress)
        run_method = method
    else:
        run = run_scipy(ev, t0, t1, x, tev, method, rtol, atol, max_step, u_of, repartition,
                        cond_limit)
        run_method = f"scipy:{method}"
    out = run["out"]
    n, m = loop.tree.f, len(ev.labels)

    def arr(k: str, w: int) -> np.ndarray:
        return np.array(out[k]).reshape(-1, w) if len(out[k]) else np.zeros((0, w))
    return _Run(
        loop, np.array(out["t"], dtype=float), arr("z", n), arr("zd", n), arr("zdd", n),
        arr("Phi", m), arr("Phi_dot", m), arr("lam", m), list(ev.labels), run["partitions"],
        run["status"],
        run["message"], run["nfev"], time.perf_counter() - started, run["singular"],
        dict(zip([k for k, _ in loop.tree.parameters], ev.p.tolist(), strict=True)),
        run_method, run.get("steps", (0, 0, 0)))


def _run_c(ev: LoopEvaluator, t0: float, t1: float, x: np.ndarray, tev: np.ndarray,
           method: str, rtol: float, atol: float, max_step: float, repartition: bool,
           cond_limit: float, fn_u: CompiledFunction | None = None,
           progress: bool | Callable[[float, float], None] = False) -> dict:
    """The C integrator with the compiled loop right-hand side, segment by segment (a new
    segment after each change of partition), each in calls of a bounded number of steps:
    between them ``progress`` (True: a line on stderr every 0.5 s; a callable gets ``(t,
    t1)``) and Ctrl-C, which stops the run with ``status="interrupted"`` and keeps the
    samples computed so far (a second Ctrl-C raises at once)."""
    interrupted = [False]
    last_report = [time.perf_counter()]

    def on_sigint(signum: int, frame: Any) -> None:
        if interrupted[0]:
            raise KeyboardInterrupt
        interrupted[0] = True

    def on_chunk(t_now: float) -> None:
        if interrupted[0]:
            raise KeyboardInterrupt
        if callable(progress):
            progress(t_now, t1)
        elif progress and time.perf_counter() - last_report[0] > 0.5:
            last_report[0] = time.perf_counter()
            print(f"\rsimulating {ev.loop.name}: t = {t_now:.4g} of {t1:.4g} "
                  f"({100 * (t_now - t0) / (t1 - t0):.0f} %)", end="", file=sys.stderr)

    old_handler = None
    if threading.current_thread() is threading.main_thread():
        try:
            old_handler = signal.signal(signal.SIGINT, on_sigint)
        except ValueError:  # not the main interpreter
            old_handler = None
    try:
        run = _run_segments(ev, t0, t1, x, tev, method, rtol, atol, max_step, repartition,
                            cond_limit, fn_u, on_chunk)
    finally:
        if old_handler is not None:
            signal.signal(signal.SIGINT, old_handler)
    if progress is True:
        print(file=sys.stderr)
    return run


def _run_segments(ev: LoopEvaluator, t0: float, t1: float, x: np.ndarray, tev: np.ndarray,
                  method: str, rtol: float, atol: float, max_step: float, repartition: bool,
                  cond_limit: float, fn_u: CompiledFunction | None,
                  on_chunk: Callable[[float], None]) -> dict:
    """The segments of :func:`_run_c`."""
    kernel = LoopKernel(ev)
    kernel.set_inputs(fn_u)
    kernel.z[:] = ev.z_guess
    out: dict[str, list] = {k: [] for k in ("t", *_KEYS)}
    partitions = [(t0, tuple(ev.independent_names))]
    status, message = "finished", "the integration reached t_end"
    singular: SingularConfiguration | None = None
    nfev, i_eval, t = 0, 0, t0
    steps = np.zeros(3, dtype=int)  # steps, accepted, rejected (the integrator's counters)
    state = np.concatenate([x, [0.0]])  # [y, ẏ, W]
    mark = math.nan  # Φ_d's condition number at the partition (nan: measure it)
    while i_eval < tev.size:
        f = ev.part.f
        if math.isnan(mark):
            kernel.set_cond_limit(np.inf)
            kernel.samples(np.array([t]), state[None, :2 * f])
            mark = max(kernel.cond, 10.0)
        kernel.set_cond_limit(min(cond_limit, 10 * mark) if repartition else cond_limit)
        seg = Segment(f, kernel.ev.u, kernel.tree.address, kernel.state_address,
                      kernel.accel_address, t, state, tev[i_eval:], C_METHODS[method], rtol,
                      atol, max_step)
        seg.atol[-1] = 1e300  # W out of the error norm: in joules it made the steps depend on
        # the length unit (the results integrate W over the samples)
        z_start, y_start = kernel.z.copy(), state[:f].copy()
        stop = False
        try:
            code = seg.run(t1, steps_per_call(f), on_chunk)
        except KeyboardInterrupt:  # between two calls: the samples so far are consistent
            code, stop = 0, True
        nfev += int(seg.cnt[0])
        steps += np.asarray(seg.cnt[1:4], dtype=int)
        # before the samples overwrite them: why it stopped and where (a trial state)
        reason, c_now, z_fail = int(kernel.info[2]), kernel.cond, kernel.z.copy()
        k = int(seg.n_out[0])
        if k:  # the samples, followed from the segment's start
            kernel.restart(z_start, y_start)
            _record(out, kernel, seg.out_t[:k], seg.out_x[:k, :2 * f])
            i_eval += k
        if stop:
            t_last = out["t"][-1] if out["t"] else t
            status = "interrupted"
            message = (f"interrupted by the user (Ctrl-C) at t = {t_last:.9g}; the motion up "
                       "to there is kept")
            break
        if code == 0:
            break
        t, state = float(seg.st[0]), seg.x.copy()
        if code != -1:
            status = "failed"
            message = (f"the integration failed at t = {seg.fail[0]:.9g}: "
                       f"{FAILED.get(code, f'code {code}')}")
            break
        # Newton's start at the last accepted state: the last sample (or the segment's start;
        # the failed evaluation may have left the kernel's configuration anywhere)
        ev.z_guess = kernel.z.copy() if k else z_start
        ev._last = None
        if reason == 2:
            d = decide(ev, t, state, c_now, repartition, cond_limit, z_fail, float(seg.fail[0]))
            if d.action == "switch":
                assert d.partition is not None and d.z is not None and d.zd is not None
                ev.set_partition(d.partition)
                kernel.set_partition(d.partition)
                kernel.restart(d.z, d.z[list(d.partition.independent)])
                partitions.append((t, tuple(ev.independent_names)))
                ind = list(d.partition.independent)
                state = np.concatenate([d.z[ind], d.zd[ind], state[-1:]])
                mark = math.nan
                continue
            if d.action == "continue":  # no better partition here: watch for more
                mark = d.cond
                assert d.z is not None
                kernel.restart(d.z, state[:f])
                continue
            singular = d.singular or SingularConfiguration(
                f"{ev.loop.name}: singular configuration at t = {t:.9g}: the condition "
                f"number of Φ_d reached {c_now:.3g}", t=t, cond=c_now)
        else:
            singular = SingularConfiguration(
                f"{ev.loop.name}: at t ≈ {seg.fail[0]:.9g} (last accepted state t = {t:.9g}, "
                f"independent {', '.join(ev.independent_names)}): {REASONS.get(reason, reason)}",
                t=float(seg.fail[0]), z=kernel.z.copy(), cond=c_now)
        status, message = "singular", str(singular)
        break
    return {"out": out, "partitions": partitions, "status": status, "message": message,
            "singular": singular, "nfev": nfev, "steps": tuple(int(k) for k in steps)}


def _record(out: dict[str, list], kernel: LoopKernel, t: np.ndarray, x: np.ndarray) -> None:
    """Samples at ``t`` of the states ``x = [y, ẏ]`` on the manifold (C); the energies are
    the results' (:class:`jourdain.Results`, from the tree's kinematics)."""
    s, bad = kernel.samples(t, x)
    if bad >= 0:  # a sample off the manifold's reach (at a singular position): cut there
        t = t[:bad]
        s = {k: v[:bad] for k, v in s.items()}
    out["t"].extend(t.tolist())
    for k in _KEYS:
        out[k].extend(s[k])


#: the formulations of :func:`simulate_closed` and the options each takes (their defaults)
FORMULATIONS: dict[str, dict[str, float]] = {
    "partitioned": {},
    "redundant": {"alpha": 0.0, "beta": 0.0},
    "penalty": {"alpha": 1e7, "xi": 1.0, "omega": 30.0, "iterations": 4},
}


def simulate_closed(system: System, t_span: tuple[float, float], y0: Any, yd0: Any = None,
                    parameters: Mapping[str, float] | None = None,
                    inputs: Mapping[str, Any] | Sequence[float] | Callable[[float], Any]
                    | None = None, method: str = "DOP853", rtol: float = 1e-8,
                    atol: Any = 1e-10, t_eval: Sequence[float] | None = None,
                    max_step: float = math.inf, samples: int = 501,
                    repartition: bool = True, cond_limit: float = 1e6,
                    **options: Any) -> Any:
    """:meth:`jourdain.System.simulate` of a closed system: its motion as
    :class:`jourdain.Results` with the tree's coordinates ``y`` and the closing rows in
    :attr:`Results.constraints` (``labels``, ``Phi``, ``Phi_dot``, ``multipliers``,
    ``partitions``, ``singular``).

    ``formulation``:

    * "partitioned" (default): coordinate partitioning, every sample on ``Φ = 0`` to rounding;
      ``repartition``, ``cond_limit`` as in the module's docs.
    * "redundant": all tree coordinates with ``ÿ`` and ``λ`` from the bordered (index-1)
      system, Baumgarte's stabilization ``alpha``, ``beta`` (default 0, 0: none); Φ drifts
      with the integration error and is reported as it is. SciPy's steppers.
    * "penalty": the augmented-Lagrangian form (Bayo & Ledesma), which passes singular
      positions: ``alpha`` (penalty, 1e7), ``xi`` (1.0), ``omega`` (30.0), ``iterations``
      (4); its C right-hand side in jourdain's C integrator, or SciPy's with
      ``method="scipy:<method>"``.

    The redundant forms take no inputs yet (a :class:`jourdain.errors.ClosedSystemError`
    names them) and no partition (``partitions`` is ``[(t0, ())]``).

    ``method``: "DOP853", "RK45", "Radau" (jourdain's C integrator with the compiled loop
    right-hand side), "BDF", "LSODA" or "scipy:<method>" (SciPy's steppers). ``t_eval``
    default: ``samples`` equally spaced times. ``progress`` and Ctrl-C as for trees (the C
    methods of the partitioned form: the step loop runs in bounded calls; an interrupted run
    keeps its motion so far, ``status="interrupted"``); ``output``: the results file, written
    when the run ends or is interrupted (not sample by sample as a tree's run writes it).
    Options of tree runs that closed systems do not take yet (``events``, ``first_step``)
    raise :class:`jourdain.errors.ClosedSystemError` naming them.
    """
    from ..errors import ClosedSystemError

    formulation = options.pop("formulation", "partitioned")
    if formulation not in FORMULATIONS:
        raise EvaluationError(f"formulation must be one of "
                              f"{', '.join(repr(k) for k in FORMULATIONS)}, got "
                              f"{formulation!r}")
    own = {k: options.pop(k) for k in FORMULATIONS[formulation] if k in options}
    stray = sorted({k for opts in FORMULATIONS.values() for k in opts if k in options})
    if stray:
        takers = {k: [f for f, o in FORMULATIONS.items() if k in o] for k in stray}
        raise EvaluationError("; ".join(
            f"simulate(..., {k}=...) is an option of formulation "
            f"{' and '.join(repr(f) for f in takers[k])}, not of {formulation!r}"
            for k in stray))
    progress = options.pop("progress", False)
    output = options.pop("output", None)
    raise_on_interrupt = bool(options.pop("raise_on_interrupt", False))
    misspelt = sorted(set(options) - {"events", "first_step"})
    if misspelt:  # as Python says it, and as a tree's run does (never ignored)
        raise TypeError(f"simulate() got an unexpected keyword argument {misspelt[0]!r}")
    unknown = {k: v for k, v in options.items() if v not in (None, ())}
    if unknown:
        raise ClosedSystemError(system, f"simulate(..., {', '.join(sorted(unknown))}=...) "
                                "is not available for closed systems yet")
    engine = "c"
    if method.startswith("scipy:"):
        engine, method = "scipy", method.split(":", 1)[1]
    elif method not in C_METHODS:
        engine = "scipy"
    if isinstance(inputs, Mapping) and inputs and not all(
            isinstance(v, int | float | str | se.Basic) for v in inputs.values()):
        raise ClosedSystemError(system, "inputs given as tables or Python functions in a "
                                "mapping are not available for closed systems yet (give "
                                "numbers or expressions of t, or one function of t)")
    if formulation == "partitioned":
        lr = _simulate_partitioned(system, t_span, y0, yd0, t_eval=t_eval, samples=samples,
                                   rtol=rtol, atol=atol, method=method,
                                   parameters=parameters, inputs=inputs,
                                   repartition=repartition, cond_limit=cond_limit,
                                   max_step=max_step, engine=engine, progress=progress)
    else:
        lr = _simulate_redundant_form(system, formulation, t_span, y0, yd0, own, engine,
                                      t_eval=t_eval, samples=samples, rtol=rtol, atol=atol,
                                      method=method, parameters=parameters, inputs=inputs,
                                      max_step=max_step)
    res = _to_results(system, lr, parameters, inputs, rtol, atol)
    if output is not None:  # at the end, or with the motion so far when interrupted
        res.save(output)
    if res.interrupted and raise_on_interrupt:
        raise KeyboardInterrupt(res.message)
    return res


__all__ = ["C_METHODS", "FORMULATIONS", "SOLVERS", "simulate_closed"]
