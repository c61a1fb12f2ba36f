"""Reactions of the closing joints by name (issue 11): the multipliers λ of each closing
joint's rows assembled into the force ``F`` and the torque ``T`` that body B exerts on body
A at A's joint point, in A's frame (the joint's axes: ``axis`` and ``point_a`` are given in
it), like the tree joints' reactions (:mod:`jourdain.stages.reactions`). Body B feels
``−F`` and ``−T − (p_A − p_B) × F`` about its own joint point.

The virtual work of the constraint forces is ``δΦᵀλ`` (:mod:`jourdain.loops.closing_joints`):

* a row ``p_A − p_B`` (component k, inertial) contributes the force ``λ·e_k``;
* a row ``a·b`` (``a`` fixed in A, ``b`` in B) contributes the torque ``λ·(a × b)``;
* a row ``(p_B − p_A)·w`` (``w`` fixed in A: prismatic, point on a line or a plane)
  contributes the force ``−λ·w`` acting at ``p_B``: about ``p_A`` also the torque
  ``(p_B − p_A) × (−λ·w)``.

A ``constraint`` closing joint (scalar expressions) has no points: its reactions stay the
generalized multipliers λ (``<name>.1``, …). Where a planar model drops the out-of-plane rows
their components are zero (not determined by a planar motion).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
import symengine as se

from ..model import System
from ..model.closing import ZERO3
from ..model.expressions import Mat3, Vec3
from ..numeric import CompiledFunction, lambdify, parameter_vector
from ..stages.kinematics import _cross, _mv, kinematics
from ..symbolic import SymMatrix
from .closed_loop import constraints

_IDENT = ((se.Integer(1), se.Integer(0), se.Integer(0)),
          (se.Integer(0), se.Integer(1), se.Integer(0)),
          (se.Integer(0), se.Integer(0), se.Integer(1)))


@dataclass(frozen=True)
class ClosingReactions:
    """The wrench map of the closing joints: ``W`` (6 × m, symbolic in z): the force (rows
    0–2) and torque (rows 3–5) on A in A's frame per unit multiplier of each constraint
    row; ``joints``: the closing joints with points, each with the indices of its rows."""

    W: SymMatrix
    joints: tuple[tuple[str, tuple[int, ...]], ...]
    #: the same in inertial components
    W_inertial: SymMatrix


@lru_cache(maxsize=16)
def closing_wrench_map(loop: System) -> ClosingReactions:
    """The symbolic wrench map of :class:`ClosingReactions` for ``loop``."""
    kin = kinematics(loop.tree)
    con = constraints(loop)
    by_name = {cj.name: cj for cj in loop.closing}
    cols: list[list[se.Basic]] = []
    cols_in: list[list[se.Basic]] = []
    joints: dict[str, list[int]] = {}
    for i, row in enumerate(con.rows):
        cj = by_name[row.joint]
        if cj.type == "constraint" or row.direction is None:
            cols.append([se.Integer(0)] * 6)
            cols_in.append([se.Integer(0)] * 6)
            continue
        joints.setdefault(cj.name, []).append(i)
        rA, SA = _frame(kin, cj.body_a)
        rB, SB = _frame(kin, cj.body_b)
        pA = tuple(rA[k] + _mv(SA, cj.point_a)[k] for k in range(3))
        pB = tuple(rB[k] + _mv(SB, cj.point_b)[k] for k in range(3))
        d = row.direction
        if row.kind == "force":
            F: Vec3 = d
            # rows (p_B − p_A)·w act at p_B: their moment about p_A
            T: Vec3 = (ZERO3 if cj.type in ("spherical", "revolute", "universal")
                       else _cross((pB[0] - pA[0], pB[1] - pA[1], pB[2] - pA[2]), d))
        else:
            F, T = ZERO3, d
        # into A's frame: S_Aᵀ·v
        SAt: Mat3 = ((SA[0][0], SA[1][0], SA[2][0]), (SA[0][1], SA[1][1], SA[2][1]),
                     (SA[0][2], SA[1][2], SA[2][2]))
        cols.append([*_mv(SAt, F), *_mv(SAt, T)])
        cols_in.append([*F, *T])
    W = SymMatrix.from_rows([[cols[j][k] for j in range(len(cols))] for k in range(6)])
    W_in = SymMatrix.from_rows([[cols_in[j][k] for j in range(len(cols))] for k in range(6)])
    return ClosingReactions(W, tuple((n, tuple(ix)) for n, ix in joints.items()), W_in)


def _frame(kin: Any, body: str) -> tuple[Vec3, Any]:
    if body == "world":
        return ZERO3, _IDENT
    bk = kin[body]
    r = bk.r_O.rows
    return (r[0][0], r[1][0], r[2][0]), bk.S.rows


@lru_cache(maxsize=16)
def _wrench_function(loop: System) -> CompiledFunction:
    cr = closing_wrench_map(loop)
    return lambdify(loop.tree, {"W": cr.W, "W_inertial": cr.W_inertial})


def closing_reactions(loop: System, z: Any, lam: Any, t: Any = 0.0,
                      p: Any = None) -> dict[str, dict[str, np.ndarray]]:
    """The force ``F`` and torque ``T`` (N × 3 each, in A's frame, B on A at A's joint point;
    ``F_inertial``, ``T_inertial``: inertial components) of every closing joint with points, from configurations ``z`` (N × n) and multipliers
    ``lam`` (N × m, in the order of ``constraints(loop).labels``). ``p``: the parameter
    vector (default: the tree's values)."""
    z = np.atleast_2d(np.asarray(z, dtype=float))
    lam = np.atleast_2d(np.asarray(lam, dtype=float))
    fn = _wrench_function(loop)
    pv = parameter_vector(loop.tree, None) if p is None else np.asarray(p, dtype=float)
    Ws = fn.batch(z, np.zeros_like(z), t, pv, np.zeros(len(loop.tree.inputs)))
    out: dict[str, dict[str, np.ndarray]] = {}
    for name, ix in closing_wrench_map(loop).joints:
        cols = list(ix)
        w = np.einsum("nij,nj->ni", Ws["W"][:, :, cols], lam[:, cols])
        wi = np.einsum("nij,nj->ni", Ws["W_inertial"][:, :, cols], lam[:, cols])
        out[name] = {"F": w[:, :3], "T": w[:, 3:], "F_inertial": wi[:, :3],
                     "T_inertial": wi[:, 3:]}
    return out


__all__ = ["ClosingReactions", "closing_reactions", "closing_wrench_map"]
