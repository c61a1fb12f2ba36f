"""Kinematic loops (issue 11): closing joints, coordinate partitioning, assembly, M, k, q in
independent coordinates, simulation on the constraint manifold, reactions of the closing
joints and linearization. See :mod:`jourdain.loops.closed_loop` for the method."""

from .closed_loop import (
    Assembly,
    AssemblyError,
    ClosedLoopSystem,
    Constraints,
    LoopEvaluator,
    Partition,
    SingularConfiguration,
    constraints,
    evaluate,
    partition,
)
from .closing_joints import KINDS, ClosingJoint, ConstraintRow, grubler

__all__ = ["KINDS", "Assembly", "AssemblyError", "ClosedLoopSystem", "ClosingJoint",
           "ConstraintRow", "Constraints", "LoopEvaluator", "Partition",
           "SingularConfiguration", "constraints", "evaluate", "grubler", "partition"]
