"""The work of a study: one block of cases at a time, batched where it pays.

:func:`compute_block` computes cases ``start:stop`` of a study in the worker's
:class:`~jourdain.study.context.Context` (the model derived and compiled once per process):

- ``evaluate``: M, k, q (and ÿ, joint wrenches) of all cases of the block in one C call
  (:mod:`jourdain.study.motion`);
- ``linearize``, ``frequency_response``, ``critical``: M̃, P, Q, h of all cases in one C call,
  stacked solves and eigenvalues (:mod:`jourdain.study.linear`);
- ``simulate``: the block's runs advanced together, up to 64 per C call
  (:mod:`jourdain.study.ensemble`), bit for bit the per-case runs.

A case that fails records its error (a string) and NaN outputs; it never stops the block.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from .context import FAILURES, Context, case_arrays, context, record_errors
from .linear import (
    ASYMPTOTICALLY_STABLE_CODE,
    MARGINALLY_STABLE_CODE,
    UNSTABLE_CODE,
    VERDICTS,
    analyse,
    critical,
    frequency_responses,
    linearization_numbers,
)
from .motion import evaluate_block, simulate_block
from .spec import StudyError, StudySpec

__all__ = ["ASYMPTOTICALLY_STABLE_CODE", "Context", "MARGINALLY_STABLE_CODE",
           "UNSTABLE_CODE", "VERDICTS", "WRENCH_COMPONENTS", "case_arrays", "compute_block",
           "context", "output_layout"]

WRENCH_COMPONENTS = ("F_x", "F_y", "F_z", "T_x", "T_y", "T_z")


def output_layout(ctx: Context) -> dict[str, tuple[tuple[str, ...], tuple[int, ...], str]]:
    """Every output of one case: name -> (dimension names, shape, dtype)."""
    system, comp = ctx.system, ctx.spec.compute
    f = system.f
    out: dict[str, tuple[tuple[str, ...], tuple[int, ...], str]] = {}
    if "evaluate" in comp:
        e = comp["evaluate"]
        for name in e["outputs"]:
            if name == "M":
                out["evaluate_M"] = (("coordinate", "coordinate_j"), (f, f), "f8")
            else:
                out[f"evaluate_{name}"] = (("coordinate",), (f,), "f8")
        for j in e["reactions"]:
            out[f"wrench_{j}"] = (("wrench_component",), (6,), "f8")
    if "linearize" in comp:
        fl = ctx.f_linear  # a closed system's: its independent coordinates
        out["eigenvalue_real"] = (("mode",), (2 * fl,), "f8")
        out["eigenvalue_imag"] = (("mode",), (2 * fl,), "f8")
        out["max_real_part"] = ((), (), "f8")
        out["verdict"] = ((), (), "i1")
        if ctx.closed:  # the configuration (tree coordinates) each case was linearized about
            out["linearized_about"] = (("coordinate",), (f,), "f8")
    if "critical" in comp:
        out[f"critical_{comp['critical']['parameter']}"] = ((), (), "f8")
    if "frequency_response" in comp:
        fr = comp["frequency_response"]
        m = len(system.inputs) if fr["excitation"] == "inputs" else f
        shape = (len(fr["omega"]), f, m)
        out["frf_magnitude"] = (("omega", "coordinate", "excitation"), shape, "f8")
        out["frf_phase"] = (("omega", "coordinate", "excitation"), shape, "f8")
    if "simulate" in comp:
        s = comp["simulate"]
        if s["final"]:
            out["final"] = (("state",), (2 * f,), "f8")
        for n in s["max"]:
            out[f"max_{n}"] = ((), (), "f8")
        for n in s["max_abs"]:
            out[f"max_abs_{n}"] = ((), (), "f8")
        for n in s["series"]:
            out[f"series_{n}"] = (("time",), (s["samples"],), "f8")
        if ctx.closed:  # max |Φ| and max |Φ̇| of the closing rows along the run
            out["closure_residual"] = ((), (), "f8")
            out["closure_rate_residual"] = ((), (), "f8")
    return out


def _empty(layout: Mapping[str, tuple[tuple[str, ...], tuple[int, ...], str]], n: int
           ) -> dict[str, np.ndarray]:
    return {k: (np.full((n, *shape), -1, dtype=dt) if dt == "i1"
                else np.full((n, *shape), np.nan)) for k, (_, shape, dt) in layout.items()}


def compute_block(spec: StudySpec, start: int, stop: int,
                  keys: Mapping[str, str] | None = None) -> dict[str, Any]:
    """Compute cases ``start:stop`` of ``spec``; returns ``{"start", "stop", "outputs" (name ->
    array (n, ...)), "errors" (n strings, "" where the case succeeded)}``.

    ``keys``: the content keys of the compiled functions the study started with; a worker whose
    own differ (another jourdain, another model) refuses the block with a :class:`StudyError`.
    """
    ctx = context(spec)
    if keys is not None and dict(keys) != ctx.keys:
        raise StudyError(f"{spec.model_path}: this worker compiled another model (keys "
                         f"{ctx.keys}, the study's {dict(keys)}): different jourdain versions?",
                         spec.filename)
    n = stop - start
    out = _empty(output_layout(ctx), n)
    errors = [""] * n
    P, Y, YD = case_arrays(ctx, start, stop)
    ok = _check_parameters(ctx, P, errors)
    comp = spec.compute
    if "evaluate" in comp:
        evaluate_block(ctx, P, Y, YD, ok, out, errors)
    if "linearize" in comp or "frequency_response" in comp:
        idx = np.flatnonzero(ok)
        # M̃, P, Q, B of the cases: one C call for both outputs
        nums = linearization_numbers(ctx, P[idx], Y[idx]) if idx.size else None
    if "linearize" in comp:
        lam, maxre, verdict, errs = analyse(ctx, P[idx], nums, Y[idx])
        if ctx.closed and nums is not None:
            out["linearized_about"][idx] = nums["y_s"]
        out["eigenvalue_real"][idx] = lam.real
        out["eigenvalue_imag"][idx] = lam.imag
        out["max_real_part"][idx] = maxre
        out["verdict"][idx] = verdict
        record_errors(errors, idx, errs, "linearize")
    if "critical" in comp:
        idx = np.flatnonzero(ok)
        crit, errs = critical(ctx, P[idx], Y[idx])
        out[f"critical_{comp['critical']['parameter']}"][idx] = crit
        record_errors(errors, idx, errs, "critical")
    if "frequency_response" in comp:
        mag, phase, errs = frequency_responses(ctx, P[idx], nums)
        out["frf_magnitude"][idx] = mag
        out["frf_phase"][idx] = phase
        record_errors(errors, idx, errs, "frequency_response")
    if "simulate" in comp:
        simulate_block(ctx, P, Y, YD, ok, out, errors)
    return {"start": start, "stop": stop, "outputs": out, "errors": errors}


def _check_parameters(ctx: Context, P: np.ndarray, errors: list[str]) -> np.ndarray:
    """The model's checks of its numbers (mass data, joint axes) at every case's parameters;
    False where they fail (the error recorded). Each distinct combination of the parameters
    the bodies and joints use is checked once."""
    from ..model.bodies import check_values

    ok = np.ones(len(P), dtype=bool)
    names = ctx.parameter_names
    if ctx.body_parameters is None:  # once per context: a walk over every body's expressions
        ctx.body_parameters = frozenset(_body_names(ctx.system))
    used = ctx.body_parameters & {v.name for v in ctx.spec.varied if v.kind == "parameter"}
    if not used:
        return ok
    cols = [names.index(n) for n in names if n in used]
    if len(cols) == 1:  # one parameter: the 1-D unique, 8× faster than by rows
        values, inverse = np.unique(P[:, cols[0]], return_inverse=True)
        combos = values[:, None]
    else:
        combos, inverse = np.unique(P[:, cols], axis=0, return_inverse=True)
    base = ctx.p0.tolist()
    for c, row in enumerate(combos):
        key = tuple(row.tolist())
        problem = ctx.checked.get(key)
        if problem is None:
            vals = dict(zip(names, base, strict=True))
            vals.update({names[j]: float(x) for j, x in zip(cols, row, strict=True)})
            try:
                check_values(ctx.system.bodies, vals)
                problem = ""
            except FAILURES as exc:
                problem = f"parameters: {exc}"
            if len(ctx.checked) < 100_000:
                ctx.checked[key] = problem
        if problem:
            for i in np.flatnonzero(inverse.reshape(-1) == c):
                ok[i] = False
                errors[i] = problem
    return ok


def _body_names(system: Any) -> set[str]:
    """Names of the symbols in the bodies' mass data and joints (what check_values reads)."""
    import dataclasses

    import symengine as se

    out: set[str] = set()
    stack: list[Any] = list(system.bodies)
    while stack:
        x = stack.pop()
        if isinstance(x, se.Basic):
            out.update(str(s) for s in x.free_symbols)
        elif isinstance(x, tuple | list):
            stack.extend(x)
        elif dataclasses.is_dataclass(x) and not isinstance(x, type):
            stack.extend(getattr(x, fl.name) for fl in dataclasses.fields(x))
        elif hasattr(x, "free_symbols"):
            out.update(str(s) for s in x.free_symbols)
    return out
