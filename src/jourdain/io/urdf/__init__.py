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

A model built from a file is kept in the compile cache under a hash of the file's bytes, the
options and jourdain's source (:mod:`~jourdain.io.urdf.cache`): read again, it comes from there
without importing yourdfpy.

Mimic joints (``<mimic joint="d" multiplier="k" offset="o"/>``) are coupled: the joint turns
(slides) by ``k·q_d + o``, a function of the coordinate of joint d, which both share
(``mimic="coupled"``, the default; as Pinocchio's ``buildModelFromUrdf(..., mimic=True)``);
``mimic="independent"`` makes them ordinary joints with their own coordinates (Pinocchio's
default), ``mimic="error"`` refuses them. A mimic joint has no actuator of its own.

Not supported, each a :class:`UrdfError` naming the link or joint and the file: closed loops (a link that is the child of two joints, ``<loop_joint>`` extensions),
a joint whose parent or child link is not declared, several root links, a moving body with no
mass anywhere below it (M would be singular), malformed XML, DTDs (entity declarations).
"""


from __future__ import annotations

import io
from pathlib import Path

from ...errors import ModelError
from .build import _build
from .cache import cached, keep, model_key
from .model import (
    ROOT_COORDINATES,
    ROOT_JOINT,
    UrdfError,
    UrdfGeometry,
    UrdfJoint,
    UrdfLink,
    UrdfModel,
)
from .source import _float, _read_xml, _Source, _yourdfpy

__all__ = ["UrdfError", "UrdfGeometry", "UrdfJoint", "UrdfLink", "UrdfModel", "load_urdf",
           "ROOT_JOINT", "ROOT_COORDINATES"]



def load_urdf(path: str | Path, *, floating_base: bool = False, gravity: float = 9.81,
              mimic: str = "coupled", joint_damping: bool = False,
              actuated: bool = True) -> UrdfModel:
    """Read a URDF file into a jourdain model (see the module docstring for the mapping).

    Parameters
    ----------
    path : the ``.urdf`` file
    floating_base : hang the root link from the world by a free joint (6 coordinates
        :data:`ROOT_COORDINATES`) instead of fixing it
    gravity : default value of the parameter ``g``, gravity along −z (m/s²)
    mimic : ``"coupled"`` (a ``<mimic>`` joint follows the coordinate of the joint it mimics,
        ``k·q_d + o``: one coordinate for both), ``"independent"`` (an ordinary joint with its
        own coordinate, as Pinocchio's ``buildModelFromUrdf`` does unless asked otherwise; the
        coupling is kept as data) or ``"error"`` (refused, naming it)
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
    if mimic not in ("coupled", "error", "independent"):
        raise ModelError('load_urdf: mimic must be "coupled", "independent" or "error", got '
                         f"{mimic!r}")
    g_value = _float(gravity, "load_urdf: gravity", name, None)
    if g_value is None:
        raise ModelError("load_urdf: gravity must be a number, got None")
    raw, lines = _read_xml(name)
    key = model_key(raw, str(Path(name).resolve()),
                    {"floating_base": bool(floating_base), "g": g_value, "mimic": mimic,
                     "joint_damping": bool(joint_damping), "actuated": bool(actuated)})
    model = cached(key)
    if model is not None:  # built before from these bytes (io.urdf.cache): no yourdfpy import
        return model
    yourdfpy = _yourdfpy()
    try:
        urdf = yourdfpy.URDF.load(io.BytesIO(raw), build_scene_graph=False,
                                  build_collision_scene_graph=False, load_meshes=False,
                                  load_collision_meshes=False)
    except Exception as exc:  # noqa: BLE001 - yourdfpy's own errors, reported located
        raise UrdfError(f"yourdfpy cannot read the file: {type(exc).__name__}: {exc}",
                        name) from None
    src = _Source(name, lines)
    model = _build(urdf.robot, src, floating_base=floating_base, g=g_value,
                   mimic=mimic, joint_damping=joint_damping, actuated=actuated)
    keep(key, model)
    return model


