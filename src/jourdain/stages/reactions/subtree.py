"""The wrench one joint transmits, from the Newton–Euler residual of the sub-tree it carries
(``docs/method.md`` §4): ``Σ (m_i a_i − f_i^e, I_i α_i + ω̃_i I_i ω_i − l_i^e)`` moved to the
joint point and the child frame, projected on the joint's directions (``Reactions.joint_g``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import symengine as se

from ...errors import JourdainError
from ...model.joints import Vec3
from ...symbolic import SymMatrix
from ..kinematics import Z3, _add, _cross, _dot, _mat, _mtv, _mv, _scale
from ..newton_euler import NewtonEuler

if TYPE_CHECKING:
    from ...model.system import System
from .joints import ZERO, JointReactions, Wrench, _sample_values


# --- reactions of one joint from its sub-tree --------------------------------------------------
def _subtree(system: System, root: str) -> list[str]:
    below = {root}
    for b in system.bodies:  # tree order: parents come first
        if b.parent in below:
            below.add(b.name)
    return [b.name for b in system.bodies if b.name in below]


def _subtree_parts(ne: NewtonEuler, child: str) -> tuple[Wrench, list[Wrench]]:
    """Residual wrench of the sub-tree below (and including) ``child``, at the child frame's
    origin, in the child frame, split as ``W0 + Σ_j W_j·ÿ_j`` (it is linear in ÿ): ``W0`` from
    the local accelerations, the gyroscopic and the applied forces, ``W_j`` from the Jacobian
    columns of coordinate j."""
    kin = ne.kinematics
    system = kin.system
    f = len(kin.y)
    forces = {bf.name: bf for bf in ne.forces}
    bc = kin[child]
    Sc = _mat(bc.S)
    rO = _v(bc.r_O)
    W0: list[se.Basic] = [ZERO] * 6
    Wy: list[list[se.Basic]] = [[ZERO] * 6 for _ in range(f)]

    def add(acc: list[se.Basic], name: str, F: Vec3, tau: Vec3, arm: Vec3) -> None:
        # move a force (inertial, at the COM) and a torque (body frame) to the child frame
        Fc = _mtv(Sc, F)
        tau_c = tau if name == child else _mtv(Sc, _mv(_mat(kin[name].S), tau))
        T = _add(tau_c, _cross(arm, Fc))
        for a in range(3):
            acc[a] = acc[a] + Fc[a]
            acc[3 + a] = acc[3 + a] + T[a]

    for name in _subtree(system, child):
        body = system.body(name)
        bk = kin[name]
        bf = forces[name]
        r = _v(bk.r)
        arm = _mtv(Sc, (r[0] - rO[0], r[1] - rO[1], r[2] - rO[2]))
        m = body.mass
        a_bar = _v(bk.a_bar)
        F = (m * a_bar[0] - bf.f[0], m * a_bar[1] - bf.f[1], m * a_bar[2] - bf.f[2])
        tau: Vec3 = (-bf.l[0], -bf.l[1], -bf.l[2])
        I = body.inertia
        if body.has_inertia:
            w = _v(bk.omega)
            tau = _add(tau, _add(_mv(I, _v(bk.alpha_bar)), _cross(w, _mv(I, w))))
        add(W0, name, F, tau, arm)
        for j in set(bk.cols_T) | set(bk.cols_R):
            Fj = _scale(bk.cols_T.get(j, Z3), m)
            tj = _mv(I, bk.cols_R[j]) if body.has_inertia and j in bk.cols_R else Z3
            add(Wy[j], name, Fj, tj, arm)
    return tuple(W0), [tuple(w) for w in Wy]


def _subtree_wrench(ne: NewtonEuler, child: str) -> Wrench:
    """Residual wrench of the sub-tree below ``child`` (see :func:`_subtree_parts`) with ÿ as
    the symbols ``<coordinate>_dd``."""
    W0, Wy = _subtree_parts(ne, child)
    ydd = ne.kinematics.ydd
    return tuple(se.Add(W0[a], *(Wy[j][a] * ydd[j] for j in range(len(Wy))))
                 for a in range(6))


def _v(m: SymMatrix) -> Vec3:
    return (m.rows[0][0], m.rows[1][0], m.rows[2][0])


def _project(jr: JointReactions, W: Wrench) -> list[se.Basic]:
    """Components of the wrench W in the joint's constrained directions (orthonormal ones)."""
    n = len(jr.wrenches)
    if n:
        rng = np.random.default_rng(3)
        E = _sample_values([x for w in jr.wrenches for x in w], (), {}, rng, 3).reshape(n, 6, 3)
        gram = np.einsum("kas,mas->kms", E, E)
        if np.abs(gram - np.eye(n)[:, :, None]).max() > 1e-12:
            raise JourdainError(
                f'joint "{jr.joint.name}": its constrained directions are not orthonormal; '
                "use joint_reactions() or evaluate_reactions() instead"
            )
    out = []
    for w in jr.wrenches:
        out.append(_dot(w[:3], W[:3]) + _dot(w[3:], W[3:]))
    return out
