"""Joint wrenches as numbers: the force and torque each joint transmits, by joint name.

The reactions ``g`` (METHOD.md §4, :mod:`jourdain.stages.reactions`) are the magnitudes of the
reaction forces and torques along each joint's constrained directions ``w_k`` (unit wrenches in
the child body frame at its origin, the joint point). The joint's wrench is their sum

    W_j = Σ_k g_k·w_k = (F, T)

— the force ``F`` and the torque ``T`` about the joint point that the parent body exerts on
the child body through the joint (the parent receives ``−F``, ``−T``). Components are given
in the *joint frame* (the child body frame at the joint point, where the components of g are
named: ``hinge1.F_x`` is ``F[0]`` of a revolute joint) and in the *inertial frame*
(``S_c·F``, ``S_c·T``, ``S_c`` the child body's orientation). This is Pinocchio's ``data.f``
of the joint (linear, angular) after RNEA, in the same frame.

Free directions transmit nothing (ideal joints; force elements across a joint are applied
forces, not reactions). A component of g that is undetermined (NaN: redundant directions, a
statically indeterminate joint) makes the components it enters NaN.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING, Any

import numpy as np

from .errors import EvaluationError
from .graph import evaluate_float
from .numeric import lambdify, state_vectors
from .numeric.diagnose import state_values
from .stages.kinematics import kinematics
from .stages.reactions import joint_directions
from .symbolic import SymMatrix

if TYPE_CHECKING:
    from .model.system import System


@dataclass(frozen=True)
class JointWrench:
    """The wrench a joint transmits to its child body, at one state (arrays of shape (3,)) or
    along a motion ((N, 3), one row per time).

    Attributes
    ----------
    joint, parent, child : str
        The joint and the bodies it connects (the wrench acts on ``child``, minus it on
        ``parent``).
    force, torque : arrays
        In the joint frame (the child body frame at the joint point); the torque about the
        joint point.
    force_inertial, torque_inertial : arrays
        The same vectors in inertial components.
    """

    joint: str
    parent: str
    child: str
    force: np.ndarray
    torque: np.ndarray
    force_inertial: np.ndarray
    torque_inertial: np.ndarray

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready data (lists; NaN as None): ``parent``, ``child``, ``frame`` (the child
        body's name), ``force``, ``torque``, ``force_inertial``, ``torque_inertial``."""
        def lst(a: np.ndarray) -> Any:
            a = np.asarray(a, float)
            if a.ndim == 0:
                return float(a) if np.isfinite(a) else None
            return [lst(x) for x in a]

        return {"parent": self.parent, "child": self.child, "frame": self.child,
                "force": lst(self.force), "torque": lst(self.torque),
                "force_inertial": lst(self.force_inertial),
                "torque_inertial": lst(self.torque_inertial)}


@lru_cache(maxsize=32)
def _layout(system: System, only: tuple[str, ...] | None = None
            ) -> tuple[tuple[Any, ...], list[Any], dict[str, SymMatrix]]:
    """The joints' constrained directions (of those in ``only`` where given), and per joint
    with directions its matrix ``E_k`` (6 × n_k, the unit wrenches as columns) and its child's
    orientation ``S_k``."""
    joints = joint_directions(system, only)
    kin = kinematics(system)
    mats: dict[str, SymMatrix] = {}
    for k, jr in enumerate(joints):
        if not jr.wrenches:
            continue
        mats[f"E_{k}"] = SymMatrix.from_rows([[w[a] for w in jr.wrenches] for a in range(6)])
        mats[f"S_{k}"] = kin[jr.child].S
    return joints, list(mats), mats


@lru_cache(maxsize=32)
def _compiled(system: System, only: tuple[str, ...] | None = None) -> Any:
    return lambdify(system, _layout(system, only)[2], lean=True)


def _assemble(joints: Sequence[Any], g: np.ndarray, nums: Mapping[str, np.ndarray]
              ) -> dict[str, JointWrench]:
    """Wrenches from g (..., q) and the numbers of ``E_k`` (..., 6, n_k), ``S_k`` (..., 3, 3)."""
    lead = g.shape[:-1]
    out: dict[str, JointWrench] = {}
    for k, jr in enumerate(joints):
        if jr.wrenches:
            E, S = nums[f"E_{k}"], nums[f"S_{k}"]
            W = np.einsum("...an,...n->...a", E, g[..., list(jr.columns)])
            F, T = W[..., :3], W[..., 3:]
            FI = np.einsum("...ab,...b->...a", S, F)
            TI = np.einsum("...ab,...b->...a", S, T)
        else:
            F = T = FI = TI = np.zeros((*lead, 3))
        out[jr.joint.name] = JointWrench(jr.joint.name, jr.parent, jr.child, F, T, FI, TI)
    return out


def joint_wrenches(system: System, g: Any, y: Any, yd: Any = None, t: float = 0.0,
                   parameters: Mapping[str, float] | None = None,
                   only: tuple[str, ...] | None = None) -> dict[str, JointWrench]:
    """The wrench of every joint (of those in ``only``) at one state from its reactions ``g``
    (q,), in the order of ``system.bodies``: ``{joint name: JointWrench}`` (see the module
    docstring).

    The constrained directions and the orientations are evaluated once in floating point
    (no compilation); :meth:`System.evaluate` returns these as ``joint_wrenches``.
    """
    joints, names, mats = _layout(system, only)
    # the directions and orientations do not depend on the inputs: zeros stand for them (None
    # is refused for a model with inputs)
    args = state_vectors(system, y, np.zeros(system.f) if yd is None else yd, t, parameters,
                         [0.0] * len(system.inputs))
    gv = np.asarray(g, dtype=float).reshape(-1)
    q = sum(len(jr.columns) for jr in joints)
    if gv.size != q:
        raise EvaluationError(f"joint_wrenches: g must have {q} components (g_names), got "
                              f"{gv.size}")
    flat = evaluate_float([e for n in names for e in mats[n].entries()],
                          state_values(system, *args))
    nums: dict[str, np.ndarray] = {}
    i = 0
    for n in names:
        r, c = mats[n].shape
        nums[n] = np.asarray(flat[i:i + r * c], dtype=float).reshape(r, c)
        i += r * c
    return _assemble(joints, gv, nums)


def joint_wrenches_along(system: System, g: np.ndarray, t: np.ndarray, y: np.ndarray,
                         yd: np.ndarray, parameters: np.ndarray,
                         only: tuple[str, ...] | None = None) -> dict[str, JointWrench]:
    """The wrenches along a motion: ``g`` (N, q), ``t`` (N,), ``y``, ``yd`` (N, f), the
    parameter vector (compiled once per system and ``only``; arrays (N, 3) in the result)."""
    joints, names, _ = _layout(system, only)
    if not names:
        return _assemble(joints, np.asarray(g, float), {})
    out = _compiled(system, only).batch(y, yd, t, parameters, None)
    return _assemble(joints, np.asarray(g, float), out)


def wrench_table(w: JointWrench, t: np.ndarray) -> tuple[list[str], np.ndarray]:
    """Column names and an (N, 13) table of one joint's wrench along a motion: t, then the
    force and torque in the joint frame, then in the inertial frame."""
    cols = ["t"] + [f"{w.joint}.{q}_{a}{frame}" for frame in ("", "_inertial")
                    for q in ("F", "T") for a in "xyz"]
    data = np.column_stack([np.asarray(t, float), w.force, w.torque, w.force_inertial,
                            w.torque_inertial])
    return cols, data
