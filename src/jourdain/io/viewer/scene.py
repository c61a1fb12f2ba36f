"""The scene of a page as JSON: bodies, shapes, visuals, frames, spring-dampers, camera and the
poses (float32, base64), and its decoding.
"""

from __future__ import annotations

import base64
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ...errors import EvaluationError, ModelError
from ...model.expressions import values_at
from ...model.forces import Gravity, SpringDamper

if TYPE_CHECKING:
    from ...model.system import System
    from ...simulation.results import Results

from .meshes import Mesh, read_mesh
from .poses import _system, body_poses, frame_times, quaternions
from .visuals import (
    _COLORS,
    MAX_TRIANGLES,
    MIN_THICKNESS,
    SCENE_FORMAT,
    SHAPES,
    Visual,
    _check_visuals,
    equivalent_shape,
    visuals_by_body,
)


def _b64(a: np.ndarray, dtype: str) -> str:
    return base64.b64encode(np.ascontiguousarray(a, dtype=dtype).tobytes()).decode("ascii")


def _mesh_spec(m: Mesh) -> dict[str, Any]:
    """A mesh in the page: vertices (float32), triangles as vertex indices (uint32), groups
    of triangles with their colour."""
    return {"vertices": _b64(m.vertices.reshape(-1), "<f4"),
            "indices": _b64(m.faces.reshape(-1), "<u4"),
            "groups": [[int(a), int(n), None if c is None else [float(x) for x in c]]
                       for a, n, c in m.groups]}


def _visual_specs(owner: str, items: Sequence[Visual], notes: list[str],
                  budget: list[int]) -> list[dict[str, Any]]:
    """The scene entries of one body's visuals; meshes read and embedded (``budget[0]``: the
    triangles the page may still take)."""
    out = []
    for k, v in enumerate(items):
        spec: dict[str, Any] = {
            "kind": v.kind, "size": [float(x) for x in v.size],
            "scale": [float(x) for x in v.scale], "position": [float(x) for x in v.position],
            "quaternion": quaternions(np.asarray(v.rotation, float)).tolist(),
            "color": None if v.color is None else [float(x) for x in tuple(v.color)[:3]]}
        if v.kind == "mesh":
            try:
                m = read_mesh(v.file)  # type: ignore[arg-type]
            except ModelError as exc:
                notes.append(f"{owner}: {exc}; drawn without it")
                continue
            if len(m.faces) > budget[0]:
                notes.append(f"{owner}: mesh {k} ({len(m.faces)} triangles) left out, more "
                             f"than {MAX_TRIANGLES} triangles in the page")
                continue
            budget[0] -= len(m.faces)
            spec.update(_mesh_spec(m))
            spec["file"] = str(v.file)
        out.append(spec)
    return out


def _vec(exprs: Sequence[Any], values: Mapping[str, float], where: str) -> np.ndarray:
    v = np.array(values_at(exprs, values), float)
    if not np.all(np.isfinite(v)):
        raise EvaluationError(f"3-D view: {where} has no finite value at the parameters")
    return v


def _up(system: System, values: Mapping[str, float]) -> np.ndarray:
    for f in system.forces:
        if isinstance(f, Gravity):
            g = np.array(values_at(f.vector, values), float)
            n = np.linalg.norm(g)
            if np.all(np.isfinite(g)) and n > 0:
                return -g / n
    return np.array([0.0, 0.0, 1.0])


