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
from .spec import StudyError, StudySpec

__all__ = ["FAILURES", "Context", "case_arrays", "context", "forget_contexts", "record_errors"]

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
    if about is not None:
        from ..analysis.modes import _cyclic_of

        lin = system.linearize(nominal_mapping(system, model.nominal_motion(about)))
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
    if "simulate" in comp:
        ctx.ensemble = _ensemble(ctx)
    return ctx


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

