"""The study's compiled model in a worker: :class:`Context`, built once per study and process.

A worker builds its :class:`Context` once per study and process (:func:`context`): the model
rebuilt from the study's copy of the model file (its SHA-256 checked), derived and compiled
once (the compiled libraries come from the on-disk cache of :mod:`jourdain.numeric` when
another process built them; their content keys are compared with the ones the study started
with). A block of cases then only evaluates numbers (:mod:`jourdain.study.compute`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import JourdainError
from ..pipeline.system import tree_linearization
from .spec import StudyError, StudySpec

__all__ = ["EQUILIBRIUM", "FAILURES", "Context", "case_arrays", "context", "forget_contexts", "record_errors"]

#: the errors of one case that are recorded (its outputs NaN) instead of stopping the block
FAILURES = (JourdainError, ArithmeticError, ValueError, np.linalg.LinAlgError)


@dataclass(eq=False)
class Context:
    """What a worker needs for the cases of one study (built once per process)."""

    spec: StudySpec
    model: Any
    system: Any
    p0: np.ndarray
    y0: np.ndarray
    yd0: np.ndarray
    cases: np.ndarray
    keys: dict[str, str]
    dynamics: Any = None
    linearization: Any = None
    compiled_linearization: Any = None
    cyclic: tuple[str, ...] = ()
    bounds: Any = None
    #: the runs of ``simulate``, advanced together (None: one run per case)
    ensemble: Any = None
    #: the parameters the bodies' mass data and joints use (found on first use)
    body_parameters: frozenset[str] | None = None
    #: problems of the model's numbers found so far, by the values of the parameters the
    #: bodies and joints use ("" where the values passed the checks)
    checked: dict[tuple[float, ...], str] = field(default_factory=dict)
    #: a closed system (closing joints): linearized per case by
    #: :func:`jourdain.loops.nominal.linearize_closed`, simulated per case by its own
    #: ``simulate`` (never the open tree)
    closed: bool = False
    #: the independent coordinates of a closed system's linearization (its modes: 2 per name)
    independent: tuple[str, ...] = ()
    #: a closed system's nominal state at a case's parameters (None: the equilibrium nearest
    #: the case's initial configuration, ``about = "equilibrium"``)
    nominal_state: Any = None

    @property
    def f_linear(self) -> int:
        """Coordinates of the linearization: the system's, or a closed system's independent
        ones."""
        return len(self.independent) if self.closed else self.system.f

    @property
    def parameter_names(self) -> list[str]:
        return [k for k, _ in self.system.parameters]


_CONTEXTS: dict[str, Context] = {}


def context(spec: StudySpec) -> Context:
    """The study's :class:`Context` in this process (built on first use, then reused)."""
    import hashlib

    # every block: the model text that came with it must be the one the study hashed
    if hashlib.sha256(spec.model_text.encode()).hexdigest() != spec.model_hash:
        raise StudyError(f"{spec.model_path}: the model's text does not match the study's model "
                         "hash", spec.filename)
    ctx = _CONTEXTS.get(spec.spec_hash)
    if ctx is None:
        _CONTEXTS.clear()  # one study at a time per worker: its compiled model, not all
        ctx = _build(spec)
        _CONTEXTS[spec.spec_hash] = ctx
    return ctx


def forget_contexts() -> None:
    """Drop this process's contexts (a fresh worker rebuilds its model from the study)."""
    _CONTEXTS.clear()


