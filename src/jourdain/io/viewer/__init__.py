"""The 3-D view of a simulated motion in the browser: one self-contained HTML page.

:func:`view` (``jd.view(results)``) gives a :class:`View`: in Jupyter it shows itself (an
``<iframe srcdoc>``), :meth:`View.save` writes the page, which opens offline from ``file://``.
The report of ``jourdain run`` embeds the same page (:func:`report_section`).

What is drawn
-------------
* every body with inertia as its **equivalent box** (or ellipsoid, ``shape="ellipsoid"``): the
  solid of the same mass and principal moments of inertia, centred at the centre of mass and
  aligned with the principal axes. A box with sides a, b, c has I₁ = m(b² + c²)/12, ..., so
  a² = 6(I₂ + I₃ − I₁)/m (an ellipsoid with semi-axes a, b, c: I₁ = m(b² + c²)/5); the triangle
  inequality of the principal moments makes these squares non-negative. Sides that come out
  (nearly) zero (a slender rod) are drawn with a small thickness. Point masses are spheres
  whose volume grows with the mass; massless frames only have their triad.
* a triad at each body frame (x red, y green, z blue) and a fainter one at each joint frame,
  fixed in the parent body's frame (or the inertial one);
* spring-dampers as lines between their two points;
* the visuals of a body where given (:class:`Visual`, the ``visuals`` hook: per body a list
  of meshes — file, scale — and boxes, cylinders, spheres, each with its origin in the body
  frame; a URDF model's ``<visual>`` elements, :attr:`jourdain.io.urdf.UrdfModel.visuals`, are
  taken as they are). STL (binary or ASCII), OBJ and COLLADA (``.dae``) files are read here
  (:mod:`.meshes`) and embedded, so the page needs no file beside it. A body with visuals is
  drawn by them instead of its equivalent shape; a mesh that cannot be read (missing file,
  another format such as glTF, an unresolved ``package://`` address) is left out with a note,
  and the body keeps its equivalent shape if none of its visuals could be drawn. Visuals of
  ``"world"`` stand still.

The motion
----------
Per frame and body, the inertial position ``r_O`` of the body frame's origin and its rotation
``S`` (body → inertial) as a quaternion, at evenly spaced times on
:meth:`~jourdain.simulation.results.Results.interpolate`'s motion: each joint's relative rotation and
position compiled (:func:`pose_function`, evaluated for all frames in one call) and composed
along the tree (:func:`body_poses`); stored as float32 (base64).

three.js (MIT license) is bundled into ``three_bundle.js`` by ``tools/build_viewer.sh`` from
the npm versions pinned in ``tools/viewer/package-lock.json`` and inlined into every page.
"""

from __future__ import annotations

import base64
import html
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ...errors import EvaluationError, JourdainError, ModelError
from ...model.expressions import values_at
from .meshes import Mesh, read_mesh

if TYPE_CHECKING:
    from ...model.system import System
    from ...simulation.results import Results

#: format tag of the scene JSON embedded in the page
SCENE_FORMAT = "jourdain-view/1"
#: frames per second of simulated time (before the caps below)
FRAMES_PER_SECOND = 50
#: at most this many frames, and at most this many body poses (frames × bodies) in a page
MAX_FRAMES = 2000
MAX_POSES = 60_000
#: meshes: at most this many triangles in one page (over all meshes), files at most this large
MAX_TRIANGLES = 200_000
#: the smallest side of an equivalent shape, relative to its largest side and to the scene
MIN_THICKNESS = (0.04, 0.01)
SHAPES = ("box", "ellipsoid")
_COLORS = ("#4e79a7", "#f28e2b", "#59a14f", "#e15759", "#76b7b2", "#edc948", "#b07aa1",
           "#ff9da7", "#9c755f", "#bab0ac")


#: the kinds of :class:`Visual` and the numbers of their ``size``
VISUAL_KINDS = {"mesh": 0, "box": 3, "cylinder": 2, "sphere": 1}


