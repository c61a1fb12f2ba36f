"""URDF import: a robot description (``.urdf``) as a jourdain model.

:func:`load_urdf` reads a URDF file with the maintained parser `yourdfpy
<https://github.com/clemense/yourdfpy>`_ (the optional extra ``jourdain[urdf]``) and builds a
:class:`~jourdain.System` the way Pinocchio's ``buildModelFromUrdf`` builds its model, so that
the two give the same numbers (M against CRBA, k − q against the nonlinear effects, the joint
wrenches against RNEA's ``data.f``; tests/reference/test_urdf_pinocchio.py):

* every moving joint (``revolute``, ``continuous``, ``prismatic``, ``floating``, ``planar``)
  gives one jourdain body, named after the URDF child link, hanging from its parent body by a
  jourdain joint of the same name placed at the joint's ``<origin>`` (``xyz``, ``rpy``) and
  moving about/along its ``<axis>``; the body frame is the child link's frame;
* a ``fixed`` joint welds its child link to the parent's body: the child's mass, centre of mass
  and inertia are merged into that body (as Pinocchio does), and the link's pose in the body
  frame is kept (:attr:`UrdfModel.links`) for its meshes; links welded to the root of a fixed
  base do not move and carry no mass into the model;
* the root link is fixed to the world (``floating_base=False``) or hangs from the world by a
  free joint ``root_joint`` (``floating_base=True``, Pinocchio's ``JointModelFreeFlyer`` root):
  translations ``root_x, root_y, root_z`` along the world axes, then the angles ``root_yaw,
  root_pitch, root_roll`` about z, the turned y, the turned x (the rotation
  ``R = Rz(yaw)·Ry(pitch)·Rx(roll)`` of URDF's ``rpy``);
* each body's mass, centre of mass and inertia tensor (about the centre of mass, body frame)
  are parameters ``m_<body>``, ``cx_<body>``, ``cy_<body>``, ``cz_<body>``, ``Ixx_<body>``,
  ``Ixy_<body>``, ... with the URDF's values (merged) as defaults, except the numbers that are
  exactly 0, which stay literal zeros (a massless link, a point mass, zero products of
  inertia); gravity ``g`` (default 9.81, Pinocchio's) acts along −z;
* each one-coordinate joint (revolute, continuous, prismatic) gets an input ``tau_<joint>``:
  a generalized force (torque or force) on its coordinate, zero unless given;
* joint limits, damping and friction are kept as data (:class:`UrdfJoint`); with
  ``joint_damping=True`` the viscous ``damping`` also acts, as ``−damping·ẏ`` on the coordinate.

Names: URDF names that are not identifiers (``arm/link-1``) are made identifiers (``arm_link_1``)
and the map is kept (:attr:`UrdfJoint.coordinates`, :attr:`UrdfLink.body`). Geometry is kept
as references for viewers (:class:`UrdfGeometry`: mesh file names and scales, boxes,
cylinders, spheres, each with its pose in the body frame; :attr:`UrdfModel.visuals` gives the
meshes in the form of the 3-D view), never loaded.

Not supported, each a :class:`UrdfError` naming the link or joint and the file: ``mimic``
joints (unless ``mimic="independent"``, which makes them ordinary joints as Pinocchio does by
default), closed loops (a link that is the child of two joints, ``<loop_joint>`` extensions),
a joint whose parent or child link is not declared, several root links, a moving body with no
mass anywhere below it (M would be singular), malformed XML, DTDs (entity declarations).
"""

from __future__ import annotations

import io
import keyword
import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import symengine as se

from ..errors import ModelError
from ..model import (
    Body,
    Free,
    GeneralizedForce,
    Gravity,
    Planar,
    Prismatic,
    Revolute,
    RotationalSpringDamper,
)
from ..pipeline import System  # jourdain.System: the model with its stages (issue 16)
from .expressions import RESERVED_NAMES
from .modelfile import (
    MAX_FILE_BYTES,
    ModelFile,
    ModelFileError,
    NominalMotion,
    SimulationSettings,
)

