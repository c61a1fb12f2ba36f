"""Motions of a block of cases: ``evaluate`` (M, k, q, ÿ and joint wrenches at the cases' initial
states, one C call for the block) and ``simulate`` (a run per case, advanced together in C by
:class:`jourdain.study.ensemble.Ensemble` where the method and inputs allow, else one
:func:`jourdain.simulation.simulate.simulate` per case; the numbers are the same).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from .context import FAILURES, Context, record_errors
from .spec import StudyError

__all__ = ["ENSEMBLE_BYTES", "ENSEMBLE_CASES", "evaluate_block", "simulate_block"]

#: the most memory the motions of one ensemble call take (a block's runs with many samples
#: are integrated in several calls)
ENSEMBLE_BYTES = 256 * 2**20
#: the most runs of one ensemble call (a Ctrl-C waits for the call to end)
ENSEMBLE_CASES = 64


def evaluate_block(ctx: Context, P: np.ndarray, Y: np.ndarray, YD: np.ndarray, ok: np.ndarray,
              out: dict[str, np.ndarray], errors: list[str]) -> None:
    e = ctx.spec.compute["evaluate"]
    fn = ctx.dynamics
    f, n_u = ctx.system.f, len(ctx.system.inputs)
    idx = np.flatnonzero(ok)
    if not idx.size:
        return
    U = np.zeros((idx.size, n_u))
    mkq = fn.batch(Y[idx], YD[idx], e["t"], P[idx], U if n_u else None)
    good = np.all(np.isfinite(mkq["M"].reshape(idx.size, -1)), axis=1) & np.all(
        np.isfinite(mkq["k"].reshape(idx.size, -1)), axis=1) & np.all(
        np.isfinite(mkq["q"].reshape(idx.size, -1)), axis=1)
    want = e["outputs"]
    if "M" in want:
        out["evaluate_M"][idx] = mkq["M"]
    for name in ("k", "q"):
        if name in want:
            out[f"evaluate_{name}"][idx] = mkq[name].reshape(idx.size, f)
    if "ydd" in want or e["reactions"]:
        bodies = [b.joint.name for b in ctx.system.bodies]
        try:
            ydd, W = fn.dynamics(Y[idx], YD[idx], e["t"], P[idx], U if n_u else None)
            rows: list[tuple[int, np.ndarray, np.ndarray]] = [(k, ydd[k], W[k])
                                                               for k in range(idx.size)]
        except FAILURES:  # one case's M is singular: the others one at a time
            rows = []
            for k in range(idx.size):
                try:
                    a, w = fn.dynamics(Y[idx[k]:idx[k] + 1], YD[idx[k]:idx[k] + 1], e["t"],
                                       P[idx[k]], U[k] if n_u else None)
                    rows.append((k, a[0], w[0]))
                except FAILURES as exc:
                    good[k] = False
                    record_errors(errors, idx, {k: str(exc)}, "evaluate")
        for k, a, w in rows:
            if "ydd" in want:
                out["evaluate_ydd"][idx[k]] = a
            for j in e["reactions"]:
                out[f"wrench_{j}"][idx[k]] = w[bodies.index(j)]
    for kk in np.flatnonzero(~good):
        k = int(kk)
        if not errors[idx[k]]:
            record_errors(errors, idx, {k: "M, k or q is not finite at this case"}, "evaluate")
        for name in out:
            if name.startswith(("evaluate_", "wrench_")):
                out[name][idx[k]] = np.nan


def simulate_block(ctx: Context, P: np.ndarray, Y: np.ndarray, YD: np.ndarray, ok: np.ndarray,
                   out: dict[str, np.ndarray], errors: list[str]) -> None:
    """The ``simulate`` outputs of the cases where ``ok``: all of them in one ensemble call
    where the context has an ensemble; a case that fails there (and every case without an
    ensemble) runs on its own through :func:`jourdain.simulation.simulate.simulate`, whose
    error message is recorded."""
    idx = np.flatnonzero(ok)
    if not idx.size:
        return
    s = ctx.spec.compute["simulate"]
    coords = ctx.system.coordinate_names
    alone = idx
    if ctx.ensemble is not None:
        # the runs' motions at all samples are held at once: at most ENSEMBLE_BYTES of them,
        # and ENSEMBLE_CASES runs per call (Ctrl-C is seen between calls)
        per_case = 8 * s["samples"] * (2 * ctx.system.f + 1)
        step = max(1, min(ENSEMBLE_CASES, ENSEMBLE_BYTES // per_case))
        failed = []
        for a in range(0, idx.size, step):
            part = idx[a:a + step]
            run = ctx.ensemble.run(P[part], Y[part], YD[part])
            for k in np.flatnonzero(run.ok):
                _store(out, s, int(part[k]), run.y[k], run.yd[k], coords)
            failed.append(part[~run.ok])
        alone = np.concatenate(failed)
    for i in alone:
        _simulate_case(ctx, int(i), P, Y, YD, out, errors)


def _simulate_case(ctx: Context, i: int, P: np.ndarray, Y: np.ndarray, YD: np.ndarray,
                   out: dict[str, np.ndarray], errors: list[str]) -> None:
    from ..simulation.simulate import simulate

    s = ctx.spec.compute["simulate"]
    system = ctx.system
    t_eval = np.linspace(0.0, s["t_end"], s["samples"]).tolist()
    inputs = {k: v for k, v in ctx.model.simulation.inputs} or None
    parameters = dict(zip(ctx.parameter_names, P[i].tolist(), strict=True))
    try:
        # a closed system's on its constraint manifold (simulate routes it)
        r = simulate(system, (0.0, s["t_end"]), Y[i], YD[i], parameters=parameters,
                     inputs=inputs, method=s["method"], rtol=s["rtol"], atol=s["atol"],
                     t_eval=t_eval, raise_on_interrupt=True)  # Ctrl-C stops the study
        if len(r.t) != len(t_eval):
            raise StudyError(f"the run stopped at t = {r.t[-1]:.6g} ({r.status}: "
                             f"{r.message})")
    except FAILURES as exc:
        record_errors(errors, np.array([i]), {0: str(exc)}, "simulate")
        return
    _store(out, s, i, r.y, r.yd, system.coordinate_names)
    if ctx.closed:
        out["closure_residual"][i], out["closure_rate_residual"][i] = r.closure_residual


def _store(out: dict[str, np.ndarray], s: Mapping[str, Any], i: int, y: np.ndarray,
           yd: np.ndarray, names: Sequence[str]) -> None:
    """Case ``i``'s outputs from its motion ``y``, ``yd`` (samples, f), ``names`` the
    coordinates."""
    f = len(names)
    cols = {n: y[:, k] for k, n in enumerate(names)}
    cols.update({f"{n}_d": yd[:, k] for k, n in enumerate(names)})
    if s["final"]:
        out["final"][i, :f] = y[-1]
        out["final"][i, f:] = yd[-1]
    for n in s["max"]:
        out[f"max_{n}"][i] = cols[n].max()
    for n in s["max_abs"]:
        out[f"max_abs_{n}"][i] = np.abs(cols[n]).max()
    for n in s["series"]:
        out[f"series_{n}"][i] = cols[n]