def _camera(motion: np.ndarray, points: np.ndarray, up: np.ndarray
            ) -> tuple[np.ndarray, float, np.ndarray, np.ndarray]:
    """Centre, extent (diagonal), viewing direction (centre → camera) and ground point of a
    scene that holds ``points``; the view looks across the plane of ``motion`` (the frame
    origins and centres of mass) where that is planar."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    center = (lo + hi) / 2
    extent = float(np.linalg.norm(hi - lo))
    # a horizontal basis (h1, h2) perpendicular to "up"
    a = np.eye(3)[int(np.argmin(np.abs(up)))]
    h1 = np.cross(up, a)
    h1 /= np.linalg.norm(h1)
    h2 = np.cross(up, h1)
    spread = motion.std(axis=0) if len(motion) > 1 else np.zeros(3)
    if spread.max() > 0 and spread.min() < 1e-6 * spread.max():
        n = np.eye(3)[int(np.argmin(spread))]  # planar motion: look at the plane, a bit oblique
        if abs(n @ up) < 0.9:
            side = np.cross(up, n)
            d = n + 0.35 * side / np.linalg.norm(side) + 0.15 * up
        else:
            d = up + 0.6 * h1 + 0.3 * h2
    else:
        d = h1 + 0.6 * h2 + 0.5 * up
    d = d / np.linalg.norm(d)
    ground = center - up * float(np.max((center - points) @ up, initial=0.0))
    return center, extent, d, ground


def _line(group: Any) -> list[str]:
    """The bodies of an elastic body's line, in order along it: its mass points
    ``<body>_g<k>`` (consistent mass) or else its nodes ``<body>_n<k>``."""
    points = getattr(group, "points", None)
    if points is not None:
        return [f"{group.name}_g{k}" for k in range(len(points.mass))]
    return [f"{group.name}_n{k}" for k in range(len(getattr(group, "node_mass", ())))]


def scene(results: Results, visuals: Any = None,
          shape: str = "box", max_frames: int | None = None) -> dict[str, Any]:
    """The scene of the page as a JSON-ready dict (``"format": "jourdain-view/1"``): bodies
    with their shapes, meshes and joint frames, spring-dampers, the camera, the frame times
    (float64) and the poses (float32, frames × bodies × (x, y, z, qx, qy, qz, qw)), both base64.
    """
    system = _system(results)
    if shape not in SHAPES:
        raise ModelError(f"3-D view: shape must be one of {', '.join(SHAPES)}, got {shape!r}")
    notes: list[str] = []
    visuals = visuals_by_body(visuals, notes)
    _check_visuals(visuals, system)
    values = dict(system.parameter_values)
    values.update(results.parameters)

    times = frame_times(results, max_frames)
    r, S = body_poses(results, times)

    # mass data: the equivalent shapes before thickening
    bodies = []
    raw = []
    for b in system.bodies:
        m = _vec([b.mass], values, f'the mass of body "{b.name}"')[0]
        com = _vec(b.com, values, f'the centre of mass of body "{b.name}"')
        inertia = _vec([x for row in b.inertia for x in row], values,
                       f'the inertia of body "{b.name}"').reshape(3, 3)
        sides, V = equivalent_shape(m, inertia, shape)
        raw.append((m, com, sides, V))
    # the extent of the scene: the motion of the frames and centres of mass, and the shapes
    com_world = r + np.einsum("npij,pj->npi", S, np.array([c for _, c, _, _ in raw]))
    # each shape as its bounding sphere, by six points around its centre of mass
    radius = np.array([0.5 * float(np.linalg.norm(s)) for _, _, s, _ in raw])
    around = com_world[:, :, None, :] + radius[None, :, None, None] * np.concatenate(
        [np.eye(3), -np.eye(3)])[None, None]
    pts = np.concatenate([np.zeros((1, 3)), r.reshape(-1, 3), com_world.reshape(-1, 3),
                          around.reshape(-1, 3)])
    up = _up(system, values)
    center, extent, view_dir, ground = _camera(pts[1:1 + 2 * r.shape[0] * r.shape[1]], pts, up)
    L = max(extent, 1e-9)
    distance = 1.45 * L  # the whole scene in the 40° field of view
    mmax = max((m for m, _, _, _ in raw), default=0.0)

    budget = [MAX_TRIANGLES]
    # an elastic body's mass nodes or points: small beads on its line (viewer.js joins them)
    beads = {n for g in getattr(system, "groups", ()) for n in _line(g)}
    for i, (b, (m, com, sides, V)) in enumerate(zip(system.bodies, raw, strict=True)):
        if m <= 0:
            kind, size = "none", np.zeros(3)
        elif b.name in beads:
            kind, size = "sphere", np.full(3, 0.012 * L)
        elif sides.max() <= 1e-9 * L:  # a point mass: volume by mass
            kind = "sphere"
            size = np.full(3, max(0.06 * L * (m / mmax) ** (1 / 3), 0.02 * L))
        else:
            kind = shape
            size = np.maximum(sides, max(MIN_THICKNESS[0] * sides.max(), MIN_THICKNESS[1] * L))
        jpos = _vec(b.joint.position, values, f'the position of joint "{b.joint.name}"')
        jrot = _vec([x for row in b.joint.orientation for x in row], values,
                    f'the orientation of joint "{b.joint.name}"').reshape(3, 3)
        drawn = _visual_specs(f"body {b.name}", visuals.get(b.name, []), notes, budget)
        bodies.append({
            "name": b.name, "parent": b.parent, "mass": float(m),
            "color": _COLORS[i % len(_COLORS)],
            "shape": {"kind": kind, "size": size.tolist(), "position": com.tolist(),
                      "quaternion": quaternions(V).tolist()},
            "joint": {"name": b.joint.name, "position": jpos.tolist(),
                      "quaternion": quaternions(jrot).tolist()},
            "visuals": drawn})
    world_visuals = _visual_specs("world", visuals.get("world", []), notes, budget)

    springs = []
    for f in system.forces:
        if isinstance(f, SpringDamper):
            springs.append({"name": f.name, "body_a": f.body_a, "body_b": f.body_b,
                            "point_a": _vec(f.point_a, values, f'spring "{f.name}" point_a'
                                            ).tolist(),
                            "point_b": _vec(f.point_b, values, f'spring "{f.name}" point_b'
                                            ).tolist()})
    closing = []  # a closed system's closing joints (their points in the bodies' frames)
    for c in getattr(system, "closing", ()):
        if c.point_a is None or c.point_b is None:
            continue  # a general constraint of expressions: no points to draw
        closing.append({"name": c.name, "type": c.type, "body_a": c.body_a,
                        "body_b": c.body_b,
                        "point_a": _vec(c.point_a, values, f'closing joint "{c.name}" point_a'
                                        ).tolist(),
                        "point_b": _vec(c.point_b, values, f'closing joint "{c.name}" point_b'
                                        ).tolist()})
    names = {b.name for b in system.bodies}
    elastic = [{"name": g.name, "nodes": [n for n in _line(g) if n in names]}
               for g in getattr(system, "groups", ())]
    poses = np.concatenate([r, quaternions(S)], axis=-1)  # (n, p, 7)
    return {"format": SCENE_FORMAT, "name": system.name, "n_frames": int(len(times)),
            "times": _b64(times, "<f8"), "poses": _b64(poses.reshape(-1), "<f4"),
            "bodies": bodies, "world_visuals": world_visuals, "springs": springs,
            "closing": closing, "elastic": elastic,
            "up": up.tolist(),
            "center": center.tolist(), "extent": float(L), "view_dir": view_dir.tolist(),
            "distance": float(distance), "ground": ground.tolist(), "notes": notes,
            "shape": shape, "status": results.status}


def closing_ends(sc: Mapping[str, Any]) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Per closing joint of a scene dict, the inertial positions (n, 3) of its point on body
    A and on body B at the scene's frames (from the poses as the page draws them: float32)."""
    _, poses = decode_poses(sc)
    poses = poses.astype(float)
    index = {b["name"]: i for i, b in enumerate(sc["bodies"])}
    out = {}
    for c in sc.get("closing", []):
        ends = []
        for body, point in ((c["body_a"], c["point_a"]), (c["body_b"], c["point_b"])):
            p = np.asarray(point, float)
            if body == "world":
                ends.append(np.broadcast_to(p, (len(poses), 3)).copy())
                continue
            pose = poses[:, index[body]]
            x, y, z, w = (pose[:, k] for k in range(3, 7))
            R = np.stack([
                np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
                np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
                np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
            ], axis=1)
            ends.append(pose[:, :3] + R @ p)
        out[c["name"]] = (ends[0], ends[1])
    return out


def decode_poses(sc: Mapping[str, Any]) -> tuple[np.ndarray, np.ndarray]:
    """Times (n,) and poses (n, p, 7) of a scene dict (as embedded in a page)."""
    times = np.frombuffer(base64.b64decode(sc["times"]), dtype="<f8")
    poses = np.frombuffer(base64.b64decode(sc["poses"]), dtype="<f4")
    return times, poses.reshape(len(times), len(sc["bodies"]), 7)