__all__ = ["UrdfError", "UrdfGeometry", "UrdfJoint", "UrdfLink", "UrdfModel", "load_urdf",
           "ROOT_JOINT", "ROOT_COORDINATES"]

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
        from .viewer import MeshVisual

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
# ------------------------------------------------------------------------------------------

def _yourdfpy() -> Any:
    try:
        import yourdfpy
    except ImportError:
        raise ModelError(
            "reading URDF files needs the package yourdfpy: install jourdain's extra with "
            "pip install 'jourdain[urdf]' (or pip install yourdfpy)") from None
    return yourdfpy


def _read_xml(path: str) -> tuple[bytes, dict[tuple[str, str], int]]:
    """The file's bytes, checked to be well-formed XML without a DTD (a located error
    otherwise): yourdfpy would recover silently from broken XML."""
    try:
        with open(path, "rb") as fh:
            raw = fh.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise UrdfError(f"cannot read the URDF file: {exc.strerror}", path) from None
    if len(raw) > MAX_FILE_BYTES:
        raise UrdfError(f"the file is larger than {MAX_FILE_BYTES // 1_000_000} MB; URDF "
                        "files of real robots are a few hundred kB", path)
    from lxml import etree  # a dependency of yourdfpy

    parser = etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False,
                             huge_tree=False)
    try:
        root = etree.fromstring(raw, parser=parser)
    except etree.XMLSyntaxError as exc:
        line = exc.lineno if isinstance(exc.lineno, int) and exc.lineno > 0 else None
        msg = str(exc.msg) if getattr(exc, "msg", None) else str(exc)
        raise UrdfError(f"malformed XML: {msg}", path, line) from None
    if root.getroottree().docinfo.internalDTD is not None or b"<!ENTITY" in raw:
        raise UrdfError("DOCTYPE/ENTITY declarations are not read (URDF files need none)", path)
    if root.tag != "robot":
        raise UrdfError(f"the root element is <{root.tag}>, expected <robot>", path,
                        root.sourceline)
    lines: dict[tuple[str, str], int] = {}
    for el in root:
        if not isinstance(el.tag, str):
            continue
        if "loop" in el.tag.lower():
            name = el.get("name", "")
            raise UrdfError(f'<{el.tag}> "{name}": closed kinematic loops are not supported '
                            "(jourdain models trees; cut the loop or model it in a model "
                            "file)", path, el.sourceline)
        if el.tag in ("link", "joint"):
            lines.setdefault((el.tag, el.get("name", "")), el.sourceline)
            mim = el.find("mimic") if el.tag == "joint" else None
            if mim is not None:
                lines.setdefault(("mimic", el.get("name", "")), mim.sourceline)
    return raw, lines


def _float(value: object, what: str, path: str, line: int | None,
           default: float | None = None) -> float | None:
    if value is None:
        return default
    try:
        v = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise UrdfError(f"{what}: expected a number, got {value!r}", path, line) from None
    if not math.isfinite(v):
        raise UrdfError(f"{what}: {value!r} is not a finite number", path, line)
    return v


def _matrix(value: Any, what: str, path: str, line: int | None) -> np.ndarray:
    """A 4×4 pose of yourdfpy (None: identity), checked finite with a rotation block."""
    if value is None:
        return np.eye(4)
    T = np.asarray(value, dtype=float)
    if T.shape != (4, 4) or not np.all(np.isfinite(T)):
        raise UrdfError(f"{what}: the origin is not finite", path, line)
    return T


def _pose(T: np.ndarray) -> Pose:
    return tuple(tuple(float(x) for x in row) for row in T)  # type: ignore[return-value]


