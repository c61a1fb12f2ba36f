"""The work of a study: one block of cases at a time, batched where it pays.

A worker builds a :class:`Context` once per study and process (:func:`context`): the model
rebuilt from the study's copy of the model file (its SHA-256 checked), derived and compiled
once (the compiled libraries come from the on-disk cache of :mod:`jourdain.numeric` when
another process built them; their content keys are compared with the ones the study started
with). A block of cases then only evaluates numbers:

- ``evaluate``: M, k, q (and ÿ, joint wrenches) of all cases of the block in one C call
  (:meth:`jourdain.numeric.CompiledFunction.batch`, ``dynamics``);
- ``linearize``: M̃, P, Q, h of all cases in one C call, the state matrices
  ``A = [[0, I], [−M̃⁻¹Q, −M̃⁻¹P]]`` by stacked Cholesky solves and the eigenvalues by one
  stacked LAPACK call; the verdict as :func:`jourdain.analysis.stability` gives it (its rule
  applied to the stack where the largest real part decides it, the function itself otherwise);
- ``frequency_response``: magnitude and phase of the steady-state response over the study's
  frequencies, from the same C call, the complex solves stacked over cases and frequencies;
- ``critical``: bisection on the verdict for all cases of the block together, then the
  crossing of the largest real part through zero (as
  :func:`jourdain.analysis.stability_boundary`);
- ``simulate``: one run per case (:func:`jourdain.simulation.simulate.simulate`).

A case that fails records its error (a string) and NaN outputs; it never stops the block.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import JourdainError
from .spec import StudyError, StudySpec

__all__ = ["ASYMPTOTICALLY_STABLE_CODE", "Context", "MARGINALLY_STABLE_CODE",
           "UNSTABLE_CODE", "VERDICTS", "compute_block", "context", "output_layout"]

#: verdict codes stored in the results (−1: the case failed)
ASYMPTOTICALLY_STABLE_CODE, MARGINALLY_STABLE_CODE, UNSTABLE_CODE = 0, 1, 2
VERDICTS = ("asymptotically stable", "marginally stable", "unstable")
WRENCH_COMPONENTS = ("F_x", "F_y", "F_z", "T_x", "T_y", "T_z")
_FAILURES = (JourdainError, ArithmeticError, ValueError, np.linalg.LinAlgError)


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
    return ctx


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
        out["eigenvalue_real"] = (("mode",), (2 * f,), "f8")
        out["eigenvalue_imag"] = (("mode",), (2 * f,), "f8")
        out["max_real_part"] = ((), (), "f8")
        out["verdict"] = ((), (), "i1")
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
    return out


def _empty(layout: Mapping[str, tuple[tuple[str, ...], tuple[int, ...], str]], n: int
           ) -> dict[str, np.ndarray]:
    return {k: (np.full((n, *shape), -1, dtype=dt) if dt == "i1"
                else np.full((n, *shape), np.nan)) for k, (_, shape, dt) in layout.items()}


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
        _evaluate(ctx, P, Y, YD, ok, out, errors)
    if "linearize" in comp or "frequency_response" in comp:
        idx = np.flatnonzero(ok)
        # M̃, P, Q, B of the cases: one C call for both outputs
        nums = linearization_numbers(ctx, P[idx]) if idx.size else None
    if "linearize" in comp:
        lam, maxre, verdict, errs = analyse(ctx, P[idx], nums)
        out["eigenvalue_real"][idx] = lam.real
        out["eigenvalue_imag"][idx] = lam.imag
        out["max_real_part"][idx] = maxre
        out["verdict"][idx] = verdict
        _record(errors, idx, errs, "linearize")
    if "critical" in comp:
        idx = np.flatnonzero(ok)
        crit, errs = critical(ctx, P[idx])
        out[f"critical_{comp['critical']['parameter']}"][idx] = crit
        _record(errors, idx, errs, "critical")
    if "frequency_response" in comp:
        mag, phase, errs = frequency_responses(ctx, P[idx], nums)
        out["frf_magnitude"][idx] = mag
        out["frf_phase"][idx] = phase
        _record(errors, idx, errs, "frequency_response")
    if "simulate" in comp:
        _simulate(ctx, P, Y, YD, ok, out, errors)
    return {"start": start, "stop": stop, "outputs": out, "errors": errors}


def _record(errors: list[str], idx: np.ndarray, errs: Mapping[int, str], what: str) -> None:
    for i, msg in errs.items():
        k = int(idx[i])
        errors[k] = f"{errors[k]}; {what}: {msg}" if errors[k] else f"{what}: {msg}"


def _check_parameters(ctx: Context, P: np.ndarray, errors: list[str]) -> np.ndarray:
    """The model's checks of its numbers (mass data, joint axes) at every case's parameters;
    False where they fail (the error recorded). Each distinct combination of the parameters
    the bodies and joints use is checked once."""
    from ..model.bodies import check_values

    ok = np.ones(len(P), dtype=bool)
    names = ctx.parameter_names
    used = _body_names(ctx.system) & {v.name for v in ctx.spec.varied if v.kind == "parameter"}
    if not used:
        return ok
    cols = [names.index(n) for n in names if n in used]
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
            except _FAILURES as exc:
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


# --- evaluate ---------------------------------------------------------------------------------

def _evaluate(ctx: Context, P: np.ndarray, Y: np.ndarray, YD: np.ndarray, ok: np.ndarray,
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
        except _FAILURES:  # one case's M is singular: the others one at a time
            rows = []
            for k in range(idx.size):
                try:
                    a, w = fn.dynamics(Y[idx[k]:idx[k] + 1], YD[idx[k]:idx[k] + 1], e["t"],
                                       P[idx[k]], U[k] if n_u else None)
                    rows.append((k, a[0], w[0]))
                except _FAILURES as exc:
                    good[k] = False
                    _record(errors, idx, {k: str(exc)}, "evaluate")
        for k, a, w in rows:
            if "ydd" in want:
                out["evaluate_ydd"][idx[k]] = a
            for j in e["reactions"]:
                out[f"wrench_{j}"][idx[k]] = w[bodies.index(j)]
    for k in np.flatnonzero(~good):
        if not errors[idx[k]]:
            _record(errors, idx, {int(k): "M, k or q is not finite at this case"}, "evaluate")
        for name in out:
            if name.startswith(("evaluate_", "wrench_")):
                out[name][idx[k]] = np.nan


# --- linearize: state matrices, eigenvalues and verdicts of a stack of cases -----------------

def linearization_numbers(ctx: Context, P: np.ndarray) -> dict[str, np.ndarray]:
    """M̃, P, Q, B, ... of the linearization at each row of ``P`` (n ≥ 1), in one C call."""
    n, f = len(P), ctx.system.f
    Z = np.zeros((n, f))
    U = np.zeros((n, len(ctx.system.inputs))) if ctx.system.inputs else None
    return ctx.compiled_linearization.function.batch(Z, Z, 0.0, P, U)


def analyse(ctx: Context, P: np.ndarray, nums: Mapping[str, np.ndarray] | None = None
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict[int, str]]:
    """Eigenvalues (n, 2f) sorted as :func:`jourdain.analysis.sweep` sorts them, the largest
    real part (n,) and the verdict code (n,) of the linearization at each row of ``P``; and
    the errors by row (their outputs NaN / −1). ``nums``: :func:`linearization_numbers` at
    ``P`` where already computed."""
    from ..analysis.cyclic import reduced_matrix
    from ..analysis.modes import ZERO_RTOL, _verdict

    n, f = len(P), ctx.system.f
    lam = np.full((n, 2 * f), np.nan + 0j)
    maxre = np.full(n, np.nan)
    verdict = np.full(n, -1, dtype=np.int8)
    errs: dict[int, str] = {}
    if not n:
        return lam, maxre, verdict, errs
    if nums is None:
        nums = linearization_numbers(ctx, P)
    A, bad = state_matrices(nums["M_tilde"], nums["P"], nums["Q"])
    for i, msg in bad.items():
        errs[i] = msg
    good = np.array([i not in bad for i in range(n)])
    if not good.any():
        return lam, maxre, verdict, errs
    Ag = A[good]
    ev = np.linalg.eigvals(Ag)
    order = np.lexsort((ev.real, ev.imag), axis=-1)
    ev = np.take_along_axis(ev, order, axis=-1)
    names = tuple(ctx.system.coordinate_names)
    Ar = (np.stack([reduced_matrix(a, names, ctx.cyclic) for a in Ag]) if ctx.cyclic
          else Ag)
    evr = np.linalg.eigvals(Ar) if ctx.cyclic else ev
    # the verdict of modes._verdict: a group's centre lies within 2·cluster_tol of its
    # members, so a largest real part beyond tol + 2·cluster_tol is unstable and one below
    # −tol − 2·cluster_tol asymptotically stable; cases in between take the function itself
    scale = np.maximum(1.0, np.abs(evr).max(axis=1))
    tol = ZERO_RTOL * scale
    cluster = 1e3 * np.sqrt(np.finfo(float).eps) * scale
    mr = evr.real.max(axis=1)
    v = np.where(mr > tol + 2 * cluster, UNSTABLE_CODE,
                 np.where(mr < -tol - 2 * cluster, ASYMPTOTICALLY_STABLE_CODE, -1))
    for k in np.flatnonzero(v < 0):
        v[k] = VERDICTS.index(_verdict(Ar[k], ZERO_RTOL).verdict)
    gi = np.flatnonzero(good)
    lam[gi] = ev
    maxre[gi] = ev.real.max(axis=1)
    verdict[gi] = v
    return lam, maxre, verdict, errs


def frequency_responses(ctx: Context, P: np.ndarray,
                        nums: Mapping[str, np.ndarray] | None = None
                        ) -> tuple[np.ndarray, np.ndarray, dict[int, str]]:
    """``|η̂|`` and ``arg η̂`` (unwrapped along the frequencies), each (n, n_ω, f, m), of the
    linearization at each row of ``P``: ``η̂ = (Q − Ω²M̃ + iΩP)⁻¹·F`` with ``F = B`` (inputs)
    or the identity (``h``), as :func:`jourdain.analysis.frequency_response` gives it for one
    case; M̃, P, Q, B of all cases from one C call, the complex solves stacked over cases and
    frequencies. A case whose dynamic stiffness is singular at some Ω records its error.
    ``nums``: :func:`linearization_numbers` at ``P`` where already computed."""
    fr = ctx.spec.compute["frequency_response"]
    n, f = len(P), ctx.system.f
    w = np.asarray(fr["omega"], dtype=float)
    m = len(ctx.system.inputs) if fr["excitation"] == "inputs" else f
    mag = np.full((n, len(w), f, m), np.nan)
    phase = np.full((n, len(w), f, m), np.nan)
    errs: dict[int, str] = {}
    if not n:
        return mag, phase, errs
    if nums is None:
        nums = linearization_numbers(ctx, P)
    F = nums["B"] if fr["excitation"] == "inputs" else np.broadcast_to(np.eye(f), (n, f, f))
    W = w[None, :, None, None]
    Z = (nums["Q"][:, None] - W**2 * nums["M_tilde"][:, None] + 1j * W * nums["P"][:, None])
    rhs = np.broadcast_to(F[:, None], (n, len(w), f, m)).astype(complex)
    try:
        eta = np.linalg.solve(Z, rhs)
        rows = range(n) if not np.all(np.isfinite(eta)) else ()
    except np.linalg.LinAlgError:
        eta, rows = np.full(rhs.shape, np.nan + 0j), range(n)
    for i in rows:  # case by case where the stack failed: name the frequency
        for k, wk in enumerate(w):
            try:
                eta[i, k] = np.linalg.solve(Z[i, k], rhs[i, k])
            except np.linalg.LinAlgError:
                eta[i] = np.nan
                errs[i] = (f"the dynamic stiffness Q - Ω²M̃ + iΩP is singular at Ω = {wk} "
                           "rad/s (an undamped resonance, or a rigid-body mode at Ω = 0)")
                break
    mag[:] = np.abs(eta)
    phase[:] = np.unwrap(np.angle(eta), axis=1)
    return mag, phase, errs


def state_matrices(M: np.ndarray, Pm: np.ndarray, Q: np.ndarray
                   ) -> tuple[np.ndarray, dict[int, str]]:
    """``A = [[0, I], [−M̃⁻¹Q, −M̃⁻¹P]]`` for a stack (n, f, f), by the Cholesky factor of
    M̃ as :func:`jourdain.analysis.state_space` forms it; rows where M̃ is not finite or not
    positive definite are reported (their A is zero)."""
    n, f = M.shape[0], M.shape[1]
    A = np.zeros((n, 2 * f, 2 * f))
    A[:, :f, f:] = np.eye(f)
    bad: dict[int, str] = {}
    finite = np.all(np.isfinite(M.reshape(n, -1)) & np.isfinite(Pm.reshape(n, -1))
                    & np.isfinite(Q.reshape(n, -1)), axis=1)
    for i in np.flatnonzero(~finite):
        bad[int(i)] = "the linearization has non-finite entries at this case"
    idx = np.flatnonzero(finite)
    Ms = 0.5 * (M[idx] + np.swapaxes(M[idx], 1, 2))
    try:
        L = np.linalg.cholesky(Ms)
        chol_ok = np.ones(idx.size, dtype=bool)
    except np.linalg.LinAlgError:  # some case is not positive definite: find which
        L = np.zeros_like(Ms)
        chol_ok = np.zeros(idx.size, dtype=bool)
        for k in range(idx.size):
            try:
                L[k] = np.linalg.cholesky(Ms[k])
                chol_ok[k] = True
            except np.linalg.LinAlgError:
                ev = np.linalg.eigvalsh(Ms[k])
                bad[int(idx[k])] = (f"M_tilde is not positive definite (eigenvalues "
                                    f"{np.array2string(ev, precision=4)})")
    idx, L = idx[chol_ok], L[chol_ok]
    if idx.size:
        Lt = np.swapaxes(L, 1, 2)
        X = np.concatenate([Q[idx], Pm[idx]], axis=2)
        S = np.linalg.solve(Lt, np.linalg.solve(L, X))
        A[idx, f:, :f] = -S[:, :, :f]
        A[idx, f:, f:] = -S[:, :, f:]
    return A, bad


# --- critical value by bisection on the verdict ------------------------------------------------

def critical(ctx: Context, P: np.ndarray) -> tuple[np.ndarray, dict[int, str]]:
    """The value of the critical parameter in [lower, upper] where the verdict changes between
    stable and unstable, for every row of ``P`` (the other parameters); as
    :func:`jourdain.analysis.stability_boundary`: bisection on the verdict to ``rtol``, then,
    where the stable side is asymptotically stable, the zero of the largest real part between
    the nearest asymptotically stable point and the unstable end (Illinois' regula falsi,
    all rows together). Rows whose ends have the same verdict are errors."""
    c = ctx.spec.compute["critical"]
    j = ctx.parameter_names.index(c["parameter"])
    n = len(P)
    out = np.full(n, np.nan)
    errs: dict[int, str] = {}
    if not n:
        return out, errs
    ab = np.asarray(ctx.bounds(P), dtype=float).reshape(n, 2)
    a, b = ab[:, 0].copy(), ab[:, 1].copy()

    def at(x: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray, dict[int, str]]:
        Px = P[rows].copy()
        Px[:, j] = x
        _, mr, v, e = analyse(ctx, Px)
        return v, mr, e

    rows = np.arange(n)
    va, _, ea = at(a, rows)
    vb, _, eb = at(b, rows)
    alive = np.ones(n, dtype=bool)
    for i, msg in {**ea, **eb}.items():
        errs[i] = f"at the bracket's end: {msg}"
        alive[i] = False
    ua, ub = va == UNSTABLE_CODE, vb == UNSTABLE_CODE
    for i in np.flatnonzero(alive & (ua == ub)):
        word = "unstable" if ua[i] else "stable"
        errs[int(i)] = (f"the system is {word} at both {c['parameter']} = {a[i]:.17g} and "
                        f"{b[i]:.17g}; give a bracket where it changes")
        alive[i] = False
    asym = np.where(va == ASYMPTOTICALLY_STABLE_CODE, a,
                    np.where(vb == ASYMPTOTICALLY_STABLE_CODE, b, np.nan))
    rtol = c["rtol"]
    for _ in range(2000):
        width = np.abs(b - a) > rtol * np.maximum(1.0, np.maximum(np.abs(a), np.abs(b)))
        live = np.flatnonzero(alive & width)
        if not live.size:
            break
        mid = 0.5 * (a[live] + b[live])
        vm, _, em = at(mid, live)
        for i, msg in em.items():
            errs[int(live[i])] = f"at {c['parameter']} = {mid[i]:.17g}: {msg}"
            alive[live[i]] = False
        asym[live] = np.where(vm == ASYMPTOTICALLY_STABLE_CODE, mid, asym[live])
        same = (vm == UNSTABLE_CODE) == ua[live]
        a[live] = np.where(same, mid, a[live])
        b[live] = np.where(same, b[live], mid)
    unstable_end = np.where(ua, a, b)
    out[:] = 0.5 * (a + b)
    # the crossing of the largest real part through zero, between the nearest asymptotically
    # stable point and the unstable end
    rows = np.flatnonzero(alive & np.isfinite(asym))
    if rows.size:
        x0, x1 = asym[rows].copy(), unstable_end[rows].copy()
        _, f0, _ = at(x0, rows)
        _, f1, _ = at(x1, rows)
        go = f1 > 0
        x0, x1, f0, f1, rows = x0[go], x1[go], f0[go], f1[go], rows[go]
        xs = 0.5 * (x0 + x1)
        for _ in range(200):
            if not rows.size:
                break
            xs = x1 - f1 * (x1 - x0) / (f1 - f0)
            xs = np.where(np.isfinite(xs), xs, 0.5 * (x0 + x1))
            _, fs, em = at(xs, rows)
            fs = np.where(np.isfinite(fs), fs, 0.0)
            # Illinois: keep the bracket [x0, x1] with f0 < 0 < f1 (f0 halved when x1 moves)
            left = fs < 0
            side0 = np.where(left, xs, x0)
            side1 = np.where(left, x1, xs)
            f0n = np.where(left, fs, f0 * 0.5)
            f1n = np.where(left, f1 * 0.5, fs)
            done = (np.abs(side1 - side0) <= 4 * np.finfo(float).eps * np.abs(xs) + 1e-300) | (
                fs == 0)
            out[rows[done]] = xs[done]
            keep = ~done
            x0, x1, f0, f1, rows = side0[keep], side1[keep], f0n[keep], f1n[keep], rows[keep]
            out[rows] = 0.5 * (x0 + x1)
    for i in errs:
        out[i] = np.nan
    return out, errs


# --- simulate: one run per case -----------------------------------------------------------------

def _simulate(ctx: Context, P: np.ndarray, Y: np.ndarray, YD: np.ndarray, ok: np.ndarray,
              out: dict[str, np.ndarray], errors: list[str]) -> None:
    from ..simulation.simulate import simulate

    s = ctx.spec.compute["simulate"]
    system = ctx.system
    names = ctx.parameter_names
    coords = system.coordinate_names
    t_eval = np.linspace(0.0, s["t_end"], s["samples"])
    inputs = {k: v for k, v in ctx.model.simulation.inputs} or None
    f = system.f
    for i in np.flatnonzero(ok):
        try:
            r = simulate(system, (0.0, s["t_end"]), Y[i], YD[i],
                         parameters=dict(zip(names, P[i].tolist(), strict=True)),
                         inputs=inputs, method=s["method"], rtol=s["rtol"], atol=s["atol"],
                         t_eval=t_eval, raise_on_interrupt=True)  # Ctrl-C stops the study
            if len(r.t) != len(t_eval):
                raise StudyError(f"the run stopped at t = {r.t[-1]:.6g} ({r.status}: "
                                 f"{r.message})")
        except _FAILURES as exc:
            _record(errors, np.array([i]), {0: str(exc)}, "simulate")
            continue
        cols = {n: r.y[:, k] for k, n in enumerate(coords)}
        cols.update({f"{n}_d": r.yd[:, k] for k, n in enumerate(coords)})
        if s["final"]:
            out["final"][i, :f] = r.y[-1]
            out["final"][i, f:] = r.yd[-1]
        for n in s["max"]:
            out[f"max_{n}"][i] = cols[n].max()
        for n in s["max_abs"]:
            out[f"max_abs_{n}"][i] = np.abs(cols[n]).max()
        for n in s["series"]:
            out[f"series_{n}"][i] = cols[n]
