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
* a closed system's closing joints (``system.closing``): red lines from each body's origin to
  its point of the joint, the two points joined, and a marker at the joint (the scene's
  ``"closing"``; :func:`closing_ends` gives both points along the frames). The bodies of a
  closed system move as its tree's at the same coordinates (:func:`body_poses` composes the
  joints of ``system.tree``'s bodies), which are on the manifold Φ = 0: the loop drawn closed;
* ``jd.view(system, y=...)``: one configuration at rest (:func:`at_rest`; a closed system's
  assembled onto its loops);
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

from .meshes import Mesh, read_mesh
from .page import View, at_rest, embed, model_visuals, report_section, view
from .poses import body_poses, closing_points, frame_times, pose_function, quaternions
from .scene import closing_ends, decode_poses
from .visuals import (
    FRAMES_PER_SECOND,
    MAX_FRAMES,
    MAX_POSES,
    MAX_TRIANGLES,
    MIN_THICKNESS,
    SCENE_FORMAT,
    SHAPES,
    VISUAL_KINDS,
    MeshVisual,
    Visual,
    equivalent_shape,
    rpy_matrix,
    visuals_by_body,
)

__all__ = ["FRAMES_PER_SECOND", "MAX_FRAMES", "MAX_POSES", "MAX_TRIANGLES", "MIN_THICKNESS",
           "SCENE_FORMAT", "SHAPES", "VISUAL_KINDS", "Mesh", "MeshVisual", "View", "Visual",
           "at_rest", "body_poses", "closing_ends", "closing_points", "decode_poses", "embed", "equivalent_shape", "frame_times",
           "model_visuals", "pose_function", "quaternions", "read_mesh",
           "report_section", "rpy_matrix", "view", "visuals_by_body"]