class _Names:
    """URDF names made identifiers, unique within one kind, first come first served (file
    order, so the result does not depend on anything but the file)."""

    def __init__(self, prefix: str) -> None:
        self.prefix = prefix
        self.taken: set[str] = set()
        self.names: dict[str, str] = {}

    def __call__(self, name: str) -> str:
        if name in self.names:
            return self.names[name]
        s = re.sub(r"[^A-Za-z0-9_]", "_", name)
        s = re.sub(r"__+", "_", s).strip("_")
        if not s or not s[0].isalpha():
            s = f"{self.prefix}_{s}".rstrip("_")
        if keyword.iskeyword(s) or s in RESERVED_NAMES:
            s = f"{s}_{self.prefix}"
        base, k = s, 2
        while s in self.taken:
            s, k = f"{base}_{k}", k + 1
        self.taken.add(s)
        self.names[name] = s
        return s


@dataclass
class _Mass:
    """Mass data being merged into one body (body frame): m, m·c and the inertia about the
    body frame's origin."""

    m: float = 0.0
    mc: np.ndarray = field(default_factory=lambda: np.zeros(3))
    I_o: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    rotational: bool = False  # some link has a nonzero inertia tensor

    def add(self, m: float, c: np.ndarray, I_c: np.ndarray) -> None:
        """Add a body of mass ``m``, centre of mass ``c`` and inertia ``I_c`` about it (all in
        the body frame): Steiner's theorem moves the inertia to the origin."""
        self.m += m
        self.mc += m * c
        self.I_o += I_c + m * (float(c @ c) * np.eye(3) - np.outer(c, c))
        self.rotational = self.rotational or bool(np.any(I_c != 0.0))

    def com_inertia(self) -> tuple[np.ndarray, np.ndarray]:
        """Centre of mass and inertia about it (symmetrized)."""
        if self.m == 0.0:
            return np.zeros(3), self.I_o.copy()
        c = self.mc / self.m
        I = self.I_o - self.m * (float(c @ c) * np.eye(3) - np.outer(c, c))
        return c, 0.5 * (I + I.T)


def load_urdf(path: str | Path, *, floating_base: bool = False, gravity: float = 9.81,
              mimic: str = "error", joint_damping: bool = False,
              actuated: bool = True) -> UrdfModel:
    """Read a URDF file into a jourdain model (see the module docstring for the mapping).

    Parameters
    ----------
    path : the ``.urdf`` file
    floating_base : hang the root link from the world by a free joint (6 coordinates
        :data:`ROOT_COORDINATES`) instead of fixing it
    gravity : default value of the parameter ``g``, gravity along −z (m/s²)
    mimic : ``"error"`` (a ``<mimic>`` joint is refused, naming it) or ``"independent"`` (a
        mimic joint is an ordinary joint with its own coordinate, as Pinocchio's
        ``buildModelFromUrdf`` does unless asked otherwise; the coupling is kept as data)
    joint_damping : apply each joint's ``<dynamics damping>`` as a viscous generalized force
        ``−damping·ẏ`` (default: kept as data only, as Pinocchio)
    actuated : an input ``tau_<joint>`` on every revolute, continuous and prismatic joint

    Returns
    -------
    UrdfModel
        A :class:`~jourdain.io.ModelFile` (``.system`` is the :class:`~jourdain.System`) with
        the joints, links and geometry of the file.

    Raises
    ------
    UrdfError
        Anything the file says that jourdain cannot model, naming the file and the link or
        joint (a :class:`~jourdain.ModelError`).
    """
    name = str(path)
    if mimic not in ("error", "independent"):
        raise ModelError(f'load_urdf: mimic must be "error" or "independent", got {mimic!r}')
    g_value = _float(gravity, "load_urdf: gravity", name, None)
    yourdfpy = _yourdfpy()
    raw, lines = _read_xml(name)
    try:
        urdf = yourdfpy.URDF.load(io.BytesIO(raw), build_scene_graph=False,
                                  build_collision_scene_graph=False, load_meshes=False,
                                  load_collision_meshes=False)
    except Exception as exc:  # noqa: BLE001 - yourdfpy's own errors, reported located
        raise UrdfError(f"yourdfpy cannot read the file: {type(exc).__name__}: {exc}",
                        name) from None
    src = _Source(name, lines)
    return _build(urdf.robot, src, floating_base=floating_base, g=float(g_value),
                  mimic=mimic, joint_damping=joint_damping, actuated=actuated)


