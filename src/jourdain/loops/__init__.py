"""The numbers of closed systems (closing joints, METHOD.md §7): coordinate partitioning,
assembly, M, k, q in independent coordinates, simulation on the constraint manifold, reactions
of the closing joints and linearization. A closed system is a :class:`jourdain.System` with
``closing`` joints; its methods and the package's functions call these. See
:mod:`jourdain.loops.closed_loop` for the method."""

from ..model.closing import KINDS, ClosingJoint, grubler
from ..stages.constraints import ConstraintRow
from .closed_loop import (
    Assembly,
    AssemblyError,
    Constraints,
    LoopEvaluator,
    Partition,
    SingularConfiguration,
    constraints,
    evaluate,
    partition,
)

__all__ = ["KINDS", "Assembly", "AssemblyError", "ClosingJoint", "ConstraintRow",
           "Constraints", "LoopEvaluator", "Partition", "SingularConfiguration", "constraints",
           "evaluate", "grubler", "partition"]