def _build(spec: StudySpec) -> Context:
    from ..io.capabilities import nominal_mapping
    from ..io.modelfile import loads_model

    model = loads_model(spec.model_text, spec.model_path)
    system = model.system
    f = system.f
    sim = model.simulation
    y0 = np.array(sim.y0, dtype=float) if sim.y0 else np.zeros(f)
    yd0 = np.array(sim.yd0, dtype=float) if sim.yd0 else np.zeros(f)
    p0 = np.array([v for _, v in system.parameters], dtype=float)
    ctx = Context(spec, model, system, p0, y0, yd0, spec.cases(), {})
    comp = spec.compute
    if system.is_closed:
        _refuse_closed(spec, system)
    if system.frictions and {"evaluate", "frequency_response"} & set(comp):
        raise StudyError(f"{spec.filename}: joint friction "
                         f"({', '.join(fr.name for fr in system.frictions)}) is solved with the "
                         "reactions at every state: a study computes [compute.simulate] (one "
                         "run per case) for it, not evaluate or frequency_response",
                         spec.filename)
    if "evaluate" in comp:
        from ..numeric import dynamics_function

        ctx.dynamics = dynamics_function(system)
        ctx.keys["evaluate"] = ctx.dynamics.key
    abouts = {comp[k]["about"] for k in ("linearize", "critical", "frequency_response")
              if k in comp}
    if len(abouts) > 1:
        raise StudyError(f"{spec.filename}: linearize, critical and frequency_response must be "
                         f"about the same nominal motion, got {sorted(abouts)}", spec.filename)
    about = next(iter(abouts), None)
    if system.is_closed:
        _closed(ctx, about)
    elif about is not None:
        from ..analysis.modes import _cyclic_of

        lin = tree_linearization(system.linearize(nominal_mapping(system,
                                                                  model.nominal_motion(about))))
        if not lin.is_time_invariant:
            raise StudyError(f'{spec.filename}: the linearization about "{about}" is '
                             f"time-variant ({', '.join(lin.time_dependence)} depend on t): "
                             "no eigenvalue verdict", spec.filename)
        ctx.linearization = lin
        ctx.compiled_linearization = lin.compile()
        ctx.keys["linearize"] = ctx.compiled_linearization.function.key
        ctx.cyclic = tuple(_cyclic_of(lin))
    if "critical" in comp:
        import symengine as se

        c = comp["critical"]
        syms = list(system.parameter_symbols)
        exprs = []
        for k in ("lower", "upper"):
            v = c[k]
            if isinstance(v, str):
                from ..io.expressions import parse_expression

                exprs.append(parse_expression(v, names=set(ctx.parameter_names)))
            else:
                exprs.append(se.Float(v))
        ctx.bounds = se.Lambdify(syms, exprs, real=True)
    if "simulate" in comp and not ctx.closed and not system.frictions:
        # a closed system's runs, and those with joint friction, are one System.simulate per
        # case (the ensemble driver runs the tree's compiled equations only)
        ctx.ensemble = _ensemble(ctx)
    return ctx


#: ``about`` of a closed system's linearization: the equilibrium nearest each case's initial
#: configuration (the default where the model has no nominal motion)
EQUILIBRIUM = "equilibrium"


def _refuse_closed(spec: StudySpec, system: Any) -> None:
    """What a study cannot compute for a closed system: a ClosedSystemError naming it."""
    from ..errors import ClosedSystemError

    for what, capability in (
            ("evaluate", "the study's [compute.evaluate] (M, k, q, ÿ and joint wrenches of a "
             "block in one C call of the open tree's equations)"),
            ("frequency_response", "the study's [compute.frequency_response] (frequency "
             "responses of the linearization in the independent coordinates)")):
        if what in spec.compute:
            raise ClosedSystemError(system, f"{capability} is not available for closed "
                                    "systems yet", "compute [compute.linearize], "
                                    "[compute.critical] or [compute.simulate], or call "
                                    "system.evaluate per case")


def _closed(ctx: Context, about: str | None) -> None:
    """A closed system's context: no batched C evaluation (its M, k, q come from the
    manifold, per case); what the study cannot do for it raises ClosedSystemError naming the
    capability."""
    from ..errors import ClosedSystemError
    from ..loops.closed_loop import LoopEvaluator

    system = ctx.system
    ctx.closed = True
    if system.is_general:  # velocity constraints: η and its cyclic ones from the nominal
        _general(ctx, about)
        return
    # the partition at the initial configuration: the linearization's coordinates
    ev = LoopEvaluator(system, ctx.y0, 0.0, None)
    ctx.independent = tuple(ev.independent_names)
    if about is not None and about != EQUILIBRIUM:
        import symengine as se

        nominal = ctx.model.nominal_motion(about)
        t = se.Symbol("t")
        exprs = [*nominal.y, *nominal.yd]
        if any(t in se.sympify(e).free_symbols for e in exprs) or nominal.inputs:
            raise ClosedSystemError(system, f'the nominal motion "{about}" depends on t or has '
                                    "nominal inputs: a closed system's study is linearized "
                                    "about a state (numbers in the parameters)",
                                    f'use about = "{EQUILIBRIUM}" or a constant state')
        ctx.nominal_state = se.Lambdify(list(system.parameter_symbols), exprs, real=True)