@dataclass(frozen=True)
class _Source:
    """The file being read: its name and the source lines of its links and joints."""

    path: str
    lines: Mapping[tuple[str, str], int]

    def line(self, tag: str, name: str) -> int | None:
        return self.lines.get((tag, name))


def _build(robot: Any, src: _Source, *, floating_base: bool, g: float, mimic: str,
           joint_damping: bool, actuated: bool) -> UrdfModel:
    path = src.path
    # --- the tree: unique names, every joint between declared links, one parent per link ---
    link_names = [lk.name for lk in robot.links]
    links = {}
    for lk in robot.links:
        if lk.name in links:
            raise UrdfError(f'link "{lk.name}" is declared twice', path,
                            src.line("link", lk.name))
        links[lk.name] = lk
    if not links:
        raise UrdfError("the robot has no link", path)
    parent_joint: dict[str, Any] = {}
    children: dict[str, list[Any]] = {n: [] for n in link_names}
    seen_joints: set[str] = set()
    for j in robot.joints:
        line = src.line("joint", j.name)
        if j.name in seen_joints:
            raise UrdfError(f'joint "{j.name}" is declared twice', path, line)
        seen_joints.add(j.name)
        for role, ln in (("parent", j.parent), ("child", j.child)):
            if ln not in links:
                raise UrdfError(f'joint "{j.name}": its {role} link "{ln}" is not declared '
                                "(no <link> of that name)", path, line)
        if j.type not in (*MOVING, "fixed"):
            raise UrdfError(f'joint "{j.name}": unknown joint type "{j.type}"; URDF types are '
                            "revolute, continuous, prismatic, fixed, floating, planar", path,
                            line)
        if j.child in parent_joint:
            raise UrdfError(
                f'joint "{j.name}": link "{j.child}" is already the child of joint '
                f'"{parent_joint[j.child].name}"; a link with two parents closes a kinematic '
                "loop, which is not supported (jourdain models trees)", path, line)
        if j.mimic is not None and mimic == "error":
            raise UrdfError(
                f'joint "{j.name}": mimic joints (coupled to joint "{j.mimic.joint}") are not '
                'supported; load_urdf(..., mimic="independent") reads it as an ordinary joint '
                "with its own coordinate", path, src.line("mimic", j.name) or line)
        parent_joint[j.child] = j
        children[j.parent].append(j)
    roots = [n for n in link_names if n not in parent_joint]
    if len(roots) != 1:
        if not roots:
            raise UrdfError("every link is the child of a joint: the joints form a loop "
                            "(no root link)", path)
        raise UrdfError(f"the links do not form one tree: {len(roots)} root links ("
                        + ", ".join(f'"{r}"' for r in roots) + "); connect them by joints",
                        path, src.line("link", roots[1]))
    root = roots[0]

    # --- walk the tree depth-first (children in file order): bodies, joints, mass data ---
    body_names, joint_names = _Names("link"), _Names("joint")
    body_of: dict[str, str] = {}          # link -> jourdain body ("world" for a fixed base)
    pose_of: dict[str, np.ndarray] = {}   # link -> pose in its body's frame
    mass: dict[str, _Mass] = {}
    order: list[str] = []                 # jourdain bodies, parents first
    body_spec: dict[str, dict] = {}       # body -> parent, joint
    coords: list[str] = []
    coord_units: dict[str, str] = {}
    info: dict[str, UrdfJoint] = {}
    inputs: list[str] = []
    forces: list[Any] = []
    damping: dict[str, float] = {}        # parameter d_<coordinate> -> <dynamics damping>

    if floating_base:
        b = body_names(root)
        body_of[root], pose_of[root] = b, np.eye(4)
        mass[b] = _Mass()
        order.append(b)
        coords.extend(ROOT_COORDINATES)
        coord_units.update({c: "m" if k < 3 else "rad" for k, c in enumerate(ROOT_COORDINATES)})
        body_spec[b] = {"parent": "world", "joint": Free(ROOT_JOINT, _symbols(ROOT_COORDINATES), "zyx")}
    else:
        body_of[root], pose_of[root] = "world", np.eye(4)

    def visit(ln: str) -> None:
        """The link's own mass data into its body; its joints next on the stack (depth-first,
        children in file order, as Pinocchio adds them)."""
        if body_of[ln] != "world":
            _add_inertial(mass[body_of[ln]], links[ln], pose_of[ln], src)
        stack.extend(reversed(children[ln]))

    stack: list[Any] = []
    visit(root)
    while stack:
        j = stack.pop()
        ln = j.parent
        b = body_of[ln]
        jline = src.line("joint", j.name)
        origin = _matrix(j.origin, f'joint "{j.name}" <origin>', path, jline)
        X = pose_of[ln] @ origin  # joint frame in the parent body's frame
        axis = _axis(j, path, jline)
        common = {"name": j.name, "type": j.type, "parent": j.parent, "child": j.child,
                  "axis": tuple(float(a) for a in axis), "origin": _pose(origin),
                  **_limits(j, path, jline)}
        if j.mimic is not None:
            common["mimic"] = (str(j.mimic.joint),
                               float(_float(j.mimic.multiplier, f'joint "{j.name}" mimic '
                                            "multiplier", path, jline, 1.0)),
                               float(_float(j.mimic.offset, f'joint "{j.name}" mimic offset',
                                            path, jline, 0.0)))
        if j.type == "fixed":
            body_of[j.child], pose_of[j.child] = b, X
            info[j.name] = UrdfJoint(**common, body=b, joint=None, coordinates=())
            visit(j.child)
            continue
        cb = body_names(j.child)
        jn = joint_names(j.name)
        body_of[j.child], pose_of[j.child] = cb, np.eye(4)
        mass[cb] = _Mass()
        order.append(cb)
        pos = tuple(float(x) for x in X[:3, 3])
        R = X[:3, :3]
        ori = None if np.array_equal(R, np.eye(3)) else [[float(x) for x in r] for r in R]
        axis_name = _AXIS_NAMES.get(common["axis"])  # "x", "-y", ... or None
        ax = axis_name or common["axis"]
        try:
            if j.type in ("revolute", "continuous", "prismatic"):
                q = jn
                make = Prismatic if j.type == "prismatic" else Revolute
                joint = make(jn, se.Symbol(q), ax, position=pos, orientation=ori)
                qs: tuple[str, ...] = (q,)
            elif j.type == "floating":
                qs = tuple(f"{jn}_{s}" for s in ("x", "y", "z", "yaw", "pitch", "roll"))
                joint = Free(jn, _symbols(qs), "zyx", position=pos, orientation=ori)
            else:  # planar: the plane normal to the axis, which must be a frame axis
                normal = axis_name
                if normal is None or normal.startswith("-"):
                    raise UrdfError(
                        f'joint "{j.name}": a planar joint is read only with its axis '
                        "along +x, +y or +z of the joint frame (the plane's normal), got "
                        f"{' '.join(f'{a:g}' for a in axis)}", path, jline)
                a1, a2 = {"x": "yz", "y": "zx", "z": "xy"}[normal]
                qs = (f"{jn}_{a1}", f"{jn}_{a2}", f"{jn}_rot")
                joint = Planar(jn, _symbols(qs), normal, position=pos, orientation=ori)
        except UrdfError:
            raise
        except ModelError as exc:
            raise UrdfError(f'joint "{j.name}": {exc}', path, jline) from None
        coords.extend(qs)
        coord_units.update({c: "m" if (j.type == "prismatic" or k < (
            3 if j.type == "floating" else 2 if j.type == "planar" else 0)) else "rad"
            for k, c in enumerate(qs)})
        body_spec[cb] = {"parent": b, "joint": joint}
        tau = None
        if actuated and len(qs) == 1:
            tau = f"tau_{qs[0]}"
            inputs.append(tau)
            forces.append(GeneralizedForce(f"actuator_{qs[0]}", se.Symbol(qs[0]),
                                           se.Symbol(tau)))
        if joint_damping and len(qs) == 1 and common.get("damping"):
            damping[f"d_{qs[0]}"] = float(common["damping"])
            forces.append(RotationalSpringDamper(f"damping_{qs[0]}", se.Symbol(qs[0]),
                                                 damping=se.Symbol(f"d_{qs[0]}")))
        info[j.name] = UrdfJoint(**common, body=cb, joint=jn, coordinates=qs, input=tau)
        visit(j.child)

    if not coords:
        raise UrdfError("the robot has no moving joint (every joint is fixed and the base is "
                        "fixed): nothing moves; load it with floating_base=True for a free "
                        "rigid body", path)

    # --- bodies with their merged mass data as parameters ---
    params: dict[str, float] = {"g": g}
    units: dict[str, str] = {"g": "m/s^2"}
    bodies: list[Body] = []
    below = _mass_below(order, body_spec, mass)
    link_of = {v: k for k, v in body_names.names.items()}  # body -> URDF link
    for b in order:
        md = mass[b]
        spec = body_spec[b]
        urdf_link = link_of.get(b, b)
        jname = spec["joint"].name
        if below[b] <= 0.0:
            raise UrdfError(
                f'link "{urdf_link}" (joint "{jname}") and every link it carries have no mass '
                "(no <inertial>, or mass 0): the coordinates of that joint move nothing and "
                "the mass matrix is singular; give one of these links an <inertial>", path,
                src.line("link", urdf_link))
        if md.m == 0.0 and md.rotational:
            raise UrdfError(f'link "{urdf_link}": mass 0 with a nonzero inertia tensor, which no '
                            "rigid body has; give its mass or set the inertia to 0", path,
                            src.line("link", urdf_link))
        c, I = md.com_inertia()

        def param(pname: str, value: float, unit: str) -> se.Basic:
            # a number that is exactly 0 stays a literal 0: a massless body, a point mass and
            # the zero products of inertia are then zero for the stages, not only in value
            if value == 0.0:
                return se.Integer(0)
            params[pname], units[pname] = float(value), unit
            return se.Symbol(pname)

        m_sym = param(f"m_{b}", md.m, "kg")
        com = tuple(param(f"c{a}_{b}", float(c[k]), "m") for k, a in enumerate("xyz"))
        Isym: list[list[se.Basic]] = [[se.Integer(0)] * 3 for _ in range(3)]
        for r in range(3):
            for s in range(r, 3):
                Isym[r][s] = Isym[s][r] = param(f"I{'xyz'[r]}{'xyz'[s]}_{b}", float(I[r, s]),
                                                "kg*m^2")
        try:
            bodies.append(Body(b, spec["parent"], spec["joint"], mass=m_sym, com=com,
                               inertia=Isym))
        except ModelError as exc:
            raise UrdfError(f'link "{urdf_link}": {exc}', path,
                            src.line("link", urdf_link)) from None
    params.update(damping)

    units.update(coord_units)
    units.update({tau: "N*m" if coord_units[tau[4:]] == "rad" else "N" for tau in inputs})
    clash = sorted(set(coords) & set(params) | set(coords) & set(inputs))
    if clash:
        raise UrdfError(f"the coordinate name(s) {clash} (from joint names) collide with "
                        "jourdain's parameter or input names; rename the joints", path)
    try:
        system = System(coords, bodies, [Gravity((0, 0, -se.Symbol("g"))), *forces],
                        parameters=params, inputs=inputs, units=units, name=robot.name)
    except ModelError as exc:
        raise UrdfError(str(exc), path) from None

    # --- data for viewers and users ---
    link_data = tuple(UrdfLink(ln, body_of.get(ln, "world"), _pose(pose_of.get(ln, np.eye(4))))
                      for ln in link_names)
    visuals, collisions = [], []
    for lk in robot.links:
        for v in lk.visuals:
            visuals.append(_geometry(v, lk.name, body_of[lk.name], pose_of[lk.name], src,
                                     collision=False))
        for v in lk.collisions:
            collisions.append(_geometry(v, lk.name, body_of[lk.name], pose_of[lk.name], src,
                                        collision=True))
    zero = NominalMotion(
        "zero", tuple(se.Integer(0) for _ in coords), tuple(se.Integer(0) for _ in coords),
        tuple(se.Integer(0) for _ in coords),
        description="every joint coordinate 0 (under gravity an equilibrium only where the "
                    "inputs hold it)")
    descriptions = _descriptions(system, info.values(), link_data, floating_base)
    return UrdfModel(
        path=path, system=system, descriptions=descriptions,
        description=f'URDF robot "{robot.name}" ({Path(path).name})'
                    + (", floating base" if floating_base else ""),
        nominal=(zero,) if not floating_base else (),
        simulation=SimulationSettings(y0=(0.0,) * system.f, yd0=(0.0,) * system.f),
        robot=str(robot.name), floating_base=floating_base,
        joints=tuple(info[j.name] for j in robot.joints), links=link_data,
        visual_geometry=tuple(visuals), collision_geometry=tuple(collisions))


