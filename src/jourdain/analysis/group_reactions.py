"""Reactions of a system with elastic bodies (:class:`jourdain.model.bodies.BodyGroup`).

The joints inside an elastic body (its nodes', points' and attachment frames') all move with
the body's elastic coordinates: they have no reactions of their own, and Q̄, N̂ of the whole
system are not formed. Every other joint — the hinge an elastic body hangs from, the joints of
what hangs from its attachment frames, any rigid part of the model — transmits the wrench that
the residual ``M̄·J̄·ÿ + q̄^c − q̄^e`` of the sub-tree it carries gives
(:func:`jourdain.analysis.reactions.joint_reactions`): its components ``g`` along the joint's
constrained directions and its wrench (:mod:`jourdain.wrenches`), at one state
(:meth:`System.evaluate`) and along a simulated motion (``Results.g``,
``Results.joint_wrenches``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import JourdainError
from ..wrenches import joint_wrenches, joint_wrenches_along
from .reactions import _joint_function, _refuse_friction, joint_components, joint_reactions

if TYPE_CHECKING:
    from ..model.system import System

__all__ = ["ordinary_joints", "group_reactions", "group_reactions_along",
           "group_wrenches_along"]


def ordinary_joints(system: System) -> list[str]:
    """The joints of ``system`` outside its elastic bodies, in body order."""
    inner = {j for g in system.groups for j in g.internal_joints()}
    return [b.joint.name for b in system.bodies if b.joint.name not in inner]


def _note(system: System) -> str:
    return ("the joints inside elastic bodies (" + ", ".join(g.name for g in system.groups)
            + ") share the bodies' elastic coordinates and have no reactions of their own; "
            "the other joints' reactions come from the sub-trees they carry")


def group_reactions(system: System, y: Any, yd: Any, t: float, parameters: Any,
                    inputs: Any) -> dict[str, Any]:
    """The reaction entries of :meth:`System.evaluate` for a system with elastic bodies:
    ``g``, ``g_names``, ``g_undetermined`` of the ordinary joints, their ``joint_wrenches``
    and ``reactions_note``; ``{"reactions_error": message}`` where they cannot be had."""
    try:
        only = tuple(ordinary_joints(system))
        g = joint_reactions(system, list(only), y, yd, t, parameters, inputs)
        names = list(g)
        vals = np.array([g[n] for n in names], dtype=float)
        wrenches = joint_wrenches(system, vals, y, yd, t, parameters, only)
    except JourdainError as exc:
        return {"reactions_error": str(exc)}
    return {"g": vals, "g_names": names,
            "g_undetermined": [n for n, v in zip(names, vals, strict=True) if np.isnan(v)],
            "joint_wrenches": wrenches, "reactions_note": _note(system)}


def group_reactions_along(system: System, results: Any) -> tuple[np.ndarray, list[str]]:
    """``g`` (N, components) of the ordinary joints along a simulated motion and its column
    names: each sample's ÿ from the equations of motion and each joint's sub-tree residual
    (the compiled function of :func:`jourdain.analysis.reactions.joint_reactions`, one batch
    over the samples)."""
    _refuse_friction(system)
    info, fn = _joint_function(system, tuple(ordinary_joints(system)))
    p = np.array([results.parameters[k] for k, _ in system.parameters])
    batch = fn.batch(results.y, results.yd, results.t, p,
                     results.u if results.u.shape[1] else None)
    names = [f"{name}.{sfx}" for name, suffixes in info for sfx in suffixes]
    g = np.empty((len(results.t), len(names)))
    for k, tk in enumerate(results.t):
        row = joint_components(info, {n: v[k] for n, v in batch.items()}, f"at t = {tk:.9g}")
        g[k] = [row[n] for n in names]
    return g, names


def group_wrenches_along(system: System, g: np.ndarray, t: np.ndarray, y: np.ndarray,
                         yd: np.ndarray, parameters: np.ndarray) -> dict[str, Any]:
    """The wrenches of the ordinary joints along a motion from their ``g`` (N, components, in
    the order of :func:`group_reactions_along`), ``{joint: JointWrench}``."""
    return joint_wrenches_along(system, g, t, y, yd, parameters, tuple(ordinary_joints(system)))
