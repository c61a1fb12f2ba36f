"""The linearization of a closed system about the nominal state or motion its user gives
(:meth:`jourdain.System.linearize` of a system with closing joints): about a state, a
:class:`jourdain.loops.linearization.LoopLinearization` in the independent coordinates
(time-invariant); about a motion (expressions of t) or a state held in a rheonomic system, a
time-variant :class:`jourdain.loops.periodic.ClosedLinearization` with its Floquet analysis."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from functools import lru_cache
from typing import Any

import numpy as np
import symengine as se

from ..errors import EvaluationError
from ..model import System
from ..model.validation import force_expressions
from ..stages.kinematics import kinematics
from ..stages.linearization.nominal import NOMINAL_RTOL
from .closed_loop import LoopEvaluator, constraints
from .linearization import LoopLinearization, linearize_loop, linearize_loop_exact
from .periodic import ClosedLinearization, linearize_along


@lru_cache(maxsize=32)
def _mentions_t(system: System) -> bool:
    """Whether t appears explicitly anywhere the closed equations come from: the tree's
    kinematics (a prescribed motion), a force element's law (an excitation) or a closing
    row."""
    t = system.t
    kin = kinematics(system.tree)
    exprs = [e for bk in kin.bodies for m in (bk.r_O, bk.S) for e in m.entries()]
    exprs += [e for f in system.forces for e in force_expressions(f)]
    exprs += constraints(system).Phi.entries()
    return any(t in se.sympify(e).free_symbols for e in exprs)


def _time_variant(system: System, lin: LoopLinearization, y: np.ndarray, yd: np.ndarray,
                  ydd: Any, parameters: Mapping[str, float] | None) -> bool:
    """Whether M̃, P, Q change with t at the state held: tested at two more times where t
    appears at all (:func:`_mentions_t`), as the numeric linearization of trees does."""
    if not _mentions_t(system):
        return False
    for t in (0.318309886, 1.2732395447):
        other = linearize_loop(system, lin.z_s, yd, t, ydd, parameters)
        for a, b in ((lin.M_tilde, other.M_tilde), (lin.P, other.P), (lin.Q, other.Q)):
            if a.shape != b.shape:
                return True
            scale = max(1.0, float(np.abs(a).max(initial=0.0)))
            if np.abs(a - b).max(initial=0.0) > 1e-8 * scale:
                return True
    return False


def _at_rest_in_equilibrium(lin: LoopLinearization, yd: np.ndarray, ydd: Any) -> bool:
    """At rest (ẏ_s = ÿ_s = 0) where ``h`` vanishes against the forces at work (M̃ and Q of
    the differences as their scale): an equilibrium, where the exact linearization of
    :func:`linearize_loop_exact` holds."""
    if np.any(yd != 0) or (ydd is not None and np.any(np.asarray(ydd) != 0)):
        return False
    scale = float(np.abs(lin.Q).max(initial=0.0)) * (1.0 + float(np.abs(lin.z_s).max()))
    return float(np.abs(lin.h).max(initial=0.0)) <= NOMINAL_RTOL * max(scale, 1e-300)


def _is_motion(v: Any) -> bool:
    """A nominal value that is an expression (of t and the parameters), not a number."""
    if isinstance(v, se.Basic):
        return not v.is_Number
    return False


def linearize_closed(system: System, nominal: Any, inputs: Mapping[str, float] | None = None,
                     parameters: Mapping[str, float] | None = None
                     ) -> LoopLinearization | ClosedLinearization:
    """:meth:`jourdain.System.linearize` of a closed system about the state ``nominal``: a
    mapping ``{coordinate: value, "<coordinate>_d": rate, "<coordinate>_dd": acceleration}``
    (constant numbers; coordinates left out are 0 and assembled) or the f tree coordinates.
    Expressions of t and the parameters for the independent coordinates give the
    linearization about that nominal motion
    (:class:`jourdain.loops.periodic.ClosedLinearization`, with its Floquet analysis)."""
    from ..errors import ClosedSystemError

    if inputs:
        raise ClosedSystemError(system, "a linearization with nominal inputs is not available "
                                "for closed systems yet")
    names = system.coordinate_names
    f = system.f
    y, yd = np.zeros(f), np.zeros(f)
    ydd: Any = None
    if isinstance(nominal, Mapping) and any(_is_motion(v) for v in nominal.values()):
        return linearize_along(system, nominal, parameters)  # a motion: expressions of t
    if isinstance(nominal, Mapping):
        acc: dict[str, float] = {}
        for k, v in nominal.items():
            key = str(k)
            try:
                val = float(v)
            except (TypeError, ValueError):
                raise EvaluationError(f"nominal {key}: expected a number or a SymEngine "
                                      f"expression of t and the parameters, got {v!r}"
                                      ) from None
            if key in names:
                y[names.index(key)] = val
            elif key.endswith("_dd") and key[:-3] in names:
                acc[key[:-3]] = val
            elif key.endswith("_d") and key[:-2] in names:
                yd[names.index(key[:-2])] = val
            else:
                raise EvaluationError(f'nominal: unknown coordinate "{key}"; coordinates are '
                                      f"{', '.join(names)}")
        if acc:
            ydd = acc
    else:
        y = np.asarray(nominal, dtype=float).reshape(-1)
        if y.size != f:
            raise EvaluationError(f"nominal: {f} coordinates expected ({', '.join(names)}), "
                                  f"got {y.size}")
    if isinstance(ydd, dict):  # accelerations of the independent coordinates, by name
        ev = LoopEvaluator(system, y, 0.0, parameters)
        ydd = np.array([ydd.get(c, 0.0) for c in ev.independent_names])
    lin = linearize_loop(system, y, yd, 0.0, ydd, parameters)
    if isinstance(nominal, Mapping) and not any(k.endswith("_d") for k in map(str, nominal)) \
            and _time_variant(system, lin, y, yd, ydd, parameters):
        # a rheonomic system (a prescribed motion, an excitation in t): the matrices change
        # along the nominal state held, a linear time-variant system (its Floquet analysis)
        held = {c: se.Float(float(v)) for c, v in zip(names, lin.z_s, strict=True)}
        return linearize_along(system, held, parameters)
    if _at_rest_in_equilibrium(lin, yd, ydd):
        # the symbolic derivatives there (the constraint forces' geometric stiffness
        # included): exact where the differences carry an error of about eps^(2/3)
        lin = linearize_loop_exact(system, lin.z_s, 0.0, parameters)
    pars = system.parameter_values
    pars.update(dict(parameters or {}))
    return replace(lin, system=system, parameters=pars)


def linearize_state(system: System, nominal: Any,
                    parameters: Mapping[str, float] | None = None) -> LoopLinearization:
    """:func:`linearize_closed` about a state, where a time-invariant result is needed (a
    stability map, the report's eigenvalues): ClosedSystemError when the closed system's
    linearization there changes with t (judge it by its Floquet analysis instead)."""
    from ..errors import ClosedSystemError

    lin = linearize_closed(system, nominal, None, parameters)
    if not isinstance(lin, LoopLinearization):
        raise ClosedSystemError(system, "its linearization changes with t (a prescribed motion "
                                "or an excitation): eigenvalues at one instant decide nothing; "
                                "use the Floquet analysis over a period")
    return lin


__all__ = ["linearize_closed", "linearize_state"]