def _descriptions(system: System, joints: Any, links: Sequence[UrdfLink],
                  floating_base: bool) -> tuple[tuple[str, str], ...]:
    """One line per coordinate, input and mass parameter, for reports and ``check``."""
    out: dict[str, str] = {}
    if floating_base:
        for c in ROOT_COORDINATES:
            out[c] = f"floating base ({ROOT_JOINT}): {c[5:]}"
    for j in joints:
        lim = (f", limits [{j.lower:g}, {j.upper:g}]"
               if j.lower is not None and j.upper is not None and j.type != "continuous" else "")
        for c in j.coordinates:
            out[c] = f'{j.type} joint "{j.name}" ({j.parent} → {j.child}){lim}'
        if j.input:
            effort = f", effort limit {j.effort:g}" if j.effort is not None else ""
            out[j.input] = f'actuator of joint "{j.name}"{effort}'
    welded: dict[str, list[str]] = {}
    for lk in links:
        if lk.body != "world" and lk.name != lk.body:
            welded.setdefault(lk.body, []).append(lk.name)
    params = system.parameter_values
    for b in system.body_names:
        extra = welded.get(b, [])
        more = f" with the welded link(s) {', '.join(extra)}" if extra else ""
        for key, what in (("m", "mass"), ("cx", "centre of mass x"), ("cy", "centre of mass y"),
                          ("cz", "centre of mass z")):
            if f"{key}_{b}" in params:
                out[f"{key}_{b}"] = f"{what} of link {b}{more}"
        for a in ("xx", "xy", "xz", "yy", "yz", "zz"):
            if f"I{a}_{b}" in params:
                out[f"I{a}_{b}"] = f"inertia I{a} of link {b}{more} about its centre of mass"
    out["g"] = "gravity along -z"
    return tuple(out.items())


