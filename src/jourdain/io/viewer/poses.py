"""The motion in the page: each body's position and rotation (as a quaternion) at evenly
spaced times, from compiled joint poses composed along the tree.
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import TYPE_CHECKING, Any

import numpy as np

from ...errors import EvaluationError, ModelError
from ...numeric import lambdify
from ...stages.kinematics import joint_motions
from ...symbolic import SymMatrix

if TYPE_CHECKING:
    from ...model.system import System
    from ...simulation.results import Results

from .visuals import FRAMES_PER_SECOND, MAX_FRAMES, MAX_POSES


@lru_cache(maxsize=32)
def pose_function(system: System) -> Any:
    """Compiled relative motion of every joint (:func:`jourdain.stages.kinematics.joint_motions`):
    ``"A<i>"`` (3×3, the child axes in the parent frame) and ``"d<i>"`` (3×1, the child origin in
    the parent frame) of body ``i``, as functions of (y, ẏ, t, parameters, inputs). Short
    expressions, one joint each: cheap to compile however deep the tree (composing the poses
    symbolically, as ``kinematics().bodies[i].S`` does, costs seconds of compilation for a chain
    of 60 bodies)."""
    mats = {}
    for i, jm in enumerate(joint_motions(system)):
        mats[f"A{i}"] = SymMatrix.from_rows([list(row) for row in jm.A])
        mats[f"d{i}"] = SymMatrix.column(list(jm.d))
    return lambdify(system, mats, lean=True)


def quaternions(S: np.ndarray) -> np.ndarray:
    """Unit quaternions (x, y, z, w) of rotation matrices ``S`` (…, 3, 3), by Shepperd's method
    (the largest of w², x², y², z² taken first, so no division by a small number); w ≥ 0."""
    S = np.asarray(S, float)
    m00, m11, m22 = S[..., 0, 0], S[..., 1, 1], S[..., 2, 2]
    tr = m00 + m11 + m22
    cand = np.stack([1 + tr, 1 + 2 * m00 - tr, 1 + 2 * m11 - tr, 1 + 2 * m22 - tr], axis=-1)
    k = np.argmax(cand, axis=-1)
    q = np.empty(S.shape[:-2] + (4,))
    # each case divides by its own (largest) component; the others' divisions are discarded
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.sqrt(np.maximum(cand[..., 0], 0.0)) * 2
        w = [s / 4, (S[..., 2, 1] - S[..., 1, 2]) / s, (S[..., 0, 2] - S[..., 2, 0]) / s,
             (S[..., 1, 0] - S[..., 0, 1]) / s]
        s1 = np.sqrt(np.maximum(cand[..., 1], 0.0)) * 2
        x = [(S[..., 2, 1] - S[..., 1, 2]) / s1, s1 / 4, (S[..., 0, 1] + S[..., 1, 0]) / s1,
             (S[..., 0, 2] + S[..., 2, 0]) / s1]
        s2 = np.sqrt(np.maximum(cand[..., 2], 0.0)) * 2
        y = [(S[..., 0, 2] - S[..., 2, 0]) / s2, (S[..., 0, 1] + S[..., 1, 0]) / s2, s2 / 4,
             (S[..., 1, 2] + S[..., 2, 1]) / s2]
        s3 = np.sqrt(np.maximum(cand[..., 3], 0.0)) * 2
        z = [(S[..., 1, 0] - S[..., 0, 1]) / s3, (S[..., 0, 2] + S[..., 2, 0]) / s3,
             (S[..., 1, 2] + S[..., 2, 1]) / s3, s3 / 4]
    for case, (qw, qx, qy, qz) in enumerate((w, x, y, z)):
        sel = k == case
        q[sel] = np.stack([qx, qy, qz, qw], axis=-1)[sel]
    q *= np.where(q[..., 3:] < 0, -1.0, 1.0)
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def frame_times(results: Results, max_frames: int | None = None) -> np.ndarray:
    """Evenly spaced times over the run: :data:`FRAMES_PER_SECOND` per second of simulated time,
    at most ``max_frames`` (default :data:`MAX_FRAMES`, and :data:`MAX_POSES` / bodies)."""
    t = np.asarray(results.t, float)
    if len(t) < 2 or t[-1] <= t[0]:
        return t[:1].copy()
    nb = max(len(results.system.bodies), 1) if results.system is not None else 1
    cap = min(MAX_FRAMES if max_frames is None else int(max_frames), MAX_POSES // nb)
    n = int(min(max(math.ceil((t[-1] - t[0]) * FRAMES_PER_SECOND) + 1, 2), max(cap, 2)))
    return np.linspace(t[0], t[-1], n)


def body_poses(results: Results, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Positions ``r_O`` (n, p, 3) and rotation matrices ``S`` (n, p, 3, 3) of every body frame
    at ``times`` (within the run) on the interpolated motion: the joints' relative motions
    composed parents first, ``S_i = S_λ·A_i``, ``r_O,i = r_O,λ + S_λ·d_i`` (METHOD.md §1)."""
    system = _system(results)
    fn = pose_function(system)
    p = np.array([results.parameters[k] for k, _ in system.parameters])
    if len(results.t) < 2:
        y, yd = results.y[:1], results.yd[:1]
    else:
        m = results.interpolate(times)
        y, yd = m["y"], m["yd"]
    out = fn.batch(y, yd, times, p, None)  # positions do not depend on inputs
    n, nb = len(times), len(system.bodies)
    r = np.zeros((n, nb, 3))
    S = np.zeros((n, nb, 3, 3))
    index = {b.name: i for i, b in enumerate(system.bodies)}
    for i, b in enumerate(system.bodies):  # parents come first
        A, d = out[f"A{i}"], out[f"d{i}"][:, :, 0]
        if b.parent == "world":
            S[:, i], r[:, i] = A, d
        else:
            k = index[b.parent]
            S[:, i] = S[:, k] @ A
            r[:, i] = r[:, k] + np.einsum("nij,nj->ni", S[:, k], d)
    if not (np.all(np.isfinite(r)) and np.all(np.isfinite(S))):
        raise EvaluationError("3-D view: the body positions are not finite along the motion")
    return r, S


def closing_points(system: System, r: np.ndarray, S: np.ndarray,
                   values: Any) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Per closing joint with points (``system.closing``; a general constraint of expressions
    has none), the inertial positions (n, 3) of its point on body A and on body B, from the
    body poses ``r`` (n, p, 3) and ``S`` (n, p, 3, 3) of :func:`body_poses` (the tree's at the
    closed configuration); ``values``: the parameter values by name. On the manifold the two
    coincide where the joint fixes the points together (revolute, spherical, ...)."""
    from ...model.expressions import values_at

    index = {b.name: i for i, b in enumerate(system.bodies)}
    n = r.shape[0]
    out: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    for c in getattr(system, "closing", ()):
        if c.point_a is None or c.point_b is None:
            continue
        ends = []
        for body, point in ((c.body_a, c.point_a), (c.body_b, c.point_b)):
            p = np.array(values_at(point, values), float)
            if body == "world":
                ends.append(np.broadcast_to(p, (n, 3)).copy())
            else:
                i = index[body]
                ends.append(r[:, i] + np.einsum("nij,j->ni", S[:, i], p))
        out[c.name] = (ends[0], ends[1])
    return out


def _system(results: Results) -> System:
    system = getattr(results, "system", None)
    if system is None:
        raise ModelError("the 3-D view needs the system of the results (results loaded from a "
                         "file: Results.load(path, system=...))")
    return system


