"""What a URDF file becomes besides the :class:`~jourdain.System`: its joints, links and
geometry (:class:`UrdfJoint`, :class:`UrdfLink`, :class:`UrdfGeometry`), the
:class:`UrdfModel` holding them, :class:`UrdfError`, and the names of the floating base.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import ModelError
from ..modelfile import (
    ModelFile,
    ModelFileError,
)
from ..viewer import MeshVisual

#: name of the free joint of a floating base (Pinocchio's name for its root joint)
ROOT_JOINT = "root_joint"
#: coordinates of the floating base: position of the root link frame in the world frame, then
#: the angles of R = Rz(yaw)·Ry(pitch)·Rx(roll) (URDF's rpy convention)
ROOT_COORDINATES = ("root_x", "root_y", "root_z", "root_yaw", "root_pitch", "root_roll")
#: the moving joint types of URDF that jourdain reads
MOVING = ("revolute", "continuous", "prismatic", "floating", "planar")

_AXIS_NAMES = {(1.0, 0.0, 0.0): "x", (0.0, 1.0, 0.0): "y", (0.0, 0.0, 1.0): "z",
               (-1.0, 0.0, 0.0): "-x", (0.0, -1.0, 0.0): "-y", (0.0, 0.0, -1.0): "-z"}


class UrdfError(ModelFileError):
    """A URDF file jourdain cannot read: the message names the file and the link or joint."""

    def __init__(self, message: str, file: str, line: int | None = None) -> None:
        where = f"{file}:{line}" if line else file
        super().__init__(f"{where}: {message}", file, line)


# ------------------------------------------------------------------------------------------
# the data kept besides the System
# ------------------------------------------------------------------------------------------

Pose = tuple[tuple[float, float, float, float], ...]
"""A homogeneous transform as 4 rows of 4 floats: ``[[R, p], [0, 0, 0, 1]]``, mapping
coordinates in the frame it describes to the frame it is expressed in."""


@dataclass(frozen=True)
class UrdfJoint:
    """One URDF joint and what became of it.

    Attributes
    ----------
    name : the URDF joint name
    type : ``revolute``, ``continuous``, ``prismatic``, ``fixed``, ``floating`` or ``planar``
    parent, child : the URDF link names
    body : the jourdain body the child link belongs to (the child's own body for a moving
        joint, the body it is welded to for a fixed one; ``"world"`` when welded to a fixed
        base)
    joint : the jourdain joint's name (None for a fixed joint, merged away)
    coordinates : the jourdain coordinates it drives, in order (empty for fixed)
    axis : the unit axis in the joint frame (URDF ``<axis>``, normalized)
    origin : the joint frame in the parent link frame (URDF ``<origin>``)
    lower, upper, effort, velocity : ``<limit>`` values (None where not given)
    damping, friction : ``<dynamics>`` values (None where not given)
    mimic : ``(joint, multiplier, offset)`` of a ``<mimic>`` element read with
        ``mimic="independent"``, else None
    input : the input ``tau_<joint>`` acting on its coordinate (None if none)
    """

    name: str
    type: str
    parent: str
    child: str
    body: str
    joint: str | None
    coordinates: tuple[str, ...]
    axis: tuple[float, float, float]
    origin: Pose
    lower: float | None = None
    upper: float | None = None
    effort: float | None = None
    velocity: float | None = None
    damping: float | None = None
    friction: float | None = None
    mimic: tuple[str, float, float] | None = None
    input: str | None = None


@dataclass(frozen=True)
class UrdfLink:
    """A URDF link: the jourdain ``body`` it is part of (``"world"`` for a link of a fixed
    base) and its ``pose`` in that body's frame (identity for the link that names the body)."""

    name: str
    body: str
    pose: Pose


@dataclass(frozen=True)
class UrdfGeometry:
    """A ``<visual>`` or ``<collision>`` element of a link, for a viewer.

    Attributes
    ----------
    link : the URDF link it belongs to
    body : the jourdain body it moves with (``"world"``: fixed)
    kind : ``mesh``, ``box``, ``cylinder`` or ``sphere``
    pose : the geometry's frame in the body frame (``<origin>`` composed with the link's pose)
    filename : for a mesh, the file name as written (``package://...``, relative or absolute)
    path : for a mesh, the file found on this machine (absolute; relative names are relative to
        the URDF's folder, ``package://pkg/rest`` is looked for in the URDF's ancestor folders
        named ``pkg``), None if not found
    scale : for a mesh, the scale factors along x, y, z (1, 1, 1 by default)
    size : box: edge lengths (x, y, z); cylinder: (radius, length) along z; sphere: (radius,)
    rgba : colour of the ``<material>`` (visuals), None where not given
    collision : True for a ``<collision>`` element
    """

    link: str
    body: str
    kind: str
    pose: Pose
    filename: str | None = None
    path: str | None = None
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)
    size: tuple[float, ...] = ()
    rgba: tuple[float, float, float, float] | None = None
    collision: bool = False


@dataclass(frozen=True)
class UrdfModel(ModelFile):
    """A model read from a URDF file: a :class:`~jourdain.io.ModelFile` (the System, a nominal
    motion ``zero``: every coordinate 0, the default simulation settings) with the robot's
    data besides it.

    Attributes
    ----------
    robot : the URDF robot name
    floating_base : whether the root link hangs from the world by a free joint
    joints : every URDF joint, in file order (:class:`UrdfJoint`)
    links : every URDF link, in file order (:class:`UrdfLink`)
    visual_geometry, collision_geometry : the ``<visual>`` and ``<collision>`` elements of the
        links (:class:`UrdfGeometry`), in file order
    visuals : the meshes of :attr:`visual_geometry` as the 3-D view takes them
        (:func:`jourdain.io.viewer.view`): ``{body: [MeshVisual, ...]}``
    """

    robot: str = ""
    floating_base: bool = False
    joints: tuple[UrdfJoint, ...] = ()
    links: tuple[UrdfLink, ...] = ()
    visual_geometry: tuple[UrdfGeometry, ...] = ()
    collision_geometry: tuple[UrdfGeometry, ...] = ()

    @property
    def visuals(self) -> dict[str, list[Any]]:
        """The visual meshes of the moving bodies, ``{body: [MeshVisual, ...]}`` (file, scale,
        pose in the body frame, colour), for :func:`jourdain.io.viewer.view` and the report.
        Boxes, cylinders, spheres and the links welded to a fixed base are not in it."""
        out: dict[str, list[Any]] = {}
        for g in self.visual_geometry:
            if g.kind != "mesh" or g.body == "world":
                continue
            T = np.asarray(g.pose)
            out.setdefault(g.body, []).append(MeshVisual(
                file=g.path or g.filename or "", scale=g.scale,
                position=tuple(float(x) for x in T[:3, 3]),
                rotation=tuple(tuple(float(x) for x in r) for r in T[:3, :3]),
                color=None if g.rgba is None else g.rgba[:3]))
        return out

    def error(self, message: str) -> ModelFileError:
        """A :class:`UrdfError` for a problem a later stage found (the message names the body
        or joint; URDF elements have no key path to point at)."""
        return UrdfError(message, self.path)

    def joint(self, name: str) -> UrdfJoint:
        """The URDF joint called ``name`` (ModelError if there is none)."""
        for j in self.joints:
            if j.name == name:
                return j
        raise ModelError(f'{self.path}: no joint "{name}"; joints are: '
                         + ", ".join(j.name for j in self.joints))


# ------------------------------------------------------------------------------------------
# reading