def _symbols(names: Sequence[str]) -> tuple[se.Symbol, ...]:
    return tuple(se.Symbol(n) for n in names)


def _axis(j: Any, path: str, line: int | None) -> np.ndarray:
    """The unit axis of a joint (URDF's default 1 0 0); the zero vector is refused."""
    a = np.asarray(j.axis if j.axis is not None else (1.0, 0.0, 0.0), dtype=float)
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise UrdfError(f'joint "{j.name}": <axis xyz> must be 3 finite numbers', path, line)
    n = float(np.linalg.norm(a))
    if j.type in ("revolute", "continuous", "prismatic", "planar") and n == 0.0:
        raise UrdfError(f'joint "{j.name}": the axis is the zero vector', path, line)
    return a / n if n > 0 else a


def _limits(j: Any, path: str, line: int | None) -> dict[str, float | None]:
    out: dict[str, float | None] = {}
    lim, dyn = j.limit, j.dynamics
    for key in ("lower", "upper", "effort", "velocity"):
        out[key] = _float(getattr(lim, key, None) if lim is not None else None,
                          f'joint "{j.name}" <limit {key}>', path, line)
    for key in ("damping", "friction"):
        out[key] = _float(getattr(dyn, key, None) if dyn is not None else None,
                          f'joint "{j.name}" <dynamics {key}>', path, line)
    return out


