"""Every matrix and vector of the method at one state, and their JSON form.

``jourdain eval`` prints it and the report tabulates it (``values.json``: the same document);
``jourdain eom`` and the report's equations section show the symbolic matrices of
:func:`eom_matrices`. The stages come from :meth:`~jourdain.System.evaluate` and
:mod:`jourdain.io.capabilities` (the linearization about the state).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import EvaluationError, JourdainError
from ..io import capabilities
from ..numeric import evaluate
from ..units import value_units
from .capability import NotAvailable, require

#: The format tag of ``jourdain eval --json`` and of the report's ``values.json`` (bump the
#: number on incompatible changes).
EVAL_FORMAT = "jourdain-eval/1"

#: the quantities of the reactions stage (docs/method.md, reaction forces)
REACTION_NAMES = ("Q_bar", "N_hat", "k_hat", "q_hat", "g")
#: the quantities of the linearization about the state
LINEARIZATION_NAMES = ("M_tilde", "P", "Q", "h", "D", "G", "K", "N")


def eom_matrices(system: Any) -> dict[str, Any]:
    """The symbolic Newton–Euler matrices M̄, J̄, q̄^c, q̄^e and the equations of motion M, k, q
    by the method's names; for a closed system those of :func:`closed_eom_matrices`."""
    if system.closing:
        return closed_eom_matrices(system)
    eom = system.equations_of_motion()
    ne = eom.newton_euler
    return {"M_bar": ne.M_bar, "J_bar": ne.J_bar, "q_c": ne.q_c, "q_e": ne.q_e,
            "M": eom.M, "k": eom.k, "q": eom.q}


def closed_eom_matrices(system: Any) -> dict[str, Any]:
    """The symbolic equations of a closed system (METHOD §7): the tree's Newton–Euler matrices
    M̄, J̄, q̄^c, q̄^e of ``M̄·J̄·ÿ + q̄^c = q̄^e + Q̄·g``, the closing rows' constrained
    directions ``Q_bar_c`` (6p×r, ``J̄ᵀ·Q̄_c = Φ_yᵀ``), the constraint rows ``Phi`` (r) and
    ``Phi_y`` (r×f), and the tree's projected ``M_tree, k_tree, q_tree`` of
    ``M_tree·ÿ + k_tree = q_tree + Φ_yᵀ·λ``. The projection onto the independent coordinates
    (``ẏ = L·ẏ_i + l``, ``L = [E; −Φ_d⁻¹Φ_i]``) exists in numbers only (:func:`evaluate_all`):
    the dependent coordinates are implicit functions of the independent ones."""
    eom = system.tree.equations_of_motion()
    ne = eom.newton_euler
    con = system.constraints()
    return {"M_bar": ne.M_bar, "J_bar": ne.J_bar, "q_c": ne.q_c, "q_e": ne.q_e,
            "Q_bar_c": con.Q_bar, "Phi": con.Phi, "Phi_y": con.Phi_y,
            "M_tree": eom.M, "k_tree": eom.k, "q_tree": eom.q}


def evaluate_all(model: Any, y: np.ndarray, yd: np.ndarray, t: float,
                 parameters: dict[str, float], inputs: dict[str, float]
                 ) -> tuple[dict[str, np.ndarray], dict[str, Any], dict[str, str]]:
    """Every matrix and vector of the method at one state.

    Returns the arrays by the method's names, extra information (``g_names``,
    ``g_undetermined``, ``joint_wrenches``) and, for what is missing, the reason.
    """
    system = model.system
    missing: dict[str, str] = {}
    try:
        out = dict(system.evaluate(y, yd, t=t, parameters=parameters or None,
                                   inputs=inputs or None))
    except JourdainError as exc:
        if system.closing:  # no open-tree fallback: its numbers are not the closed system's
            raise
        # the equations of motion alone, when a later stage (the reactions) cannot be formed
        out = dict(evaluate(system, y, yd, t=t, parameters=parameters or None,
                            inputs=inputs or None))
        missing.update({k: f"the reaction forces could not be formed: {exc}"
                        for k in REACTION_NAMES})
    values = {k: np.asarray(v, float) for k, v in out.items() if isinstance(v, np.ndarray)}
    extra = {k: v for k, v in out.items() if not isinstance(v, np.ndarray)}
    error = extra.pop("reactions_error", None)
    if error:
        missing.update({k: f"the reaction forces could not be formed: {error}"
                        for k in REACTION_NAMES})
    why = extra.get("reactions_note")  # elastic bodies: g of the ordinary joints only
    for k in REACTION_NAMES:
        if k not in values and k not in missing:
            missing[k] = (f"not formed: {why}" if why else
                          "the reaction forces are not available yet in this version of "
                          "jourdain")
    try:
        values.update(linearization_at(model, y, yd, t, parameters, inputs))
    except NotAvailable as exc:
        missing.update({k: str(exc) for k in LINEARIZATION_NAMES})
    except JourdainError as exc:
        missing.update({k: f"the linearization could not be formed: {exc}"
                        for k in LINEARIZATION_NAMES})
    check_finite(system, values, extra, t)
    return values, extra, missing


