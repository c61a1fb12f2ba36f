"""Checks of the constrained directions (``docs/method.md`` §4, orthogonality J̄ᵀ·Q̄ = 0):
joint by joint (each direction does no work in the joint's relative motion; directions and
motions span all six) and of the assembled matrices at random states (:func:`_check_assembled`,
also used before reaction forces are given in numbers). A direction that does work is a
:class:`ModelError` naming the joint and the direction.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from functools import lru_cache
from typing import TYPE_CHECKING, Any

import numpy as np
import symengine as se

from ...errors import ModelError
from ...model.joints import Joint, Rot
from ..kinematics import _dot

if TYPE_CHECKING:
    from ...model.system import System
from .joints import JointReactions, _sample_values, joint_directions, relative_twist


@lru_cache(maxsize=32)
def _checked_joints(system: System) -> dict[str, str]:
    """:func:`check_joints` of :func:`joint_directions` (ModelError for a direction that does
    work), once per system."""
    return check_joints(system, joint_directions(system))

def _step_coordinates(joint: Joint, coordinates: Sequence[se.Symbol]) -> list[se.Symbol]:
    """The coordinates that the joint's elementary steps depend on."""
    free: set = set()
    for st in joint.steps:
        exprs = [st.angle] if isinstance(st, Rot) else list(st.vector)
        for e in exprs:
            free |= e.free_symbols
    return [c for c in coordinates if c in free]


def check_joints(system: System, joints: Sequence[JointReactions], samples: int = 3,
                 seed: int = 7) -> dict[str, str]:
    """Joint by joint: every constrained direction does no work in the joint's relative motion
    (``wᵀ·ξ = 0``, the orthogonality relation ``J̄ᵀ·Q̄ = 0`` restricted to one joint), the
    directions and the motions of a joint span all six, and the joints' motions are independent
    (their ranks add up to f).

    The orthogonality is shown symbolically where the expanded products ``wᵀ·ξ`` vanish (unit
    directions, the torque normal to two axes); the rest, and the ranks, are checked numerically
    at random states (coordinates in (−π, π), t in (0, 2), parameters within 10 % of their
    defaults) on the joint's own short expressions. Raises :class:`ModelError` naming the joint
    and the direction. Returns, per joint, ``"symbolic"`` or ``"numeric"``: how its
    orthogonality was verified.
    """
    rng = np.random.default_rng(seed)
    params = system.parameter_values
    total = 0
    ranks: list[tuple[JointReactions, int]] = []
    how: dict[str, str] = {}
    for jr in joints:
        ys = _step_coordinates(jr.joint, system.coordinates)
        cols = relative_twist(jr.joint, ys)
        twist = [x for v, w in cols for x in (*v, *w)]
        wr = [x for w in jr.wrenches for x in w]
        how[jr.joint.name] = "symbolic" if all(
            se.expand(_dot(w[:3], v) + _dot(w[3:], om)) == 0
            for w in jr.wrenches for v, om in cols) else "numeric"
        vals = _sample_values(twist + wr, system.coordinates, params, rng, samples)
        X = vals[:len(twist)].reshape(len(ys), 6, samples)
        W = vals[len(twist):].reshape(len(jr.wrenches), 6, samples)
        rank = max((np.linalg.matrix_rank(X[:, :, k], tol=1e-9) for k in range(samples)),
                   default=0) if ys else 0
        ranks.append((jr, rank))
        total += rank
        for k in range(samples):
            power = W[:, :, k] @ X[:, :, k].T  # (directions, coordinates)
            scale = max(1.0, float(np.abs(X[:, :, k]).max(initial=0.0)))
            for d in range(len(jr.wrenches)):
                bad = np.nonzero(np.abs(power[d]) > 1e-9 * scale *
                                 max(1.0, float(np.abs(W[d, :, k]).max())))[0]
                if bad.size:
                    raise ModelError(
                        f'joint "{jr.joint.name}" (body "{jr.child}"): its constrained direction '
                        f'"{jr.names[d]}" does work in the joint\'s motion with coordinate '
                        f"{ys[int(bad[0])]} (relative power {abs(power[d, bad[0]]):.2e} per unit "
                        "rate); the orthogonality relation J̄ᵀ·Q̄ = 0 fails"
                    )
            both = np.concatenate([X[:, :, k], W[:, :, k]]) if ys else W[:, :, k]
            if both.shape[0] < 6 or np.linalg.matrix_rank(both, tol=1e-9) < 6:
                raise ModelError(
                    f'joint "{jr.joint.name}" (body "{jr.child}"): its {len(jr.names)} '
                    f"constrained directions and its {rank} directions of motion do not span "
                    "all six; a reaction would be missing from Q̄ (give the missing directions "
                    "in constrained=[...])"
                )
    if total > system.f and system.groups:
        names = ", ".join(f'"{g.name}"' for g in system.groups)
        raise ModelError(
            f"the reaction forces of a system with elastic bodies ({names}) are not formed: "
            "the joints of an elastic body's nodes all move with its elastic coordinates, so "
            "the forces inside the body are no single joint's reaction (M, k, q, the "
            "linearization and the simulation hold the body in full; the other joints' "
            "reactions, from the sub-trees they carry: System.evaluate, Results.g and "
            "Results.joint_wrenches, jd.joint_reactions, jourdain reactions)")
    if total > system.f:
        # a joint that moves with coordinates it does not drive (gears, a screw turned by
        # another joint's angle) couples two joints: that coupling force is no joint's reaction
        odd = [f'"{jr.joint.name}" (moves in {r} directions, drives '
               f"{len(jr.joint.coordinates)} coordinate(s))" for jr, r in ranks
               if jr.joint.kind == "general" and r != len(jr.joint.coordinates)]
        raise ModelError(
            f"the joints move in {total} independent directions but the system has f = "
            f"{system.f} coordinates: some joints are coupled (a joint moved by another joint's "
            "coordinate), and the coupling force is no single joint's reaction; "
            + (f"check joint(s) {', '.join(odd)}" if odd else "check the joints' coordinates")
        )
    return how
