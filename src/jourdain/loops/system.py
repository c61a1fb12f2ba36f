"""The data of a closed-loop system (issue 11): a spanning tree and its closing joints, the
errors of the loop stages, and the symbolic constraint equations Φ, Φ_z, Φ_t and the
convective term c (:func:`constraints`), compiled with the tree's energies
(:func:`constraint_function`). The method is described in :mod:`jourdain.loops.closed_loop`."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
import symengine as se

from ..analysis.energy import energy
from ..errors import JourdainError, ModelError
from ..model import System
from ..model.forces import rate
from ..numeric import CompiledFunction, lambdify
from ..stages.kinematics import kinematics  # the model has no stage methods (issue 16)
from ..symbolic import SymMatrix
from .closing_joints import ClosingJoint, ConstraintRow, constraint_rows, grubler

EPS = float(np.finfo(float).eps)


class SingularConfiguration(JourdainError, ArithmeticError):
    """The dependent coordinates cannot be solved: ``Φ_d`` is singular or too ill-conditioned
    at the time and state given (a change of the partition may help where the constraint
    Jacobian ``Φ_z`` itself keeps full rank). Attributes ``t``, ``z``, ``zd``, ``cond``,
    ``rank`` (of Φ_z), ``suggestion`` (a partition that is well-conditioned there, or None)."""

    def __init__(self, message: str, t: float = float("nan"), z: Any = None, zd: Any = None,
                 cond: float = float("inf"), rank: int | None = None,
                 suggestion: tuple[str, ...] | None = None) -> None:
        super().__init__(message)
        self.t, self.z, self.zd, self.cond, self.rank = t, z, zd, cond, rank
        self.suggestion = suggestion


class AssemblyError(JourdainError, ValueError):
    """Newton's method found no configuration on the manifold near the one given."""



@dataclass(frozen=True)
class LoopModel:
    """A tree :class:`~jourdain.System` (coordinates z) closed by closing joints (the data;
    :class:`jourdain.loops.ClosedLoopSystem` adds the stages as methods).

    Parameters
    ----------
    tree : System
        The spanning tree; its coordinates are the redundant coordinates z.
    closing : sequence of ClosingJoint
    independent : sequence of coordinate names, optional
        The independent coordinates y (else chosen by pivoting at the initial configuration).
    name : str, optional
    """

    tree: System
    closing: tuple[ClosingJoint, ...]
    independent: tuple[str, ...] | None = None
    name: str = ""

    def __init__(self, tree: System, closing: Sequence[ClosingJoint],
                 independent: Sequence[str] | None = None, name: str | None = None) -> None:
        set_ = object.__setattr__
        if not isinstance(tree, System):
            raise ModelError(f"LoopModel: tree must be a System, got {type(tree).__name__}")
        set_(self, "tree", tree)
        closing = tuple(closing)
        if not closing:
            raise ModelError("LoopModel: no closing joints (a tree needs none)")
        names: set[str] = set()
        bodies = set(tree.body_names) | {"world"}
        joint_names = {b.joint.name for b in tree.bodies}
        params = {k for k, _ in tree.parameters}
        coords = set(tree.coordinate_names)
        for cj in closing:
            if not isinstance(cj, ClosingJoint):
                raise ModelError(f"closing joints: expected ClosingJoint objects, got "
                                 f"{type(cj).__name__}")
            if cj.name in names or cj.name in joint_names:
                raise ModelError(f'closing joint "{cj.name}": the name is used twice')
            names.add(cj.name)
            for side in (cj.body_a, cj.body_b):
                if side not in bodies:
                    raise ModelError(f'closing joint "{cj.name}": unknown body "{side}"; bodies '
                                     f"are {', '.join(sorted(bodies))}")
            allowed = params | (coords | {"t"} if cj.type == "constraint" else set())
            unknown = sorted(cj.symbols() - allowed)
            if unknown:
                what = ("coordinates, t and parameters" if cj.type == "constraint"
                        else "parameters (points and axes are constant in their bodies)")
                raise ModelError(f'closing joint "{cj.name}": unknown name(s) '
                                 f"{', '.join(unknown)}; it may use {what}")
        set_(self, "closing", closing)
        if independent is not None:
            ind = tuple(str(c) for c in independent)
            for c in ind:
                if c not in coords:
                    raise ModelError(f'independent coordinate "{c}" is not a coordinate of the '
                                     f"tree ({', '.join(tree.coordinate_names)})")
            if len(set(ind)) != len(ind):
                raise ModelError(f"independent coordinates {list(ind)} name one twice")
            set_(self, "independent", ind)
        else:
            set_(self, "independent", None)
        set_(self, "name", tree.name if name is None else str(name))

    @property
    def n(self) -> int:
        """Number of tree coordinates z."""
        return self.tree.f

    @property
    def coordinate_names(self) -> list[str]:
        return self.tree.coordinate_names

    def grubler(self) -> int:
        """Degrees of freedom by the Grübler–Kutzbach count (spatial: 6 per body)."""
        return grubler(len(self.tree.bodies), [len(b.joint.coordinates)
                                               for b in self.tree.bodies], self.closing)


