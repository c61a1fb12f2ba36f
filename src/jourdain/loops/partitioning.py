"""Coordinate partitioning of a closed-loop system: z = (y, d) by QR with column pivoting on
the constraint Jacobian Φ_z (the independent rows of Φ, then the best-conditioned Φ_d), or
the user's choice checked."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from ..errors import ModelError
from .system import EPS, System


@dataclass(frozen=True)
class Partition:
    """Independent and dependent coordinates, as indices into z, and the constraint rows kept.

    ``rows``: indices of the independent rows of Φ (rank of Φ_z at the partition state);
    ``cond``: condition number of Φ_d there.
    """

    independent: tuple[int, ...]
    dependent: tuple[int, ...]
    rows: tuple[int, ...]
    cond: float
    names: tuple[str, ...] = field(default=())

    @property
    def f(self) -> int:
        return len(self.independent)


def _rank_tol(A: np.ndarray) -> float:
    return max(A.shape) * EPS * (np.linalg.norm(A, 2) if A.size else 0.0)


def _cond(A: np.ndarray) -> float:
    """2-norm condition number of ``A`` (inf when singular; 1 when empty)."""
    if not np.isfinite(A).all():  # never factorized: LAPACK's SVD may not return on inf
        return float("inf")
    s = np.linalg.svd(A, compute_uv=False) if A.size else np.ones(1)
    return float(s[0] / s[-1]) if s[-1] > 0 else float("inf")


def partition(loop: System, Phi_z: np.ndarray,
              independent: Sequence[str] | None = None) -> Partition:
    """Choose ``z = (y, d)`` from the constraint Jacobian ``Phi_z`` (m×n) at a configuration.

    The independent rows of Φ (rank r by QR with column pivoting on Φ_zᵀ), then the dependent
    coordinates d by QR with column pivoting on those rows: the r columns taken first span
    Φ_z best, so ``Φ_d`` is as well-conditioned as a greedy choice makes it; the rest are the
    independent y, kept in the tree's order. A user's ``independent`` choice is checked
    (ModelError when its Φ_d is singular there, naming the coordinates)."""
    names = loop.coordinate_names
    n = len(names)
    _, R, piv = sla.qr(Phi_z.T, mode="economic", pivoting=True)
    diag = np.abs(np.diag(R)) if R.size else np.zeros(0)
    tol = _rank_tol(Phi_z) * 1e3
    r = int(np.sum(diag > tol))
    rows = tuple(sorted(int(i) for i in piv[:r]))
    A = Phi_z[list(rows), :]
    if independent is None:
        if r == 0:
            raise ModelError(f"{loop.name}: the constraint Jacobian Φ_z is zero at this "
                             "configuration")
        _, _, cp = sla.qr(A, mode="economic", pivoting=True)
        dep = tuple(sorted(int(j) for j in cp[:r]))
        ind = tuple(j for j in range(n) if j not in dep)
    else:
        ind = tuple(names.index(c) for c in independent)
        if len(ind) != n - r:
            raise ModelError(f"{loop.name}: {n} coordinates and {r} independent constraints "
                             f"leave {n - r} degrees of freedom, but {len(ind)} independent "
                             f"coordinates were chosen ({', '.join(independent)})")
        ind = tuple(sorted(ind))
        dep = tuple(j for j in range(n) if j not in ind)
    cond = _cond(A[:, list(dep)])
    if independent is not None and not cond < 1.0 / (EPS * max(1, r)):
        raise ModelError(f"{loop.name}: the independent coordinates {', '.join(independent)} "
                         f"do not determine the others here: Φ_d (dependent "
                         f"{', '.join(names[j] for j in dep)}) is singular (condition number "
                         f"{cond:.3g}); choose others or leave the choice to the partition")
    return Partition(ind, dep, rows, cond, tuple(names[j] for j in ind))


__all__ = ["Partition", "partition"]
