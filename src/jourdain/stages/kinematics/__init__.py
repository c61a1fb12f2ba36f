"""Kinematics of every body (``docs/method.md`` §1): r, S, ω, J_T, J_R, v̄, ω̄, ā, ᾱ.

Produces :class:`Kinematics` (one :class:`BodyKinematics` per body) and the joints' relative
motions (:func:`joint_motions`).

Conventions
-----------
* Translational quantities (``r``, ``J_T``, ``v_bar``, ``a_bar``) are in the **inertial frame**.
* Rotational quantities (``omega``, ``J_R``, ``omega_bar``, ``alpha_bar``) are in the **body
  frame**, where the inertia tensor is constant.
* ``S`` turns body-frame components into inertial ones: ``x_inertial = S · x_body``.

So ``v = J_T·ẏ + v̄`` (inertial) and ``ω = J_R·ẏ + ω̄`` (body frame), and likewise
``a = J_T·ÿ + ā``, ``α = J_R·ÿ + ᾱ``.

Method
------
The quantities are built *recursively* along the tree, one elementary transformation at a time
(as in recursive Newton–Euler algorithms), never by differentiating the composed position
vectors. Each new expression refers to the previous ones, so the result is a shared expression
graph whose size grows linearly with the depth of the tree instead of exponentially. Only the
angles and distances of the elementary steps (short user expressions) are differentiated.
Consecutive rotations about the same fixed axis are merged into one angle, so a planar chain
measured with absolute angles gives ``S = R_z(q_i)`` rather than a product of rotations.

Modules
-------
* :mod:`.vectors`: 3-vectors and 3×3 matrices as tuples of expressions;
* :mod:`.frames`: frame orientations and the rotations between them;
* :mod:`.recursion`: the elementary steps along the tree;
* :mod:`.result`: the stage (:func:`kinematics`) and the joints' motions.

The helpers of :mod:`.vectors` and :mod:`.frames` are re-exported here for the stages after this
one (Newton–Euler, projection, reactions) and the closed loops.
"""

from .frames import ROOT as ROOT
from .frames import FrameTag as FrameTag
from .frames import relative_rotation as relative_rotation
from .frames import step_axis as step_axis
from .result import BodyKinematics, JointMotion, Kinematics, joint_motions, kinematics
from .vectors import Z3 as Z3
from .vectors import _add as _add
from .vectors import _cross as _cross
from .vectors import _dot as _dot
from .vectors import _is_zero as _is_zero
from .vectors import _mat as _mat
from .vectors import _mm as _mm
from .vectors import _mtm as _mtm
from .vectors import _mtv as _mtv
from .vectors import _mv as _mv
from .vectors import _scale as _scale
from .vectors import _vec as _vec

__all__ = ["BodyKinematics", "JointMotion", "Kinematics", "joint_motions", "kinematics"]