@dataclass(frozen=True)
class Visual:
    """A shape drawn for a body instead of its equivalent box: the data hook for URDF
    ``<visual>`` elements and the like (the URDF import's :class:`~jourdain.io.urdf.UrdfGeometry`
    carries the same data and is accepted as it is).

    Parameters
    ----------
    kind : "mesh", "box", "cylinder" or "sphere"
    file : for a mesh, the path of an STL or OBJ file (relative: to the working directory)
    size : box: edge lengths (x, y, z); cylinder: (radius, length), along its z axis; sphere:
        (radius,); empty for a mesh
    scale : 3 factors applied to a mesh's vertex coordinates
    position : the visual's origin in the body frame
    rotation : 3×3 rotation matrix, the visual's axes in the body frame (``x_body = R·x + p``);
        :func:`rpy_matrix` turns a URDF ``rpy`` into one
    color : RGB (or RGBA, the A ignored) in [0, 1], or None for the body's colour
    """

    kind: str = "mesh"
    file: str | Path | None = None
    size: tuple[float, ...] = ()
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rotation: tuple[tuple[float, ...], ...] = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    color: tuple[float, ...] | None = None


class MeshVisual(Visual):
    """A mesh :class:`Visual`: ``MeshVisual(file, scale, position, rotation, color)``."""

    def __init__(self, file: str | Path, scale: Sequence[float] = (1.0, 1.0, 1.0),
                 position: Sequence[float] = (0.0, 0.0, 0.0), rotation: Any = None,
                 color: Sequence[float] | None = None) -> None:
        R = np.eye(3) if rotation is None else rotation
        super().__init__("mesh", file, (), _floats(scale), _floats(position),  # type: ignore[arg-type]
                         tuple(_floats(r) for r in R), None if color is None else _floats(color))


def _floats(v: Any) -> tuple:
    """A tuple of floats where ``v`` is a sequence of numbers (else ``v`` as given, for
    :func:`_check_visuals` to report)."""
    try:
        return tuple(float(x) for x in v)
    except (TypeError, ValueError):
        return v


def rpy_matrix(rpy: Sequence[float]) -> np.ndarray:
    """URDF's fixed-axis roll, pitch, yaw: ``R = R_z(yaw)·R_y(pitch)·R_x(roll)``."""
    r, p, y = (float(a) for a in rpy)
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), \
        math.cos(y), math.sin(y)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


@dataclass(frozen=True)
class View:
    """A 3-D view of a motion: ``html`` is the self-contained page; in Jupyter the view shows
    itself (``_repr_html_``: the page in an ``<iframe srcdoc>`` of ``height`` pixels).

    ``notes``: what could not be drawn as asked (a mesh left out, ...)."""

    html: str
    notes: tuple[str, ...] = ()
    height: int = 480
    scene: dict = field(default_factory=dict, repr=False, compare=False)

    def _repr_html_(self) -> str:
        return embed(self.html, self.height)

    def save(self, path: str | Path) -> Path:
        """Write the page to ``path`` (it opens offline, from ``file://``)."""
        path = Path(path)
        path.write_text(self.html, encoding="utf-8")
        return path

    def __repr__(self) -> str:
        return (f"View({self.scene.get('name', '')!r}: {len(self.scene.get('bodies', []))} "
                f"bodies, {self.scene.get('n_frames', 0)} frames, {len(self.html)} characters)")


# ------------------------------------------------------------------------------------------
# poses
# ------------------------------------------------------------------------------------------

@lru_cache(maxsize=32)
def pose_function(system: System) -> Any:
    """Compiled relative motion of every joint (:func:`jourdain.stages.kinematics.joint_motions`):
    ``"A<i>"`` (3×3, the child axes in the parent frame) and ``"d<i>"`` (3×1, the child origin in
    the parent frame) of body ``i``, as functions of (y, ẏ, t, parameters, inputs). Short
    expressions, one joint each: cheap to compile however deep the tree (composing the poses
    symbolically, as ``kinematics().bodies[i].S`` does, costs seconds of compilation for a chain
    of 60 bodies)."""
    from ...numeric import lambdify
    from ...stages.kinematics import joint_motions
    from ...symbolic import SymMatrix

    mats = {}
    for i, jm in enumerate(joint_motions(system)):
        mats[f"A{i}"] = SymMatrix.from_rows([list(row) for row in jm.A])
        mats[f"d{i}"] = SymMatrix.column(list(jm.d))
    return lambdify(system, mats)


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


def _system(results: Results) -> System:
    if getattr(results, "system", None) is None:
        raise ModelError("the 3-D view needs the system of the results (results loaded from a "
                         "file: Results.load(path, system=...))")
    return results.system


# ------------------------------------------------------------------------------------------
# shapes and meshes
# ------------------------------------------------------------------------------------------