def _check_assembled(system: System, joints: Sequence[JointReactions], fn: Any,
                     samples: int = 3, seed: int = 7) -> float:
    rng = np.random.default_rng(seed)
    pv = np.array(list(system.parameter_values.values()), dtype=float)
    worst = 0.0
    checked = 0
    for _ in range(8 * samples):  # states where the model has real values (sqrt(y) needs y ≥ 0)
        if checked == samples:
            break
        y = rng.uniform(-math.pi, math.pi, system.f)
        out = fn(y, np.zeros(system.f), float(rng.uniform(0, 2)), pv * rng.uniform(0.9, 1.1, pv.size),
                 np.zeros(len(system.inputs)))
        J, Q = out["J_bar"], out["Q_bar"]
        if not (np.isfinite(J).all() and np.isfinite(Q).all()):
            continue
        checked += 1
        n6 = J.shape[0]
        JQ = J.T @ Q
        # relative to ‖J̄_i‖·‖Q̄_k‖ (Cauchy–Schwarz), not to |J̄|ᵀ|Q̄|: a joint frame turned by
        # a float rotation leaves rounding noise (1e-17) in entries of J̄ that are zero, and
        # a torque column meeting only that noise read as relative residual 1
        scale = np.outer(np.linalg.norm(J, axis=0), np.linalg.norm(Q, axis=0)) + 1e-300
        rel = (np.abs(JQ) / scale).max(axis=0)
        worst = max(worst, float(rel.max())) if rel.size else worst
        bad = np.nonzero(rel > 1e-9)[0]
        if bad.size:
            c = int(bad[0])
            jr = next(j for j in joints if c in j.columns)
            raise ModelError(
                f'joint "{jr.joint.name}" (body "{jr.child}"): its constrained direction '
                f'"{jr.names[jr.columns.index(c)]}" does work in an admissible motion (relative '
                f"residual {rel[c]:.2e}); the orthogonality relation J̄ᵀ·Q̄ = 0 fails"
            )
        # redundant directions (more columns) leave components of g undetermined, which the
        # solve reports; missing ones (rank < 6p) would make every g wrong
        sv = np.linalg.svd(np.concatenate([J, Q], axis=1), compute_uv=False)
        rank = int((sv > 1e-9 * sv[0]).sum())
        if rank < n6:
            raise ModelError(
                f"[J̄, Q̄] has rank {rank} < 6p = {n6}: the constrained directions of the "
                "joints and the motions do not span all directions; a reaction is missing"
            )
    if checked == 0:
        raise ModelError("J̄ and Q̄ have no finite values at any of the random states tried: the "
                         "orthogonality J̄ᵀ·Q̄ = 0 cannot be checked, so no reaction forces are "
                         "given")
    return worst
