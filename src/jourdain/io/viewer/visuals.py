"""What is drawn for a body: its visuals (:class:`Visual`, :class:`MeshVisual`; meshes read
by :mod:`.meshes`) or its equivalent box or ellipsoid (:func:`equivalent_shape`), and the
limits of a page.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ...errors import ModelError

if TYPE_CHECKING:
    from ...model.system import System



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
        super().__init__("mesh", file, (), _floats(scale), _floats(position),
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
                  tuple(getattr(g, "scale", (1.0, 1.0, 1.0))),
                  tuple(T[:3, 3]), tuple(map(tuple, T[:3, :3])),
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




def _numeric(val: Any) -> bool:
    try:
        np.asarray(val, float)
    except (TypeError, ValueError):
        return False
    return True


def contact_visuals(system: Any, values: Mapping[str, float]) -> dict[str, list[Visual]]:
    """A cylinder for each rolling disc of ``system`` (its wheel drawn as what touches the
    ground: radius ``radius + tube_radius``, width a tenth of it, about the axle at the
    disc's centre), by body name."""
    import symengine as se

    out: dict[str, list[Visual]] = {}
    subs = {se.Symbol(k): v for k, v in values.items()}
    for c in getattr(system, "contacts", ()):
        if not hasattr(c, "radius"):
            continue
        R = float(se.sympify(c.radius + c.tube_radius).subs(subs))
        a = np.array([float(se.sympify(x).subs(subs)) for x in c.axis])
        a /= np.linalg.norm(a)
        e = np.eye(3)[0] if abs(a[0]) < 0.9 else np.eye(3)[1]
        u = e - (e @ a) * a
        u /= np.linalg.norm(u)
        rot = np.column_stack([u, np.cross(a, u), a])
        centre = tuple(float(se.sympify(x).subs(subs)) for x in c.center)
        out.setdefault(c.body, []).append(Visual(
            "cylinder", size=(R, 0.1 * R), position=centre,  # type: ignore[arg-type]
            rotation=tuple(tuple(float(v) for v in row) for row in rot)))
    return out