@dataclass(frozen=True)
class Constraints:
    """The constraint equations of a loop system (symbolic, in z, ż, t and parameters).

    ``rows`` (m ConstraintRow), ``Phi`` (m×1), ``Phi_z`` (m×n), ``Phi_t`` (m×1), ``c``
    (m×1): ``Φ̈ = Φ_z·z̈ + c``.
    """

    rows: tuple[ConstraintRow, ...]
    Phi: SymMatrix
    Phi_z: SymMatrix
    Phi_t: SymMatrix
    c: SymMatrix

    @property
    def labels(self) -> list[str]:
        return [r.label for r in self.rows]


@lru_cache(maxsize=16)
def constraints(loop: LoopModel) -> Constraints:
    """Φ, Φ_z, Φ_t and the convective term c of ``loop`` from the tree's kinematics."""
    tree = loop.tree
    rows = constraint_rows(kinematics(tree), loop.closing)
    if not rows:
        raise ModelError(f"{loop.name}: the closing joints give no constraint equation (every "
                         "row vanishes identically)")
    z = tree.coordinates
    zd = [rate(c) for c in z]
    t = tree.t
    Phi = [r.expr for r in rows]
    Phi_z = [[se.diff(e, zj) for zj in z] for e in Phi]
    Phi_t = [se.diff(e, t) for e in Phi]
    # w = Φ̇ = Φ_z ż + Φ_t; c = ∂w/∂z·ż + ∂w/∂t (the part of Φ̈ without z̈)
    c = []
    for i in range(len(Phi)):
        w = sum((Phi_z[i][j] * zd[j] for j in range(len(z))), se.Integer(0)) + Phi_t[i]
        ci = sum((se.diff(w, z[j]) * zd[j] for j in range(len(z))), se.Integer(0)) \
            + se.diff(w, t)
        c.append(ci)
    return Constraints(tuple(rows), SymMatrix.column(Phi), SymMatrix.from_rows(Phi_z),
                       SymMatrix.column(Phi_t), SymMatrix.column(c))


@lru_cache(maxsize=16)
def constraint_function(loop: LoopModel) -> CompiledFunction:
    """Compiled ``Phi, Phi_z, Phi_t, c`` and the tree's energies ``T, V`` (memoized)."""
    con = constraints(loop)
    e = energy(kinematics(loop.tree))
    return lambdify(loop.tree, {"Phi": con.Phi, "Phi_z": con.Phi_z, "Phi_t": con.Phi_t,
                                "c": con.c, "T": SymMatrix.column([e.T]),
                                "V": SymMatrix.column([e.V])})




__all__ = ["EPS", "AssemblyError", "Constraints", "LoopModel", "SingularConfiguration",
           "constraint_function", "constraints"]
