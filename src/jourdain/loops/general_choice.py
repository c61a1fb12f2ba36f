"""The partition of a general system (velocity constraints, :mod:`jourdain.loops.general`):
its constraint stage, the choice of independent coordinates, kept rows and speeds at a state
(:func:`choose`), and the rows' least-norm multipliers (:func:`least_norm`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from ..errors import ModelError, SingularConfiguration
from ..model import System
from ..model.forces import rate
from ..stages.constraints import Constraints
from ..stages.constraints import constraints as constraint_stage
from ..stages.kinematics import kinematics
from .partitioning import _rank_tol, partition


def general_constraints(system: System) -> Constraints:
    """The constraint stage of ``system`` (kept by a :class:`jourdain.System`)."""
    stage = getattr(system, "constraints", None)
    if callable(stage):
        return stage()
    return constraint_stage(kinematics(system.tree), system.closing, system.contacts)


@dataclass(frozen=True)
class Choice:
    """The partition of a general system: independent coordinates (indices into y), the
    holonomic rows kept, the velocity rows kept, the speeds' names and, for chosen
    coordinates' rates, their indices."""

    independent: tuple[int, ...]
    dependent: tuple[int, ...]
    rows_h: tuple[int, ...]
    rows_v: tuple[int, ...]
    speeds: tuple[str, ...]
    speed_coordinates: tuple[int, ...] | None


def choose(system: System, fn: dict[str, np.ndarray]) -> Choice:
    """The partition at the state whose functions are ``fn``: independent coordinates by
    pivoting on Φ_y (or the user's, checked), the independent velocity rows by pivoting on
    Aᵀ, and the speeds: the user's (their count checked: g = f − rank A) or the rates of the
    coordinates left by pivoting on A's columns."""
    names = system.coordinate_names
    f = len(names)
    bad = [k for k in ("Phi", "Phi_y", "A", "a") if not np.all(np.isfinite(fn[k]))]
    if bad:
        labels = general_constraints(system).labels
        rows = np.concatenate([np.isfinite(fn["A"]).all(axis=1),
                               np.ones(len(labels) - fn["A"].shape[0], bool)])
        named = sorted({labels[i].split(".")[0] for i in range(len(labels)) if not rows[i]})
        raise SingularConfiguration(
            f"{system.name}: the rows of {', '.join(named or [c.name for c in system.contacts])}"
            f" are not defined at this state ({', '.join(bad)} not finite: a disc lying flat on "
            "the ground has no contact point, a knife edge along the normal no direction)")
    Pz = np.real(fn["Phi_y"])
    if Pz.shape[0]:
        part = partition(system, Pz, system.independent)
        ind, dep, rows_h = part.independent, part.dependent, part.rows
    else:
        ind, dep, rows_h = tuple(range(f)), (), ()
    A = np.real(fn["A"])
    _, R, piv = sla.qr(A.T, mode="economic", pivoting=True)
    diag = np.abs(np.diag(R)) if R.size else np.zeros(0)
    r = int(np.sum(diag > _rank_tol(A) * 1e3)) if A.size else 0
    rows_v = tuple(sorted(int(i) for i in piv[:r]))
    g = f - r
    if system.speeds is not None:
        if len(system.speeds) != g:
            raise ModelError(f"{system.name}: {f} coordinates and {r} independent velocity "
                             f"rows leave {g} generalized velocities, but {len(system.speeds)} "
                             f"speeds were given ({', '.join(n for n, _ in system.speeds)})")
        sc = tuple(names.index(n[:-2]) for n, e in system.speeds
                   if n.endswith("_d") and n[:-2] in names and e == rate(
                       system.coordinates[names.index(n[:-2])]))
        return Choice(ind, dep, rows_h, rows_v, tuple(n for n, _ in system.speeds),
                      sc if len(sc) == g else None)
    Ak = A[list(rows_v), :]
    if r:
        _, _, cp = sla.qr(Ak, mode="economic", pivoting=True)
        vdep = {int(j) for j in cp[:r]}
    else:
        vdep = set()
    sc = tuple(j for j in range(f) if j not in vdep)
    return Choice(ind, dep, rows_h, rows_v, tuple(f"{names[j]}_d" for j in sc), sc)


def least_norm(A: np.ndarray, r: np.ndarray, rank: int) -> tuple[np.ndarray, np.ndarray]:
    """The least-norm λ of ``Aᵀ·λ = r`` (A: m×n, or stacked N×m×n with r N×n), the SVD of Aᵀ
    truncated at ``rank`` (the independent rows), and the rows' null combinations (those
    beyond the rank: where the equations leave the multipliers open)."""
    U, sv, Vt = np.linalg.svd(np.swapaxes(A, -1, -2), full_matrices=False)
    inv = np.zeros_like(sv)
    inv[..., :rank] = 1.0 / sv[..., :rank]
    lam = np.einsum("...ji,...j->...i", Vt, inv * np.einsum("...ij,...i->...j", U, r))
    return lam, Vt[..., rank:, :]


__all__ = ["Choice", "choose", "general_constraints", "least_norm"]
