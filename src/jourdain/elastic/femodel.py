"""Import of any finite-element model's mass and stiffness matrices.

:func:`fe_model` takes M and K (NumPy arrays, ``scipy.sparse`` matrices, or paths of
MatrixMarket files read with ``scipy.io.mmread``), the node coordinates (n, 3) in the body frame
and the DOF map: for each row of the matrices the pair ``(node, name)``, name one of
:data:`jourdain.elastic.beam.DOF_NAMES` (``ux uy uz rx ry rz``). Shorthand: ``dofs_per_node`` =
``("ux", "uy", "uz")`` (solid elements) numbers the rows node by node.

Checks, each an :class:`~jourdain.errors.ModelError` that names the matrix and what is wrong:
square and of the DOF map's size; finite (no NaN or inf, with the first bad entry); symmetric
(max |A − Aᵀ| ≤ 1e-10·max |A|, with the worst entry); M positive definite and K positive
semi-definite (the lowest eigenvalue of M > 0, of K ≥ −1e-8·max|K|: dense eigenvalues up to
3000 DOFs; beyond, the signs of the pivots of a symmetric sparse factorization of M and of
K + 1e-8·max|K|·E, Sylvester's law of inertia); the DOF map's names, node indices and no DOF
listed twice.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any

import numpy as np
import scipy.io
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from jourdain.elastic.beam import DOF_NAMES, FEModel
from jourdain.errors import ModelError

__all__ = ["fe_model", "read_matrix", "check_matrix"]

SYM_RTOL = 1e-10
PSD_RTOL = 1e-8
DENSE_LIMIT = 3000


def read_matrix(source: Any, what: str) -> Any:
    """``source`` as a float matrix: an array, a sparse matrix (CSR) or a MatrixMarket file."""
    if isinstance(source, (str, os.PathLike)):
        try:
            a = scipy.io.mmread(os.fspath(source))
        except (OSError, ValueError) as exc:
            raise ModelError(f"{what}: cannot read MatrixMarket file {os.fspath(source)!r}: "
                             f"{exc}") from exc
        return sp.csr_matrix(a, dtype=float) if sp.issparse(a) else np.asarray(a, dtype=float)
    if sp.issparse(source):
        return sp.csr_matrix(source, dtype=float)
    try:
        return np.asarray(source, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ModelError(f"{what}: not a numeric matrix ({exc})") from exc


def check_matrix(a: Any, what: str, n: int, definite: bool) -> None:
    """Raise :class:`ModelError` unless ``a`` is n × n, finite, symmetric and positive definite
    (``definite``) or semi-definite."""
    if a.ndim != 2 or a.shape != (n, n):
        raise ModelError(f"{what}: shape {a.shape}, expected ({n}, {n}) from the DOF map")
    data = a.data if sp.issparse(a) else a
    if not np.all(np.isfinite(data)):
        bad = np.argwhere(~np.isfinite(a.toarray() if sp.issparse(a) else a))[0]
        raise ModelError(f"{what}: entry ({bad[0]}, {bad[1]}) is not finite")
    scale = float(np.abs(data).max()) if data.size else 0.0
    if scale == 0.0:
        raise ModelError(f"{what}: all entries are zero")
    diff = a - a.T
    asym = abs(diff).max() if sp.issparse(diff) else float(np.abs(diff).max())
    if asym > SYM_RTOL * scale:
        d = diff.toarray() if sp.issparse(diff) else diff
        i, j = np.unravel_index(int(np.argmax(np.abs(d))), d.shape)
        raise ModelError(f"{what}: not symmetric: |A[{i},{j}] − A[{j},{i}]| = {asym:.3g} "
                         f"(> {SYM_RTOL:g}·max|A| = {SYM_RTOL * scale:.3g})")
    shift = 0.0 if definite else PSD_RTOL * scale
    if a.shape[0] <= DENSE_LIMIT:
        dense = a.toarray() if sp.issparse(a) else a
        lowest = float(sla.eigvalsh(0.5 * (dense + dense.T), subset_by_index=[0, 0])[0])
        bad = not lowest > 0 if definite else lowest < -shift
        detail = f"lowest eigenvalue {lowest:.3g}"
    else:
        negative = _negative_pivots(a, shift)
        bad, detail = negative > 0, (f"{negative} pivot(s) ≤ 0 in the symmetric factorization "
                                     f"of A + {shift:.3g}·E (Sylvester's inertia)")
    if bad:
        kind = "positive definite" if definite else "positive semi-definite"
        raise ModelError(f"{what}: not {kind} ({detail}, max|A| = {scale:.3g})")


def _negative_pivots(a: Any, shift: float) -> int:
    """How many eigenvalues of A + shift·E are ≤ 0: the signs of the pivots of a sparse LU with
    the same permutation of rows and columns (an LDLᵀ: Sylvester's law of inertia). Where
    SuperLU had to pivot off the diagonal, the lowest eigenvalue from shift-invert Lanczos
    about −shift instead."""
    A = sp.csc_matrix(a + shift * sp.identity(a.shape[0], format="csc"))
    try:
        lu = spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                       options={"SymmetricMode": True})
    except RuntimeError:  # exactly singular: a zero pivot
        return 1
    if np.array_equal(lu.perm_r, lu.perm_c):
        return int(np.count_nonzero(lu.U.diagonal() <= 0))
    lam = spla.eigsh(A, k=1, sigma=-max(shift, 1e-300), which="LM", tol=1e-6,
                     return_eigenvectors=False)
    return int(lam[0] <= 0)


def _dof_map(nodes: np.ndarray, dofs: Sequence[tuple[int, str]] | None,
             dofs_per_node: Sequence[str] | None, n: int) -> tuple[tuple[int, str], ...]:
    if (dofs is None) == (dofs_per_node is None):
        raise ModelError("fe_model: give exactly one of dofs and dofs_per_node")
    if dofs is None:
        per = tuple(dofs_per_node or ())
        dofs = [(i, name) for i in range(len(nodes)) for name in per]
    out = tuple((int(k), str(name)) for k, name in dofs)
    for row, (k, name) in enumerate(out):
        if name not in DOF_NAMES:
            raise ModelError(f"DOF map row {row}: name {name!r} is not one of {DOF_NAMES}")
        if not 0 <= k < len(nodes):
            raise ModelError(f"DOF map row {row}: node {k} is not among the {len(nodes)} nodes")
    first: dict[tuple[int, str], int] = {}
    for row, d in enumerate(out):
        if d in first:
            raise ModelError(f"DOF map rows {first[d]} and {row}: {d} is listed twice")
        first[d] = row
    if len(out) != n:
        raise ModelError(f"DOF map has {len(out)} rows, the matrices {n}")
    return out


def fe_model(M: Any, K: Any, nodes: Any, dofs: Sequence[tuple[int, str]] | None = None,
             dofs_per_node: Sequence[str] | None = None, D: Any = None,
             name: str = "fe model") -> FEModel:
    """A checked :class:`FEModel` from M, K (and damping D) and the node coordinates (module
    docstring). Dense inputs stay dense, sparse ones stay CSR."""
    Mm, Km = read_matrix(M, f"{name}: M"), read_matrix(K, f"{name}: K")
    pts = np.asarray(nodes, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 3 or not np.all(np.isfinite(pts)):
        raise ModelError(f"{name}: nodes must be a finite (n, 3) array, got shape {pts.shape}")
    n = Mm.shape[0] if Mm.ndim == 2 else -1
    check_matrix(Mm, f"{name}: M", n, definite=True)
    check_matrix(Km, f"{name}: K", n, definite=False)
    Dm = None
    if D is not None:
        Dm = read_matrix(D, f"{name}: D")
        check_matrix(Dm, f"{name}: D", n, definite=False)
    dof_map = _dof_map(pts, dofs, dofs_per_node, n)
    return FEModel(nodes=pts, dofs=dof_map, M=Mm, K=Km, D=Dm, name=name)
