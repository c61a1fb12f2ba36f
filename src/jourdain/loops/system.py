"""The errors of the numbers of closed systems, and the constraint stage
(:mod:`jourdain.stages.constraints`: Φ, Φ_y, Φ_t, c) of a closed :class:`jourdain.System`
compiled (:func:`constraint_function`). In this package ``z`` names
the tree's coordinates (the system's ``y``) and ``y`` the independent ones. The method is
described in :mod:`jourdain.loops.closed_loop`."""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..errors import AssemblyError, ClosedSystemError, ModelError, SingularConfiguration
from ..model import System
from ..numeric import CompiledFunction, lambdify
from ..stages.constraints import Constraints
from ..stages.constraints import constraints as constraint_stage
from ..stages.kinematics import kinematics  # the model has no stage methods (issue 16)

EPS = float(np.finfo(float).eps)


def constraints(loop: System) -> Constraints:
    """The constraint stage of a closed ``loop`` (:func:`jourdain.stages.constraints.constraints`
    on the tree's kinematics), kept by the system; ModelError when its closing joints give no
    row."""
    if getattr(loop, "is_general", False):
        raise ClosedSystemError(loop, "the numbers of closed systems (holonomic rows, "
                                "ẏ_i as velocities) do not apply; its velocity constraints "
                                "need the general path (jourdain.loops.general)")
    con = _constraints(loop)
    if not con.rows:
        raise ModelError(f"{loop.name}: the closing joints give no constraint equation (every "
                         "row vanishes identically)")
    return con


@lru_cache(maxsize=16)
def _constraints(loop: System) -> Constraints:
    stage = getattr(loop, "constraints", None)
    if callable(stage):  # a jourdain.System: its kept stage
        return stage()
    return constraint_stage(kinematics(loop.tree), loop.closing)


@lru_cache(maxsize=16)
def constraint_function(loop: System) -> CompiledFunction:
    """Compiled ``Phi, Phi_z, Phi_t, c`` (memoized; the energies of a run are its
    :class:`jourdain.Results`')."""
    con = constraints(loop)
    return lambdify(loop.tree, {"Phi": con.Phi, "Phi_z": con.Phi_y, "Phi_t": con.Phi_t,
                                "c": con.c})


__all__ = ["EPS", "AssemblyError", "Constraints", "SingularConfiguration",
           "constraint_function", "constraints"]