def _add_inertial(md: _Mass, lk: Any, pose: np.ndarray, src: _Source) -> None:
    """Merge the link's ``<inertial>`` (mass, origin, inertia about the centre of mass in the
    inertial frame) into the body's mass data; ``pose`` is the link's frame in the body frame."""
    inertial = lk.inertial
    if inertial is None:
        return
    path, line = src.path, src.line("link", lk.name)
    m = _float(inertial.mass, f'link "{lk.name}" <mass value>', path, line, 0.0)
    if m is None or m < 0.0:
        raise UrdfError(f'link "{lk.name}": the mass must be a number ≥ 0, got {m}', path, line)
    To = _matrix(inertial.origin, f'link "{lk.name}" <inertial><origin>', path, line)
    I = np.zeros((3, 3)) if inertial.inertia is None else np.asarray(inertial.inertia, float)
    if I.shape != (3, 3) or not np.all(np.isfinite(I)):
        raise UrdfError(f'link "{lk.name}": the inertia must be finite numbers', path, line)
    T = pose @ To  # the inertial frame in the body frame
    R = T[:3, :3]
    md.add(float(m), T[:3, 3].copy(), R @ I @ R.T)


def _mass_below(order: Sequence[str], spec: Mapping[str, dict],
                mass: Mapping[str, _Mass]) -> dict[str, float]:
    """Mass of each body together with all bodies it carries."""
    total = {b: mass[b].m for b in order}
    for b in reversed(order):  # children after parents: accumulate upward
        p = spec[b]["parent"]
        if p != "world":
            total[p] += total[b]
    return total


