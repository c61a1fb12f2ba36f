"""A row of the constraint stage (:class:`ConstraintRow`), shared by the closing joints' rows
(:mod:`jourdain.stages.constraints`) and the contacts' (:mod:`jourdain.stages.contact_rows`)."""

from __future__ import annotations

from dataclasses import dataclass

from ..model.expressions import Expr, Vec3


@dataclass(frozen=True)
class ConstraintRow:
    """One scalar constraint equation Φ_i(y, t) = 0 of a closing joint.

    ``label``: its name (``hinge.Fx``, ``hinge.M1``, ``c.1``); ``kind``: ``force`` (λ is a
    force on A at p_A along the inertial ``direction``, its opposite on B at p_B), ``moment``
    (a moment on A about the inertial ``direction``, its opposite on B) or ``generic``;
    ``direction``: 3 expressions, or None; ``body_a``, ``body_b``, ``p_a``, ``p_b``: where the
    force acts (inertial points; None for generic rows).
    """

    joint: str
    label: str
    expr: Expr
    kind: str
    direction: Vec3 | None
    body_a: str = "world"
    body_b: str = "world"
    p_a: Vec3 | None = None
    p_b: Vec3 | None = None
    #: False for a velocity row: ``expr`` is then ``w = A_i·ẏ + a_i`` (no Φ_i exists)
    holonomic: bool = True


__all__ = ["ConstraintRow"]