def equivalent_shape(mass: float, inertia: np.ndarray, shape: str = "box"
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Side lengths (or diameters, for an ellipsoid) and principal axes (columns, a rotation)
    of the homogeneous box or ellipsoid with ``mass`` and the inertia tensor ``inertia`` about
    its centre of mass. Sides are not yet thickened (a slender rod has two zero sides)."""
    if shape not in SHAPES:
        raise ModelError(f"3-D view: shape must be one of {', '.join(SHAPES)}, got {shape!r}")
    inertia = 0.5 * (np.asarray(inertia, float) + np.asarray(inertia, float).T)
    lam, V = np.linalg.eigh(inertia)
    if np.linalg.det(V) < 0:
        V[:, 2] = -V[:, 2]
    if mass <= 0:
        return np.zeros(3), V
    # a² = 6(I_b + I_c − I_a)/m for a box; semi-axis² = 5/2·(…)/m for an ellipsoid
    d = np.maximum(lam.sum() - 2 * lam, 0.0) / mass
    sides = np.sqrt(6 * d) if shape == "box" else 2 * np.sqrt(2.5 * d)
    return sides, V


def _from_geometry(g: Any) -> Visual:
    """A :class:`Visual` from a URDF import's geometry record (``kind``, ``pose`` 4×4 in the
    body frame, ``path``/``filename``, ``scale``, ``size``, ``rgba``)."""
    T = np.asarray(g.pose, float)
    if T.shape != (4, 4):
        raise ModelError(f"3-D view: the pose of a visual of {g.body!r} is not a 4×4 matrix")
    file = getattr(g, "path", None) or getattr(g, "filename", None)
    rgba = getattr(g, "rgba", None)
    return Visual(str(g.kind), file, tuple(getattr(g, "size", ()) or ()),
                  tuple(getattr(g, "scale", (1.0, 1.0, 1.0))),  # type: ignore[arg-type]
                  tuple(T[:3, 3]), tuple(map(tuple, T[:3, :3])),  # type: ignore[arg-type]
                  None if rgba is None else tuple(float(x) for x in rgba))


def visuals_by_body(visuals: Any, notes: list[str] | None = None) -> dict[str, list[Visual]]:
    """The ``visuals`` hook as ``{body: [Visual, ...]}``: a mapping of that form, or a sequence
    of records with a ``body`` attribute (a URDF model's ``visuals``; collision geometry,
    ``collision=True``, is left out, and so are meshes the import did not find, ``path`` None,
    with a note in ``notes``)."""
    if visuals is None:
        return {}
    if isinstance(visuals, Mapping):
        return {str(k): list(v) for k, v in visuals.items()}
    out: dict[str, list[Visual]] = {}
    for g in visuals:
        if getattr(g, "collision", False):
            continue
        if not hasattr(g, "body"):
            raise ModelError("3-D view: visuals must map body names to lists of Visual, or be "
                             f"records with a body (got {type(g).__name__})")
        if getattr(g, "kind", None) == "mesh" and hasattr(g, "path") and not g.path:
            if notes is not None:
                notes.append(f"body {g.body}: mesh {getattr(g, 'filename', '')!r} not found on "
                             "this machine; drawn without it")
            continue
        out.setdefault(str(g.body), []).append(g if isinstance(g, Visual) else _from_geometry(g))
    return out


def _check_visuals(visuals: Mapping[str, Sequence[Visual]], system: System) -> None:
    names = set(system.body_names) | {"world"}
    for body, items in visuals.items():
        if body not in names:
            raise ModelError(f"3-D view: visuals for {body!r}, which is not a body of "
                             f"{system.name!r} (bodies: {', '.join(system.body_names)}, world)")
        for k, v in enumerate(items):
            where = f"3-D view: visual {k} of body {body!r}"
            if not isinstance(v, Visual):
                raise ModelError(f"{where}: expected a Visual, got {type(v).__name__}")
            if v.kind not in VISUAL_KINDS:
                raise ModelError(f"{where}: kind must be one of {', '.join(VISUAL_KINDS)}, "
                                 f"got {v.kind!r}")
            checks = [("scale", v.scale, (3,)), ("position", v.position, (3,)),
                      ("rotation", v.rotation, (3, 3)), ("size", v.size, (VISUAL_KINDS[v.kind],))]
            if v.color is not None:
                checks.append(("color", tuple(v.color)[:3], (3,)))
            for what, val, shape in checks:
                a = np.asarray(val, float) if _numeric(val) else None
                if a is None or a.shape != shape or not np.all(np.isfinite(a)):
                    raise ModelError(f"{where}: {what} must be {shape} finite numbers")
            if v.kind != "mesh" and min(v.size) <= 0:
                raise ModelError(f"{where}: the {v.kind}'s size must be positive")
            if v.kind == "mesh" and not v.file:
                raise ModelError(f"{where}: a mesh needs a file")
            R = np.asarray(v.rotation, float)
            if np.abs(R.T @ R - np.eye(3)).max() > 1e-6 or np.linalg.det(R) < 0:
                raise ModelError(f"{where}: rotation is not a rotation matrix")


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


def _numeric(val: Any) -> bool:
    try:
        np.asarray(val, float)
    except (TypeError, ValueError):
        return False
    return True


# ------------------------------------------------------------------------------------------
# the scene
# ------------------------------------------------------------------------------------------

def _b64(a: np.ndarray, dtype: str) -> str:
    return base64.b64encode(np.ascontiguousarray(a, dtype=dtype).tobytes()).decode("ascii")


def _vec(exprs: Sequence[Any], values: Mapping[str, float], where: str) -> np.ndarray:
    v = np.array(values_at(exprs, values), float)
    if not np.all(np.isfinite(v)):
        raise EvaluationError(f"3-D view: {where} has no finite value at the parameters")
    return v


def _up(system: System, values: Mapping[str, float]) -> np.ndarray:
    from ...model.forces import Gravity

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
    for i, (b, (m, com, sides, V)) in enumerate(zip(system.bodies, raw, strict=True)):
        if m <= 0:
            kind, size = "none", np.zeros(3)
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
    from ...model.forces import SpringDamper

    for f in system.forces:
        if isinstance(f, SpringDamper):
            springs.append({"name": f.name, "body_a": f.body_a, "body_b": f.body_b,
                            "point_a": _vec(f.point_a, values, f'spring "{f.name}" point_a'
                                            ).tolist(),
                            "point_b": _vec(f.point_b, values, f'spring "{f.name}" point_b'
                                            ).tolist()})
    poses = np.concatenate([r, quaternions(S)], axis=-1)  # (n, p, 7)
    return {"format": SCENE_FORMAT, "name": system.name, "n_frames": int(len(times)),
            "times": _b64(times, "<f8"), "poses": _b64(poses.reshape(-1), "<f4"),
            "bodies": bodies, "world_visuals": world_visuals, "springs": springs,
            "up": up.tolist(),
            "center": center.tolist(), "extent": float(L), "view_dir": view_dir.tolist(),
            "distance": float(distance), "ground": ground.tolist(), "notes": notes,
            "shape": shape, "status": results.status}


def decode_poses(sc: Mapping[str, Any]) -> tuple[np.ndarray, np.ndarray]:
    """Times (n,) and poses (n, p, 7) of a scene dict (as embedded in a page)."""
    times = np.frombuffer(base64.b64decode(sc["times"]), dtype="<f8")
    poses = np.frombuffer(base64.b64decode(sc["poses"]), dtype="<f4")
    return times, poses.reshape(len(times), len(sc["bodies"]), 7)


# ------------------------------------------------------------------------------------------
# the page
# ------------------------------------------------------------------------------------------

_PAGE_CSS = """
html,body{height:100%;margin:0}
body{font-family:system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;font-size:13px;
color:#222;background:#f7f7f7}
#jourdain-view{display:flex;flex-direction:column;height:100%}
.jv-canvas{flex:1;min-height:120px;position:relative;overflow:hidden}
.jv-canvas canvas{display:block;width:100%;height:100%}
.jv-bar{display:flex;gap:.6em;align-items:center;padding:.3em .6em;background:#eee;
border-top:1px solid #ccc}
.jv-slider{flex:1}.jv-time{font-variant-numeric:tabular-nums;min-width:7.5em}
.jv-help{color:#666;padding:.2em .6em;background:#eee;font-size:11px}.jv-note{color:#8a5a00}
"""


def _asset(name: str) -> str:
    return resources.files(__name__).joinpath(name).read_text(encoding="utf-8")


@lru_cache(maxsize=1)
def _scripts() -> tuple[str, str]:
    return _asset("three_bundle.js"), _asset("viewer.js")


def page(sc: Mapping[str, Any]) -> str:
    """The self-contained HTML page of a scene (three.js and the viewer inlined)."""
    bundle, viewer = _scripts()
    data = json.dumps(sc, separators=(",", ":")).replace("</", "<\\/")
    name = html.escape(str(sc.get("name", "")))
    shape = {"box": "equivalent boxes", "ellipsoid": "equivalent ellipsoids"}[
        sc.get("shape", "box")]
    notes = "".join(f"<div class='jv-help jv-note'>{html.escape(n)}</div>"
                    for n in sc.get("notes", []))
    help_ = (f"<div class='jv-help'>{name}: bodies as {shape} (same mass and principal "
             "inertia, at the centre of mass) or meshes; triads: body frames (x red, y green, "
             "z blue), fainter ones the joint frames; purple lines: spring-dampers. Drag to "
             "orbit, wheel to zoom, right-drag to pan.</div>")
    speeds = "".join(f"<option value='{s}'{' selected' if s == '1' else ''}>{s}×</option>"
                     for s in ("0.1", "0.25", "0.5", "1", "2", "4"))
    return ("<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
            "<meta name='viewport' content='width=device-width, initial-scale=1'>"
            f"<title>{name} — jourdain 3-D view</title><style>{_PAGE_CSS}</style></head><body>"
            "<div id='jourdain-view'><div class='jv-canvas'></div><div class='jv-bar'>"
            "<button class='jv-play' type='button'>▶ play</button>"
            "<input class='jv-slider' type='range' aria-label='time'>"
            "<span class='jv-time'></span><label>speed <select class='jv-speed'>"
            f"{speeds}</select></label></div>{help_}{notes}</div>"
            f"<script type='application/json' id='jourdain-scene'>{data}</script>"
            f"<script>{bundle}</script><script>{viewer}</script></body></html>")


def embed(page_html: str, height: int = 480) -> str:
    """The page in an ``<iframe srcdoc>`` (sandboxed: its scripts run apart from the page that
    embeds it, which itself runs none)."""
    return (f"<iframe class='jourdain-view' srcdoc=\"{html.escape(page_html, quote=True)}\" "
            f"sandbox='allow-scripts' title='3-D view' style='width:100%;height:{int(height)}px;"
            "border:1px solid #ccc'></iframe>")


def view(results: Results, *, visuals: Any = None,
         shape: str = "box", max_frames: int | None = None, height: int = 480) -> View:
    """The 3-D view of a simulation's motion (``jd.view(results)``).

    Parameters
    ----------
    results : the :class:`~jourdain.simulation.results.Results` of a simulation (with its system)
    visuals : per body name a list of :class:`Visual` (meshes, boxes, cylinders, spheres), or
        a URDF model's ``visuals`` (``view(res, visuals=model.visuals)``); default: the
        system's ``visuals`` attribute where it has one, else none
    shape : "box" or "ellipsoid", the equivalent solid drawn for a body without visuals
    max_frames : at most this many frames (default :data:`MAX_FRAMES`)
    height : pixels of the view in a notebook
    """
    if visuals is None:
        visuals = getattr(_system(results), "visuals", None)
    sc = scene(results, visuals, shape, max_frames)
    return View(page(sc), tuple(sc["notes"]), int(height), sc)


def model_visuals(model: Any) -> Any:
    """The visuals of a model for the ``visuals`` hook: its ``visual_geometry`` (a URDF model's
    ``<visual>`` elements, every kind) where it has them, else its ``visuals``, else None."""
    return getattr(model, "visual_geometry", None) or getattr(model, "visuals", None)


def report_section(results: Results, model: Any = None) -> str:
    """The report's "3-D view" section (HTML) for the results of ``model`` (a
    :class:`~jourdain.io.ModelFile`; its visuals are drawn where it has any, see
    :func:`model_visuals`); a note instead where the view cannot be drawn."""
    try:
        v = view(results, visuals=model_visuals(model))
    except JourdainError as exc:
        why = html.escape(f"3-D view not available: {exc}")
        return f"<h3>3-D view</h3><p class='note'>{why}</p>"
    return ("<h3>3-D view</h3>" + v._repr_html_()
            + "<p class='meta'>Bodies as boxes of the same mass and principal inertia (or their "
              "visuals), body and joint frames as triads, spring-dampers as lines; play, pause "
              "and drag the slider; drag to turn the view. Needs JavaScript and WebGL; the SVG "
              "animation above needs neither.</p>")

