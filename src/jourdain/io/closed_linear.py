"""The linearization of a model with closing joints for ``jourdain linearize``, ``jourdain eval``
and the report (:func:`jourdain.io.capabilities.linear_analysis` and ``linearization_at``
dispatch here): in the independent coordinates, about a nominal state of the model file or
the equilibrium nearest its initial configuration (:func:`jourdain.loops.linearization.equilibrium`;
exact: :func:`~jourdain.loops.linearization.linearize_loop_exact`), or about the initial
configuration at rest where no equilibrium is found nearby (finite differences); about a
periodic nominal motion, its Floquet analysis (:mod:`jourdain.loops.periodic`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from ..errors import ClosedSystemError, JourdainError
from ..loops.linearization import (
    LoopLinearization,
    equilibrium,
    linearize_loop,
)
from ..loops.nominal import linearize_closed, linearize_state
from ..model import System


def linearize_near(loop: System, z0: Any,
                   parameters: Mapping[str, float] | None = None
                   ) -> tuple[LoopLinearization, str]:
    """The linearization about the equilibrium nearest ``z0``, else about ``z0`` at rest;
    with the words saying which (:func:`jourdain.loops.nominal.linearize_state`: exact at the
    equilibrium, central differences elsewhere; ClosedSystemError where it changes with t)."""
    state, about = _nearest_state(loop, z0, parameters)
    return linearize_state(loop, state, parameters), about


def _nearest_state(loop: System, z0: Any, parameters: Mapping[str, float] | None
                   ) -> tuple[dict[str, float], str]:
    """The equilibrium nearest ``z0`` (else ``z0`` itself, at rest) by coordinate, with the
    words saying which."""
    try:
        z_s = equilibrium(loop, z0, parameters=parameters)
        about = "equilibrium nearest the initial configuration"
    except JourdainError as exc:
        z_s = np.asarray(z0, dtype=float)
        about = f"initial configuration at rest (no equilibrium: {exc})"
    return dict(zip(loop.coordinate_names, z_s.tolist(), strict=True)), about


def linearization_document(loop: System, lin: LoopLinearization, about: str
                           ) -> dict[str, Any]:
    """A linearization of :func:`linearize_near` as a JSON-able document."""
    ev = lin.eigenvalues

    def mat(a: np.ndarray) -> list:
        return np.asarray(a, dtype=float).tolist()
    return {
        "model": loop.name, "about": about, "independent": list(lin.names),
        "z_s": dict(zip(loop.coordinate_names, lin.z_s.tolist(), strict=True)),
        "M_tilde": mat(lin.M_tilde), "P": mat(lin.P), "Q": mat(lin.Q), "h": mat(lin.h),
        "D": mat(lin.D), "G": mat(lin.G), "K": mat(lin.K), "N": mat(lin.N),
        "eigenvalues": [[float(v.real), float(v.imag)] for v in ev],
        "frequencies_hz": sorted({round(abs(float(v.imag)) / (2 * math.pi), 12)
                                  for v in ev if v.imag > 0}),
        "stable": bool(np.all(ev.real < 0)),
        "method": ("symbolic derivatives of the tree's k, q and of Φ (with the constraint "
                   "forces' geometric stiffness), projected with J_z"
                   if about.startswith("equilibrium") else
                   "central differences of the compiled M, k, q in the independent "
                   "coordinates"),
    }


def closed_linearization_at(system: System, y: Any, yd: Any, t: float,
                            parameters: Mapping[str, float], inputs: Mapping[str, float]
                            ) -> dict[str, np.ndarray]:
    """``M_tilde, P, Q, h, D, G, K, N`` of the closed ``system`` in its independent coordinates
    about the state assembled from (y, ẏ) at time t with ÿ_s = 0 (what
    :func:`jourdain.io.capabilities.linearization_at` gives a tree)."""
    if any(float(v) != 0.0 for v in dict(inputs).values()):
        raise ClosedSystemError(system, "the linearization of a closed system about nonzero "
                                "inputs is not available yet")
    lin = linearize_loop(system, np.asarray(y, dtype=float), np.asarray(yd, dtype=float),
                         float(t), None, dict(parameters) or None)
    return {k: np.asarray(getattr(lin, k), dtype=float)
            for k in ("M_tilde", "P", "Q", "h", "D", "G", "K", "N")}


def closed_linear_analysis(model: Any, about: str | None,
                           parameters: Mapping[str, float] | None = None, t: float = 0.0,
                           period: float | None = None) -> dict[str, Any]:
    """:func:`jourdain.io.capabilities.linear_analysis` of a model with closing joints: the
    linearization in the independent coordinates about the nominal state ``about`` (constant
    numbers) or, without it, about the equilibrium nearest the initial configuration
    (:func:`linearize_near`); its numbers, modes and stability verdict (``closed``: True).
    ``period``: a number (evaluated by the caller, :func:`jourdain.io.capabilities.period_value`)
    for the Floquet analysis."""
    from ..analysis.modes import modes, stability

    system: System = model.system
    nominal = model.nominal_motion(about) if about is not None else None
    params = dict(parameters or {}) or None
    if period is not None:
        return _periodic(system, nominal, model.simulation.y0 or [0.0] * system.f, params, t,
                         period)
    if nominal is not None:
        mapping = dict(zip(system.coordinate_names, nominal.y, strict=True))
        lin = linearize_closed(system, mapping, dict(nominal.inputs) or None, params)
        if not isinstance(lin, LoopLinearization):  # time-variant: a periodic analysis only
            raise ClosedSystemError(system, f'the linearization about "{nominal.name}" changes '
                                    "with t: give its period (--periodic T, or period = in "
                                    "the nominal motion) for the Floquet analysis")
        where = f'nominal state "{nominal.name}"'
    else:
        lin, where = linearize_near(system, model.simulation.y0 or [0.0] * system.f, params)
    num = {k: np.asarray(getattr(lin, k), dtype=float)
           for k in ("M_tilde", "P", "Q", "h", "D", "G", "K", "N")}
    ss = lin.state_space()
    scale = max(1.0, *(float(np.abs(num[k]).max(initial=0.0)) for k in ("M_tilde", "P", "Q")))
    conservative = bool(np.abs(num["D"]).max(initial=0.0) <= 1e-9 * scale
                        and np.abs(num["N"]).max(initial=0.0) <= 1e-9 * scale
                        and np.abs(num["h"]).max(initial=0.0) <= 1e-9 * scale)
    return {"closed": True, "system": system, "linearization": lin, "about": where,
            "nominal": nominal, "numbers": num, "time_invariant": True, "t": t,
            "conservative": conservative, "h_norm": float(np.abs(num["h"]).max(initial=0.0)),
            "cyclic": (), "modes": modes(ss), "stability": stability(ss, cyclic=()),
            "floquet": None, "nominal_check": None}


def _periodic(system: System, nominal: Any, y0: Any, params: Mapping[str, float] | None,
              t: float, T: float) -> dict[str, Any]:
    """The Floquet analysis of the closed ``system`` about the ``nominal`` motion (None: the
    equilibrium nearest ``y0``) over the period ``T`` from ``t``."""
    import symengine as se

    from ..analysis.floquet import floquet
    from ..loops.periodic import ClosedLinearization, linearize_along

    if nominal is not None:
        mapping = dict(zip(system.coordinate_names, nominal.y, strict=True))
        lin = linearize_closed(system, mapping, dict(nominal.inputs) or None, params)
        where = f'nominal motion "{nominal.name}"'
    else:  # the equilibrium nearest the initial configuration, as without --periodic
        state, where = _nearest_state(system, y0, params)
        lin = linearize_closed(system, state, None, params)
    if not isinstance(lin, ClosedLinearization):  # time-invariant: held over the period
        lin = linearize_along(system, {c: se.Float(float(v)) for c, v in
                                       zip(system.coordinate_names, lin.z_s, strict=True)},
                              params)
    fl = floquet(lin, T, t0=t)  # type: ignore[arg-type]  # its own floquet method
    num = lin.evaluate(t)
    return {"closed": True, "periodic": True, "system": system, "linearization": lin,
            "about": where, "nominal": nominal,
            "numbers": {k: num[k] for k in ("M_tilde", "P", "Q", "h")},
            "time_invariant": False, "t": t, "conservative": None,
            "h_norm": float(np.abs(num["h"]).max(initial=0.0)), "cyclic": (), "modes": None,
            "stability": None, "floquet": fl, "nominal_check": None, "period": T}


def closed_jsonable(res: Mapping[str, Any]) -> dict[str, Any]:
    """:func:`closed_linear_analysis` as JSON-ready data: the keys of a tree's
    (:func:`jourdain.io.capabilities.jsonable`: ``matrices``, ``eigenvalues``,
    ``natural_frequencies_hz``, ``damping_ratios``, ``stability``, ...) and those of
    :func:`linearization_document` (``independent``, ``about``, ``z_s``, ``M_tilde`` ...
    ``N``, ``frequencies_hz``, ``stable``, ``method``)."""
    def finite(a: Any) -> list[float | None]:
        return [float(x) if np.isfinite(x) else None for x in np.asarray(a, float)]
    if res.get("periodic"):
        fl = res["floquet"]
        lin = res["linearization"]
        return {
            "model": res["system"].name, "about": res["about"], "independent": list(lin.names),
            "nominal": res["nominal"].name if res["nominal"] is not None else None,
            "t": res["t"], "time_invariant": False,
            "h_norm": res["h_norm"], "period": res["period"],
            "matrices": {k: np.asarray(v, float).tolist() for k, v in res["numbers"].items()},
            "floquet": {"multipliers": [[float(v.real), float(v.imag)]
                                        for v in fl.multipliers],
                        "verdict": fl.verdict, "reason": fl.reason,
                        "tolerance": fl.tolerance, "state_names": list(fl.state_names)},
        }
    m, s = res["modes"], res["stability"]
    out: dict[str, Any] = {
        "nominal": res["nominal"].name if res["nominal"] is not None else None,
        "t": res["t"], "time_invariant": True, "conservative": res["conservative"],
        "h_norm": res["h_norm"],
        "matrices": {k: np.asarray(v, float).tolist() for k, v in res["numbers"].items()},
        "cyclic_coordinates": [],
        "natural_frequencies_hz": finite(m.frequencies_hz),
        "damping_ratios": finite(m.damping_ratios),
        "stability": {"verdict": s.verdict, "reason": s.reason,
                      "max_real_part": float(s.max_real_part), "cyclic": list(s.cyclic)},
    }
    out.update(linearization_document(res["system"], res["linearization"], res["about"]))
    return out


def closed_linear_text(res: Mapping[str, Any]) -> str:
    """A plain-text account of :func:`closed_linear_analysis`, in the order of a tree's
    (:func:`jourdain.io.capabilities.linear_text`)."""
    from .export import format_array

    doc = closed_jsonable(res)
    num = res["numbers"]
    if res.get("periodic"):
        head = [f"{doc['model']}: linearized in the independent coordinates "
                f"{', '.join(doc['independent'])} about the {doc['about']} (time-variant; "
                f"numbers at t = {res['t']:g})"]
        for k in ("M_tilde", "P", "Q", "h"):
            head.append(f"\n{k} =\n{format_array(num[k])}")
        head.append(f"\nFloquet analysis over T = {res['period']:.6g}:\n{res['floquet']}")
        return "\n".join(head)
    lines = [f"{doc['model']}: linearized in the independent coordinates "
             f"{', '.join(doc['independent'])} about the {doc['about']}",
             "  y_s = " + ", ".join(f"{k} = {v:.6g}" for k, v in doc["z_s"].items()),
             "  M̃·η̈ + P·η̇ + Q·η = h  (η: the independent coordinates; time-invariant: "
             f"numbers at t = {res['t']:g})"]
    scales = {"D": num["P"], "G": num["P"], "K": num["Q"], "N": num["Q"]}
    for k in ("M_tilde", "P", "Q", "h", "D", "G", "K", "N"):
        lines.append(f"\n{k} =\n{format_array(num[k], scales.get(k))}")
    lines.append("\nconservative (D = 0, N = 0, h = 0): "
                 + ("yes" if res["conservative"] else "no"))
    lines.append("\neigenvalues of the state-space system:\n" + str(res["modes"]))
    if doc["frequencies_hz"]:
        lines.append("frequencies: " + ", ".join(f"{f:.6g} Hz" for f in doc["frequencies_hz"]))
    lines.append(f"\nstability: {res['stability']}")
    lines.append(f"({doc['method']})")
    return "\n".join(lines)


__all__ = ["closed_jsonable", "closed_linear_analysis", "closed_linear_text",
           "closed_linearization_at", "linearization_document", "linearize_near"]