def _geometry(el: Any, link: str, body: str, link_pose: np.ndarray, src: _Source,
              collision: bool) -> UrdfGeometry:
    path, line = src.path, src.line("link", link)
    T = link_pose @ _matrix(el.origin, f'link "{link}" geometry <origin>', path, line)
    geo = el.geometry
    rgba = None
    mat = getattr(el, "material", None)
    if mat is not None and getattr(mat, "color", None) is not None:
        rgba = tuple(float(x) for x in np.asarray(mat.color.rgba, float))
    base = {"link": link, "body": body, "pose": _pose(T), "rgba": rgba, "collision": collision}
    what = f'link "{link}" {"collision" if collision else "visual"}'
    if geo is None:
        raise UrdfError(f"{what}: no <geometry>", path, line)
    if geo.mesh is not None:
        s = geo.mesh.scale
        scale = (1.0, 1.0, 1.0) if s is None else tuple(
            float(x) for x in np.broadcast_to(np.asarray(s, float), (3,)))
        return UrdfGeometry(kind="mesh", filename=str(geo.mesh.filename),
                            path=_find_mesh(str(geo.mesh.filename), path), scale=scale,
                            **base)  # type: ignore[arg-type]
    if geo.box is not None:
        return UrdfGeometry(kind="box", size=tuple(float(x) for x in geo.box.size), **base)
    if geo.cylinder is not None:
        return UrdfGeometry(kind="cylinder", size=(float(geo.cylinder.radius),
                                                   float(geo.cylinder.length)), **base)
    if geo.sphere is not None:
        return UrdfGeometry(kind="sphere", size=(float(geo.sphere.radius),), **base)
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
