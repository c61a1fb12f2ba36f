"""Glue between model files and the later stages: reactions, linearization, simulation.

The command line and the report call these functions with a loaded :class:`ModelFile`; each
uses only the public API of :class:`~jourdain.System` (``evaluate``, ``linearize``,
``simulate``) and the analysis functions.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import symengine as se

from ..analysis.cyclic import cyclic_coordinates
from ..analysis.floquet import floquet
from ..analysis.numeric_linearization import linearize_numeric
from ..errors import EvaluationError
from ..pipeline.system import tree_linearization
from ..simulation.simulate import check_samples, check_t_end
from ..stages.linearization import NominalMotionWarning
from .export import format_array
from .modelfile import ModelFile, NominalMotion

T = se.Symbol("t")


def reactions_at(system: Any, y: Any, yd: Any, t: float, parameters: Mapping[str, float],
                 inputs: Mapping[str, float]) -> dict[str, Any]:
    """``Q_bar, N_hat, k_hat, q_hat, g`` (and ``g_names``, ``g_undetermined``) at one state."""
    out = system.evaluate(y, yd, t=t, parameters=dict(parameters) or None,
                          inputs=dict(inputs) or None)
    if "g" not in out:  # the reactions could not be formed (their message says why)
        raise EvaluationError(f"the reaction forces could not be formed: "
                              f"{out.get('reactions_error', 'no reaction forces')}")
    keys = ("Q_bar", "N_hat", "k_hat", "q_hat", "g", "g_names", "g_undetermined")
    return {k: out[k] for k in keys if k in out}


def reaction_labels(system: Any) -> list[str]:
    """Names of the components of g: ``<joint>.F_x`` … in the child body frame."""
    return list(system.reactions().g_names)


def state_nominal(system: Any, y: Any, yd: Any, t: float,
                  inputs: Mapping[str, float]) -> dict[str, se.Basic]:
    """The nominal motion through the state (y, ẏ) at time t with ÿ_s = 0:
    ``y_s(τ) = y + ẏ·(τ − t)``."""
    out: dict[str, se.Basic] = {}
    for name, a, b in zip(system.coordinate_names, y, yd, strict=True):
        out[name] = se.Float(float(a)) + se.Float(float(b)) * (T - se.Float(float(t))) \
            if b != 0 else se.Float(float(a))
    for name in system.input_names:
        out[name] = se.Float(float(inputs.get(name, 0.0)))
    return out


def split(P: np.ndarray, Q: np.ndarray) -> dict[str, np.ndarray]:
    """D, G, K, N: the symmetric and skew-symmetric parts of P and Q (METHOD §6); an entry
    beyond the floating-point range is inf, without a warning (the callers check)."""
    with np.errstate(over="ignore", invalid="ignore"):
        return {"D": 0.5 * (P + P.T), "G": 0.5 * (P - P.T), "K": 0.5 * (Q + Q.T),
                "N": 0.5 * (Q - Q.T)}


def linearization_at(model: ModelFile, y: Any, yd: Any, t: float,
                     parameters: Mapping[str, float], inputs: Mapping[str, float]
                     ) -> dict[str, np.ndarray]:
    """``M_tilde, P, Q, h`` about the state (y, ẏ) at time t (nominal ÿ_s = 0), and ``D, G, K,
    N``, the symmetric and skew parts of P and Q at that instant. A closed system's in its
    independent coordinates (:func:`jourdain.loops.linearization.linearize_loop` about the
    state assembled from (y, ẏ), ÿ_s = 0)."""
    system = model.system
    if system.closing:
        from .closed_linear import closed_linearization_at  # SciPy's linear algebra: loops only

        return closed_linearization_at(system, y, yd, t, parameters, inputs)
    with warnings.catch_warnings():
        # any state, not a claimed equilibrium: h = M·ÿ there is expected
        warnings.simplefilter("ignore", NominalMotionWarning)
        # numbers at one state: forward-mode differentiation in floating point, the same
        # equations as the symbolic linearization without forming and compiling it (entries
        # equal to rounding; 0.9-1.5x the speed of the symbolic way on UR5, Solo and
        # examples/planar_arm.urdf, benchmarks/urdf_reports.py on a loaded 2-core machine)
        lin = linearize_numeric(system, state_nominal(system, y, yd, t, inputs), t,
                                dict(parameters) or None)
    out = {"M_tilde": lin.M_tilde, "P": lin.P, "Q": lin.Q, "h": lin.h}
    out.update(split(out["P"], out["Q"]))
    return out


def nominal_mapping(system: Any, nominal: NominalMotion) -> dict[str, se.Basic]:
    """The nominal motion and its nominal inputs by name, for :meth:`System.linearize`."""
    return {**dict(zip(system.coordinate_names, nominal.y, strict=True)), **dict(nominal.inputs)}


def steady_mapping(system: Any, nominal: NominalMotion) -> dict[str, se.Basic]:
    """A steady motion of a general system (velocity constraints) as
    :meth:`System.linearize` takes it: ``{coordinate: y_s, "<coordinate>_d": ẏ_s}``, the
    entries that are not 0 (expressions of the parameters)."""
    out: dict[str, se.Basic] = {}
    for name, e, ed in zip(system.coordinate_names, nominal.y, nominal.yd, strict=True):
        if e != 0:
            out[name] = e
        if ed != 0:
            out[f"{name}_d"] = ed
    return out


def linear_analysis(model: ModelFile, about: str | None,
                    parameters: Mapping[str, float] | None = None, t: float = 0.0,
                    period: Any = None) -> dict[str, Any]:
    """Linearize about a nominal motion of the model file and analyse it.

    Returns a dict: ``nominal`` (the NominalMotion), ``linearization``, ``numbers`` (M_tilde, P,
    Q, h, B and, time-invariant, D, G, K, N at ``t``), ``time_invariant``, ``conservative``
    (None when time-variant), ``modes`` and ``stability`` (None when time-variant or not
    available), ``h_norm``, ``nominal_check`` (:class:`~jourdain.stages.linearization.NominalCheck`
    at ``t``), ``cyclic`` (the cyclic coordinates) and ``floquet``
    (:class:`~jourdain.analysis.floquet.Floquet` over one period from ``t`` for a periodic
    nominal motion: ``period`` given, a number or an expression in the parameters, or the
    nominal motion's own ``period``; else None).

    The warnings of a nominal motion that is not a solution are not issued here: they are in
    ``nominal_check`` and the stability verdict, which the text and the report show.
    """
    system = model.system
    if system.closing:  # in the independent coordinates (jourdain.io.closed_linear)
        from .closed_linear import closed_linear_analysis

        nom = model.nominal_motion(about) if about is not None else None
        if period is None and nom is not None:
            period = nom.period
        T = None if period is None else period_value(system, period, parameters)
        return closed_linear_analysis(model, about, parameters, t, T)
    nominal = model.nominal_motion(about)
    params = dict(parameters or {}) or None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NominalMotionWarning)
        lin = tree_linearization(system.linearize(nominal_mapping(system, nominal)))
        num = lin.evaluate(t=t, parameters=params)
        check = lin.check_nominal(t, params)
        res = _analyse(lin, num, check, params, t)
    res["nominal"] = nominal
    res["floquet"] = None
    if period is None:
        period = nominal.period
    if period is not None:
        res["floquet"] = floquet(lin, period_value(system, period, params), t0=t,
                                 parameters=params, cyclic=res["cyclic"])
    return res


def period_value(system: Any, period: Any, parameters: Mapping[str, float] | None) -> float:
    """The number of a period given as a number or an expression in the parameters."""
    if isinstance(period, (int, float)):
        return float(period)
    values = {**system.parameter_values, **dict(parameters or {})}
    try:
        v = float(se.sympify(period).subs({se.Symbol(k): x for k, x in values.items()}))
    except (RuntimeError, TypeError, ValueError) as exc:
        raise EvaluationError(f"the period {period} has no numeric value: {exc}") from None
    if not np.isfinite(v) or v <= 0:
        raise EvaluationError(f"the period {period} must be positive, it is {v:g}")
    return v


def _analyse(lin: Any, num: dict[str, np.ndarray], check: Any,
             params: Mapping[str, float] | None, t: float) -> dict[str, Any]:
    res: dict[str, Any] = {"linearization": lin, "numbers": num, "nominal_check": check,
                           "time_invariant": lin.is_time_invariant, "t": t,
                           "h_norm": float(np.abs(num["h"]).max(initial=0.0)),
                           "cyclic": cyclic_coordinates(lin.equations_of_motion)}
    res["conservative"] = None
    res["modes"] = res["stability"] = None
    res["numerically_time_invariant"] = False
    if not lin.is_time_invariant and _constant_in_time(lin, params, num):
        # t enters only through terms that cancel (cos²(Ωt) + sin²(Ωt), cyclic coordinates):
        # the system is time-invariant and the split and the eigenvalues apply
        res["time_invariant"] = True
        res["numerically_time_invariant"] = True
        num = dict(num)
        num.update(split(num["P"], num["Q"]))
        res["numbers"] = num
    if res["time_invariant"]:
        D, N = num["D"], num["N"]
        scale = max(1.0, float(np.abs(num["P"]).max()), float(np.abs(num["Q"]).max()),
                    float(np.abs(num["M_tilde"]).max()))
        res["conservative"] = bool(np.abs(D).max(initial=0) <= 1e-9 * scale
                                   and np.abs(N).max(initial=0) <= 1e-9 * scale
                                   and check.is_solution)
        try:
            from ..analysis.modes import modes, stability
            from ..analysis.state_space import state_space

            ss = state_space(lin, t, params, allow_time_variant=True,
                             nominal_check=check)  # computed above
            res["modes"] = modes(ss)
            res["stability"] = stability(ss, cyclic=res["cyclic"])
        except ImportError:
            pass
    return res


def _constant_in_time(lin: Any, params: Mapping[str, float] | None,
                      at_t: Mapping[str, np.ndarray]) -> bool:
    """Whether M̃, P, Q and B take the same values at several times."""
    keys = ("M_tilde", "P", "Q", "B")
    scale = max(1.0, *(float(np.abs(at_t[k]).max(initial=0.0)) for k in keys))
    for tt in (0.37, 1.91, 4.6):
        other = lin.evaluate(t=tt, parameters=params)
        for k in keys:
            if np.abs(np.asarray(other[k]) - np.asarray(at_t[k])).max(initial=0.0) > 1e-9 * scale:
                return False
    return True


def jsonable(res: Mapping[str, Any]) -> dict[str, Any]:
    """The result of :func:`linear_analysis` as JSON-ready data."""
    if res.get("closed"):
        from .closed_linear import closed_jsonable

        return closed_jsonable(res)
    out: dict[str, Any] = {
        "nominal": res["nominal"].name,
        "nominal_y": [str(e) for e in res["nominal"].y],
        "t": res["t"], "time_invariant": res["time_invariant"],
        "conservative": res["conservative"], "h_norm": res["h_norm"],
        "nominal_inputs": {k: str(v) for k, v in res["nominal"].inputs},
        "nominal_is_solution": res["nominal_check"].is_solution,
        "h_relative": _finite_list([res["nominal_check"].relative])[0],
        "matrices": {k: np.asarray(v, float).tolist() for k, v in res["numbers"].items()},
        "cyclic_coordinates": list(res.get("cyclic", ())),
    }
    fl = res.get("floquet")
    if fl is not None:
        out["floquet"] = {
            "period": fl.period, "t0": fl.t0, "state_names": list(fl.state_names),
            "monodromy": np.asarray(fl.monodromy, float).tolist(),
            "multipliers": [[float(z.real), float(z.imag)] for z in fl.multipliers],
            "exponents": [[float(z.real) if np.isfinite(z.real) else None, float(z.imag)]
                          for z in fl.exponents],
            "verdict": fl.verdict, "reason": fl.reason, "tolerance": fl.tolerance,
            "cyclic": list(fl.cyclic)}
    m = res.get("modes")
    if m is not None:
        out["eigenvalues"] = [[float(z.real), float(z.imag)] for z in m.eigenvalues]
        out["natural_frequencies_hz"] = _finite_list(m.frequencies_hz)
        out["damping_ratios"] = _finite_list(m.damping_ratios)
    s = res.get("stability")
    if s is not None:
        out["stability"] = {"verdict": s.verdict, "reason": s.reason,
                            "max_real_part": float(s.max_real_part),
                            "cyclic": list(s.cyclic)}
    return out


def cyclic_text(cyclic: Any) -> str:
    """One sentence naming the cyclic coordinates (for the text output and the report)."""
    return (f"cyclic coordinates: {', '.join(cyclic)} (they appear in no equation, only their "
            "rates; the stability verdict is taken in Routh's sense on the reduced system "
            "without their positions)")


def _finite_list(a: Any) -> list[float | None]:
    return [float(x) if np.isfinite(x) else None for x in np.asarray(a, float)]


def linear_text(res: Mapping[str, Any]) -> str:
    """A plain-text account of :func:`linear_analysis`."""
    if res.get("closed"):
        from .closed_linear import closed_linear_text

        return closed_linear_text(res)
    lin = res["linearization"]
    num = res["numbers"]
    nominal = res["nominal"]
    check = res["nominal_check"]
    lines = [f"{lin.system.name}: linearized about \"{nominal.name}\""
             + (f" ({nominal.description})" if nominal.description else ""),
             "  y_s(t) = " + ", ".join(f"{n} = {e}" for n, e in
                                       zip(lin.system.coordinate_names, nominal.y, strict=True))]
    if lin.system.inputs:
        given = dict(nominal.inputs)
        lines.append("  u_s(t) = " + ", ".join(f"{n} = {given.get(n, 0)}"
                                               for n in lin.system.input_names))
    lines += ["  M̃·η̈ + P·η̇ + Q·η = h" + (" + B·Δu" if lin.system.inputs else ""),
              "  time-invariant" if res["time_invariant"] else
              f"  time-variant (depends on t: {', '.join(lin.time_dependence)}); numbers at "
              f"t = {res['t']:g}"]
    if check.kind != "nominal motion" and not check.is_solution:
        lines.append(f"  WARNING: {check.message()}")
    keys = ["M_tilde", "P", "Q", "h"] + (["B"] if lin.system.inputs else [])
    if res["time_invariant"]:
        keys += ["D", "G", "K", "N"]
    # round-off is judged against the matrix a part comes from, h against the forces at work
    scales = {"D": num["P"], "G": num["P"], "K": num["Q"], "N": num["Q"],
              "h": check.scale if np.any(check.scale) else num["h"]}
    for k in keys:
        lines.append(f"\n{k} =\n{format_array(num[k], scales.get(k))}")
    if res["conservative"] is not None:
        lines.append("\nconservative (D = 0, N = 0, h = 0): " + ("yes" if res["conservative"]
                                                                else "no"))
    if res["modes"] is not None:
        lines.append("\neigenvalues of the state-space system:\n" + str(res["modes"]))
    if res.get("cyclic"):
        lines.append("\n" + cyclic_text(res["cyclic"]))
    if res.get("floquet") is not None:
        lines.append("\n" + str(res["floquet"]))
    if res["stability"] is not None:
        lines.append(f"\nstability: {res['stability']}")
    return "\n".join(lines)


SIM_METHODS = ("DOP853", "RK45", "Radau", "BDF", "LSODA")


def simulate(model: ModelFile, parameters: Mapping[str, float] | None = None,
             t_end: float | None = None, samples: int | None = None, *,
             method: str | None = None, rtol: float | None = None, atol: float | None = None,
             y0: Mapping[str, float] | None = None, yd0: Mapping[str, float] | None = None,
             inputs: Mapping[str, Any] | None = None, progress: Any = False,
             output: str | Path | None = None) -> Any:
    """Integrate the model from its [simulation] initial state; returns a
    :class:`jourdain.simulation.results.Results`.

    Each option left out (None) is the model's ``[simulation]`` value, whose own defaults are
    those of :mod:`jourdain.simulation.simulate`; ``y0``, ``yd0`` (by coordinate name) and ``inputs`` (by
    input name: a number or an expression in t and the parameters) replace the model's values
    they name. ``progress`` and ``output`` (a results file written as the run goes) are passed
    to :func:`jourdain.simulation.simulate.simulate`; a closed system's run writes ``output``
    whole at its end or on an interruption (:func:`jourdain.loops.simulate.simulate_closed`).
    The options are checked against the bounds of :mod:`jourdain.simulation.simulate` before
    anything is computed (:class:`EvaluationError`).
    """
    system = model.system
    sim = model.simulation
    t1 = check_t_end(t_end if t_end is not None else sim.t_end)
    n = check_samples(samples if samples is not None else sim.samples, system.f,
                      len(system.inputs))
    coords = system.coordinate_names
    y = dict(zip(coords, sim.y0 or [0.0] * system.f, strict=True))
    yd = dict(zip(coords, sim.yd0 or [0.0] * system.f, strict=True))
    for given, into, what in ((y0, y, "y0"), (yd0, yd, "yd0")):
        for name, v in dict(given or {}).items():
            if name not in into:
                raise EvaluationError(f'{what}: "{name}" is not a coordinate; coordinates are '
                                      f"{', '.join(coords)}")
            into[name] = v
    laws: dict[str, Any] = {name: 0.0 for name in system.input_names}
    laws.update(dict(sim.inputs))
    for name, v in dict(inputs or {}).items():
        if name not in laws:
            raise EvaluationError(f'inputs: "{name}" is not an input of the model; inputs are '
                                  f"{', '.join(system.input_names) or '(none)'}")
        laws[name] = v
    return system.simulate((0.0, t1), [y[c] for c in coords], [yd[c] for c in coords],
                           parameters=dict(parameters or {}) or None,
                           inputs=laws or None, method=method or sim.method,
                           rtol=sim.rtol if rtol is None else rtol,
                           atol=sim.atol if atol is None else atol,
                           t_eval=np.linspace(0.0, t1, n), progress=progress,
                           output=None if output is None else str(output))


def write_csv(results: Any, system: Any, path: Path) -> Path:
    """Save a simulation as CSV (the format of :meth:`jourdain.simulation.results.Results.save`)."""
    return results.save(path)