def check_finite(system: Any, values: dict[str, np.ndarray], extra: dict[str, Any],
                 t: float) -> None:
    """An :class:`EvaluationError` naming every quantity that holds inf or NaN, NaN in the
    undetermined components of g excepted (``null`` in the JSON means undetermined, never an
    overflow): ½(Q + Qᵀ) of entries near 1e308 overflows where Q itself is finite."""
    undetermined = set(extra.get("g_undetermined", ()))
    names = list(extra.get("g_names", ()))
    overflow, nan = [], []
    for k, v in values.items():
        a = np.asarray(v, float)
        if k == "g" and names and a.size == len(names):
            a = a[[n not in undetermined for n in names]]
        if np.isinf(a).any():
            overflow.append(k)
        elif np.isnan(a).any():
            nan.append(k)
    if not (overflow or nan):
        return
    parts = []
    if overflow:
        parts.append(f"{', '.join(overflow)} overflow{'s' if len(overflow) == 1 else ''} (inf: beyond the floating-point range, "
                     "about 1.8e308)")
    if nan:
        parts.append(f"{', '.join(nan)} hold{'s' if len(nan) == 1 else ''} NaN")
    raise EvaluationError(f"{'; '.join(parts)} for {system.name!r} at t = {t:g}: the numbers of "
                          "the model are too large (check the magnitudes of its parameters and "
                          "constants)")


def reactions_at(system: Any, y: Any, yd: Any, t: float, parameters: dict[str, float],
                 inputs: dict[str, float]) -> dict[str, Any]:
    """Q̄, N̂, k̂, q̂ and g (with ``g_names``, ``g_undetermined``) at one state."""
    require(system, "reactions", "the reaction forces (jourdain reactions)")
    return capabilities.reactions_at(system, y, yd, t, parameters, inputs)


def linearization_at(model: Any, y: Any, yd: Any, t: float, parameters: dict[str, float],
                     inputs: dict[str, float]) -> dict[str, np.ndarray]:
    """M̃, P, Q, h and the split D, G, K, N about the motion through one state."""
    require(model.system, "linearize", "the linearization (jourdain linearize)")
    return capabilities.linearization_at(model, y, yd, t, parameters, inputs)


def json_array(v: np.ndarray) -> Any:
    """Nested lists with NaN (an undetermined reaction) as null."""
    a = np.asarray(v, float)
    if a.ndim == 0:
        return float(a) if np.isfinite(a) else None
    return [json_array(x) for x in a]


def eval_document(model: Any, y: np.ndarray, yd: np.ndarray, t: float,
                  parameters: dict[str, float], inputs: dict[str, float],
                  values: dict[str, np.ndarray], extra: dict[str, Any],
                  missing: dict[str, str]) -> dict[str, Any]:
    """The JSON document (:data:`EVAL_FORMAT`) of one evaluation by :func:`evaluate_all`:
    the state, the parameter values used (``parameters``: every one, overrides included),
    the numbers by name (NaN as null), the reaction labels, what is missing and why, the
    joint wrenches and the units of every quantity."""
    system = model.system
    g_names = list(extra.get("g_names", []))
    doc = {
        "format": EVAL_FORMAT, "model": system.name, "file": model.path,
        "coordinates": system.coordinate_names, "t": t, "y": np.asarray(y).tolist(),
        "yd": np.asarray(yd).tolist(), "parameters": parameters, "inputs": inputs,
        "values": {k: json_array(v) for k, v in values.items()},
        "g_names": g_names, "g_undetermined": list(extra.get("g_undetermined", [])),
        "not_available": missing,
        "joint_wrenches": {k: w.as_dict() for k, w in extra.get("joint_wrenches", {}).items()},
        "units": value_units(system, g_names),
    }
    if system.closing:  # the closed system's: its state assembled onto Φ = 0, Φ̇ = 0
        ind = list(extra.get("independent", []))
        units = dict(doc["units"])
        gen = dict(zip(system.coordinate_names, units["k"], strict=True))
        units["k"] = units["q"] = [gen[c] for c in ind]
        doc.update({
            "y": np.asarray(values.get("y", y)).tolist(),
            "yd": np.asarray(values.get("yd", yd)).tolist(),
            "units": units, "independent": ind,
            "constraint_labels": list(extra.get("constraint_labels", [])),
            "closure_residual": dict(extra.get("closure_residual", {})),
            "orthogonality": extra.get("orthogonality"),
            "closing_wrenches": {k: {n: json_array(v) for n, v in w.items()}
                                 for k, w in extra.get("closing_wrenches", {}).items()}})
    return doc
