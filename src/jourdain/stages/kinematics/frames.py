"""Frame orientations (``docs/method.md`` §1): :class:`FrameTag` links each orientation to its
parent by the shallow rotation between them, so relative rotations between two frames are
products of the few rotations between them (:func:`relative_rotation`), not of the deep ``S``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import symengine as se

from ...errors import ModelError
from ...model.joints import IDENTITY, Mat3, Rot, Trans, Vec3, rotation_matrix

if TYPE_CHECKING:
    pass
from .vectors import _mm, _mtm


class FrameTag:
    """Identity of a frame orientation, linked to its parent orientation.

    ``A`` gives this frame's axes in the parent's (v_parent = A·v_this), ``S`` the inertial
    orientation, ``axis`` = (u, θ) when all rotations from the inertial frame are about one fixed
    axis u (then S = R_u(θ)). Relative rotations between two frames are products of the shallow
    ``A`` matrices between them (:func:`relative_rotation`), not products of the deep ``S``.
    """

    __slots__ = ("parent", "A", "S", "axis", "depth")

    def __init__(self, parent: FrameTag | None, A: Mat3, S: Mat3,
                 axis: tuple[Vec3, se.Basic] | None) -> None:
        self.parent, self.A, self.S, self.axis = parent, A, S, axis
        self.depth: int = 0 if parent is None else parent.depth + 1


ROOT = FrameTag(None, IDENTITY, IDENTITY, None)


def step_axis(step: Rot | Trans) -> Vec3:
    """The axis of an elementary step; a translation given by a vector has none."""
    if step.axis is None:
        raise ModelError("a translation given by a vector has no axis")
    return step.axis


def relative_rotation(a: FrameTag, b: FrameTag) -> Mat3 | None:
    """S_aᵀ·S_b (b's axes in a's frame); None when a is b (the identity)."""
    if a is b:
        return None
    if a is ROOT and b.axis is not None:
        return rotation_matrix(b.axis[0], b.axis[1])
    if b is ROOT and a.axis is not None:
        return rotation_matrix(a.axis[0], -a.axis[1])
    if a.axis is not None and b.axis is not None and a.axis[0] == b.axis[0]:
        return rotation_matrix(a.axis[0], b.axis[1] - a.axis[1])
    # down from the common ancestor c: S_a = S_c·A_(c→a), S_b = S_c·A_(c→b)
    pa: list[Mat3] = []
    pb: list[Mat3] = []
    x, y = a, b
    while x is not y:
        if x.depth >= y.depth:
            pa.append(x.A)
            x = x.parent  # type: ignore[assignment]
        else:
            pb.append(y.A)
            y = y.parent  # type: ignore[assignment]
    Ra = _chain(pa[::-1])
    Rb = _chain(pb[::-1])
    if Ra is None:
        return Rb
    if Rb is None:
        return tuple(tuple(Ra[j][i] for j in range(3)) for i in range(3))  # type: ignore[return-value]
    return _mtm(Ra, Rb)


def _chain(ms: list[Mat3]) -> Mat3 | None:
    out = None
    for m in ms:
        out = m if out is None else _mm(out, m)
    return out


class Node:
    """One elementary step of the recursion in a shared kinematics (``kinematics(...,
    shared=True)``): the tree of these steps is what the composite-body projection
    (:mod:`jourdain.stages.composite`) walks, up for the composite bodies and down for the
    Jacobian columns.

    ``A``: the step's rotation (v_parent = A·v_this), or ``d``: its translation (parent-frame
    components; the orientation is the parent's); ``tag``: the orientation after the step;
    ``JR``, ``JT``: every Jacobian column of the frame's origin after the step in its own
    components (the twist of each coordinate there: angular velocity and velocity of the
    origin per unit rate); ``anchors``: ``(j, δω, δv)`` for each coordinate j this step depends
    on directly (its angle or vector is a function of y_j), with the twist it adds here (the
    axis times ∂angle/∂y_j, or ∂vector/∂y_j): below the step, the columns of y_j are rigid
    transports of these twists. ``index`` is the step's place in the order of creation
    (parents first).
    """

    __slots__ = ("parent", "A", "d", "tag", "JR", "JT", "anchors", "index")

    def __init__(self, parent: Node | None, A: Mat3 | None, d: Vec3 | None, tag: FrameTag,
                 JR: dict[int, Vec3], JT: dict[int, Vec3],
                 anchors: tuple[tuple[int, Vec3, Vec3], ...],
                 index: int) -> None:
        self.parent, self.A, self.d, self.tag = parent, A, d, tag
        self.JR, self.JT, self.anchors, self.index = JR, JT, anchors, index
