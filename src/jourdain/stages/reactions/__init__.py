"""Reaction forces (``docs/method.md`` §4): Q̄ from the joints, N̂·g = k̂ − q̂.

Produces Q̄ (``Q_bar``), N̂ (``N_hat``), k̂ (``k_hat``), q̂ (``q_hat``) and the reactions g
(:class:`Reactions`); in numbers, g at a state
(:func:`jourdain.analysis.reactions.evaluate_reactions`).

Every joint transmits a *wrench* (force and torque) in the directions it constrains. The wrench
is written in the child body's frame (the frame at the end of the joint) and acts at that frame's
origin, the joint point on the child side; the child body receives it with a plus sign, the
parent with a minus sign, each with the lever arm from the joint point to its centre of mass:

* translational rows (inertial frame): ``±S_c·F``
* rotational rows, child (child body frame, about its centre of mass): ``T − c_c × F``
* rotational rows, parent (parent body frame, about its centre of mass):
  ``−(R_pc·T + (o_pc − c_p) × R_pc·F)``, ``R_pc`` the rotation child → parent and ``o_pc`` the
  child frame's origin in the parent frame.

So ``Q̄`` (6p×q) has one column per constrained direction, ``g`` (q) are the magnitudes of the
reaction forces and torques, named ``<joint>.F_x``, ``<joint>.T_y``, ... after the joint and the
direction in the child frame. Multiplying ``M̄·J̄·ÿ + q̄^c = q̄^e + Q̄·g`` by ``Q̄ᵀM̄⁻¹`` removes
ÿ (orthogonality ``J̄ᵀQ̄ = 0``)::

    N̂·g = k̂ − q̂,   N̂ = Q̄ᵀM̄⁻¹Q̄,  k̂ = Q̄ᵀM̄⁻¹q̄^c,  q̂ = Q̄ᵀM̄⁻¹q̄^e.

Singular inertia
----------------
Rows of M̄ that are zero (the rotational rows of a point mass, the axial row of a thin rod, all
six rows of a massless body) have no inverse. They are *not* dropped: they state that the
wrench on a body without inertia balances (``0 = q̄^e_s − q̄^c_s + Q̄_s·g``, the statics of a
massless link), which determines, e.g., that a massless rod with a point mass transmits only an
axial force. With ``r`` the regular and ``s`` the singular rows, ``N̂, k̂, q̂`` are formed from the
regular rows, and the reactions solve the bordered system ::

    [ N̂    Q̄_sᵀ ] [ g ]   [ k̂ − q̂         ]
    [ Q̄_s  0    ] [ λ ] = [ q̄^c_s − q̄^e_s ],   λ = J̄_s·ÿ

(multiply the regular rows by ``Q̄_rᵀM̄_r⁻¹`` and use ``Q̄_rᵀJ̄_r = −Q̄_sᵀJ̄_s``). It is exact:
the limit of the regular method for inertia ε → 0. Components of ``g`` that this system leaves
open (redundant constrained directions, a statically indeterminate joint) are reported as
undetermined (NaN, and listed by name), never as numbers.

Modules
-------
* :mod:`.joints`: the per-joint view: constrained directions (:class:`JointReactions`,
  :func:`joint_directions`);
* :mod:`.checks`: the orthogonality ``J̄ᵀ·Q̄ = 0`` joint by joint and assembled;
* :mod:`.rows`: the rows of M̄ without inertia;
* :mod:`.subtree`: the wrench of one joint from the sub-tree it carries;
* :mod:`.formation`: Q̄, N̂, k̂, q̂ (:func:`reactions`, :class:`Reactions`);
The reactions in numbers are on the analysis floor, above the compiled code:
:mod:`jourdain.analysis.reactions` (``evaluate_reactions``, ``joint_reactions``, ``solve_g``).
"""

from ...graph import evaluate_arrays as graph_values
from .checks import check_joints
from .formation import Reactions, reactions
from .joints import JointReactions, constrained_directions, joint_directions, relative_twist

__all__ = [
    "JointReactions", "Reactions", "check_joints", "constrained_directions", "graph_values",
    "joint_directions", "reactions", "relative_twist",
]
