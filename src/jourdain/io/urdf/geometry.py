"""``<visual>`` and ``<collision>`` elements as :class:`UrdfGeometry`, with mesh files found on
this machine (``package://``, relative and absolute names).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from .model import UrdfError, UrdfGeometry
from .source import _matrix, _pose, _Source


def _geometry(el: Any, link: str, body: str, link_pose: np.ndarray, src: _Source,
              collision: bool) -> UrdfGeometry:
    path, line = src.path, src.line("link", link)
    T = link_pose @ _matrix(el.origin, f'link "{link}" geometry <origin>', path, line)
    geo = el.geometry
    rgba: tuple[float, float, float, float] | None = None
    mat = getattr(el, "material", None)
    if mat is not None and getattr(mat, "color", None) is not None:
        c = np.broadcast_to(np.asarray(mat.color.rgba, float), (4,))
        rgba = (float(c[0]), float(c[1]), float(c[2]), float(c[3]))
    pose = _pose(T)

    def make(kind: str, size: tuple[float, ...] = (), filename: str | None = None,
             found: str | None = None,
             scale: tuple[float, float, float] = (1.0, 1.0, 1.0)) -> UrdfGeometry:
        return UrdfGeometry(link=link, body=body, kind=kind, pose=pose, filename=filename,
                            path=found, scale=scale, size=size, rgba=rgba, collision=collision)

    what = f'link "{link}" {"collision" if collision else "visual"}'
    if geo is None:
        raise UrdfError(f"{what}: no <geometry>", path, line)
    if geo.mesh is not None:
        s = geo.mesh.scale
        v = np.broadcast_to(np.asarray(1.0 if s is None else s, float), (3,))
        return make("mesh", filename=str(geo.mesh.filename),
                    found=_find_mesh(str(geo.mesh.filename), path),
                    scale=(float(v[0]), float(v[1]), float(v[2])))
    if geo.box is not None:
        return make("box", size=tuple(float(x) for x in geo.box.size))
    if geo.cylinder is not None:
        return make("cylinder", size=(float(geo.cylinder.radius), float(geo.cylinder.length)))
    if geo.sphere is not None:
        return make("sphere", size=(float(geo.sphere.radius),))
    raise UrdfError(f"{what}: <geometry> is none of mesh, box, cylinder, sphere", path, line)


def _find_mesh(filename: str, urdf_path: str) -> str | None:
    """The mesh file on this machine, or None (see :class:`UrdfGeometry`)."""
    here = Path(urdf_path).resolve().parent
    if filename.startswith("file://"):
        filename = filename[len("file://"):]
    if filename.startswith("package://"):
        pkg, _, rest = filename[len("package://"):].partition("/")
        for d in (here, *here.parents):
            for cand in ((d / rest) if d.name == pkg else None, d / pkg / rest):
                if cand is not None and cand.is_file():
                    return str(cand)
        return None
    p = Path(filename)
    cand = p if p.is_absolute() else here / p
    return str(cand) if cand.is_file() else None