def _general(ctx: Context, about: str | None) -> None:
    """A general system's context (velocity constraints): linearized per case about the
    model's steady motion (numbers in the parameters) by
    :func:`jourdain.loops.general_linear.linearize_general`; η, its cyclic coordinates
    and the nominal state's expressions from the linearization at the default parameters."""
    import symengine as se

    from ..errors import ClosedSystemError
    from ..loops.general_linear import linearize_general

    system = ctx.system
    if about is None:
        return
    if about == EQUILIBRIUM:
        raise ClosedSystemError(system, "a study of a system with velocity constraints is "
                                "linearized about the model's steady motion",
                                "give about = \"<nominal name>\"")
    nominal = ctx.model.nominal_motion(about)
    exprs = [*nominal.y, *nominal.yd]
    if any(se.Symbol("t") in se.sympify(e).free_symbols for e in exprs) or nominal.inputs:
        raise ClosedSystemError(system, f'the nominal motion "{about}" depends on t or has '
                                "nominal inputs: a general system's study is linearized about "
                                "a steady state (numbers in the parameters)")
    ctx.nominal_state = se.Lambdify(list(system.parameter_symbols), exprs, real=True)
    v = np.asarray(ctx.nominal_state(ctx.p0), dtype=float).reshape(-1)
    lin = linearize_general(system, state_mapping(system, v))
    ctx.independent = tuple(lin.names)
    ctx.cyclic = tuple(lin.cyclic_in_eta)


def state_mapping(system: Any, v: np.ndarray) -> dict[str, float]:
    """The nominal state ``v = (y, ẏ)`` as ``{coordinate: value, "<coordinate>_d": rate}``."""
    f = system.f
    coords = system.coordinate_names
    return {**dict(zip(coords, v[:f].tolist(), strict=True)),
            **{f"{c}_d": x for c, x in zip(coords, v[f:].tolist(), strict=True)}}


def _ensemble(ctx: Context) -> Any:
    """The study's runs as an :class:`~jourdain.study.ensemble.Ensemble`, where its settings
    allow (``ensemble = false`` in ``[compute.simulate]`` asks for one run per case)."""
    from .ensemble import Ensemble

    s = ctx.spec.compute["simulate"]
    inputs = dict(ctx.model.simulation.inputs) or None
    if not s.get("ensemble", True) or not Ensemble.supports(s["method"], inputs):
        return None
    return Ensemble(ctx.system, (0.0, s["t_end"]), np.linspace(0.0, s["t_end"], s["samples"]),
                    inputs=inputs, method=s["method"], rtol=s["rtol"], atol=s["atol"])


def case_arrays(ctx: Context, start: int, stop: int
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Parameters (n, n_p), initial coordinates and rates (n, f) of cases ``start:stop``."""
    n = stop - start
    P = np.tile(ctx.p0, (n, 1))
    Y = np.tile(ctx.y0, (n, 1))
    YD = np.tile(ctx.yd0, (n, 1))
    names = ctx.parameter_names
    coords = ctx.system.coordinate_names
    vals = ctx.cases[start:stop]
    for j, v in enumerate(ctx.spec.varied):
        if v.kind == "parameter":
            P[:, names.index(v.name)] = vals[:, j]
        elif v.kind == "y0":
            Y[:, coords.index(v.name)] = vals[:, j]
        else:
            YD[:, coords.index(v.name[:-2])] = vals[:, j]
    return P, Y, YD


def record_errors(errors: list[str], idx: np.ndarray, errs: Mapping[int, str], what: str) -> None:
    for i, msg in errs.items():
        k = int(idx[i])
        errors[k] = f"{errors[k]}; {what}: {msg}" if errors[k] else f"{what}: {msg}"

