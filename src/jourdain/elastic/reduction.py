"""Boundary conditions and model reduction of finite-element models to :class:`ModalData`.

All three methods work on the DOFs left free by ``fixed`` (nodes, all their DOFs, or
``(node, name)`` pairs), and expand the basis with zeros at the fixed DOFs, so that the
invariants (:mod:`jourdain.elastic.modal`) count the whole body's mass:

- :func:`modal_truncation`: the ``n_modes`` lowest normal modes, mass-normalized
  (Φᵀ·M·Φ = E, Φᵀ·K·Φ = diag ω²).
- :func:`craig_bampton` (Craig & Bampton 1968): at the interface DOFs ``b`` the constraint modes
  Ψ = −K_ii⁻¹·K_ib (the static shapes of unit interface displacements, so any static load at the
  interface is reproduced exactly) and ``n_modes`` fixed-interface normal modes of (K_ii, M_ii);
  coordinates (u_b, η), basis [[E, 0], [Ψ, Φ_i]].
- :func:`free_modes`: ``n_modes`` elastic free-free modes and, for each DOF in ``correction``,
  a static correction mode (residual attachment mode with inertia relief, Craig & Chang 1977;
  Géradin & Rixen, *Mechanical Vibrations*, §6.4): the elastic flexibility's response to a unit
  load there, its rigid-body part removed by the projector P = E − M·Γ·Γᵀ (Γ the M-orthonormal
  rigid-body modes) and the kept modes' part Σ φ·φᵀ/ω² subtracted; the augmented basis is
  made M- and K-orthogonal. The elastic flexibility is applied by a solve with K on all DOFs
  but a statically determinate set (pivoted QR of Γᵀ picks it), whose result is then made
  M-orthogonal to Γ. For a body whose rigid modes are all held (``fixed``, or a regular K),
  the plain flexibility K⁻¹ is used.

Dense matrices are solved with LAPACK (``scipy.linalg.eigh``); ``scipy.sparse`` ones with a
sparse LU and shift-invert Lanczos (``scipy.sparse.linalg.eigsh``).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import replace
from typing import Any

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from jourdain.elastic.beam import FEModel
from jourdain.elastic.modal import ModalData, modal_data, rigid_fields
from jourdain.errors import ModelError

__all__ = ["dof_indices", "constrain", "normal_modes", "modal_truncation", "craig_bampton",
           "free_modes", "clamped_basis", "modal_damping"]

DofSpec = int | tuple[int, str]


def dof_indices(fe: FEModel, spec: Iterable[DofSpec]) -> list[int]:
    """Positions in ``fe``'s matrices of the DOFs named by ``spec``: a node index (all its DOFs)
    or a ``(node, name)`` pair; sorted, without repeats."""
    out: set[int] = set()
    for s in spec:
        if isinstance(s, tuple):
            out.add(fe.index(int(s[0]), str(s[1])))
        else:
            idx = [i for i, d in enumerate(fe.dofs) if d[0] == int(s)]
            if not idx:
                raise ModelError(f"{fe.name}: node {s} has no DOFs")
            out.update(idx)
    return sorted(out)


def _sub(a: Any, rows: Sequence[int], cols: Sequence[int]) -> Any:
    if a is None:
        return None
    if sp.issparse(a):
        return sp.csr_matrix(a)[rows][:, cols]
    return np.asarray(a)[np.ix_(rows, cols)]


def constrain(fe: FEModel, fixed: Iterable[DofSpec]) -> FEModel:
    """``fe`` with the DOFs ``fixed`` removed (held at zero)."""
    drop = set(dof_indices(fe, fixed))
    keep = [i for i in range(fe.n) if i not in drop]
    return FEModel(nodes=fe.nodes, dofs=tuple(fe.dofs[i] for i in keep),
                   M=_sub(fe.M, keep, keep), K=_sub(fe.K, keep, keep),
                   G=_sub(fe.G, keep, keep), D=_sub(fe.D, keep, keep), name=fe.name,
                   meta=dict(fe.meta))


def _shift(K: object, M: object) -> float:
    """A small negative shift for shift-invert that keeps K − σM regular with rigid modes."""
    dk = np.abs(K.diagonal()).mean()  # type: ignore[attr-defined]
    dm = np.abs(M.diagonal()).mean()  # type: ignore[attr-defined]
    return -1e-6 * float(dk / dm) if dm > 0 else -1.0


def normal_modes(K: object, M: object, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The ``n`` lowest eigenpairs of K·φ = λ·M·φ: λ ascending and Φ with Φᵀ·M·Φ = E, each
    column's sign fixed (first entry of largest magnitude positive). Repeated eigenvalues
    (a round section's two bending planes) have no unique modes: any M-orthonormal basis of
    their eigenspace comes back."""
    size = K.shape[0]  # type: ignore[attr-defined]
    if not 0 < n <= size:
        raise ModelError(f"asked for {n} modes of a model with {size} DOFs")
    if sp.issparse(K) or sp.issparse(M):
        Ks, Ms = sp.csc_matrix(K), sp.csc_matrix(M)
        if n < size - 1:
            lam, Phi = spla.eigsh(Ks, k=n, M=Ms, sigma=_shift(Ks, Ms), which="LM")
        else:
            lam, Phi = sla.eigh(Ks.toarray(), Ms.toarray())
    else:
        lam, Phi = sla.eigh(np.asarray(K), np.asarray(M), subset_by_index=[0, n - 1])
    order = np.argsort(lam)
    lam, Phi = lam[order], Phi[:, order]
    # M-normalize (eigsh's vectors are, up to rounding; make it exact), and fix the sign: the
    # first entry within 1e-6 of the largest magnitude positive (antisymmetric modes have two
    # of equal size), so that dense and sparse solvers, and repeated runs, give the same modes
    # (and the same C_t, C_r)
    norms = np.sqrt(np.einsum("ij,ij->j", Phi, np.asarray(M @ Phi)))
    mag = np.abs(Phi)
    first = np.argmax(mag >= (1 - 1e-6) * mag.max(axis=0), axis=0)
    big = Phi[first, np.arange(Phi.shape[1])]
    return lam, Phi * (np.sign(big) / norms)


def _expand(fe: FEModel, keep: Sequence[int], basis: np.ndarray) -> np.ndarray:
    out = np.zeros((fe.n, basis.shape[1]))
    out[list(keep)] = basis
    return out


def _free_part(fe: FEModel, fixed: Iterable[DofSpec]) -> tuple[FEModel, list[int]]:
    drop = set(dof_indices(fe, fixed))
    keep = [i for i in range(fe.n) if i not in drop]
    return constrain(fe, [fe.dofs[i] for i in sorted(drop)]), keep


def modal_truncation(fe: FEModel, n_modes: int, fixed: Iterable[DofSpec] = ()) -> ModalData:
    """The ``n_modes`` lowest normal modes of ``fe`` with ``fixed`` held (free-free with no
    ``fixed``: the rigid-body modes come first, at ω ≈ 0)."""
    sub, keep = _free_part(fe, fixed)
    _, Phi = normal_modes(sub.K, sub.M, n_modes)
    return modal_data(fe, _expand(fe, keep, Phi), "modal truncation", ("normal",) * n_modes)


def _solve(A: object, B: np.ndarray) -> np.ndarray:
    if sp.issparse(A):
        return np.asarray(spla.splu(sp.csc_matrix(A)).solve(np.asarray(B, dtype=float)))
    return np.asarray(sla.solve(np.asarray(A), B, assume_a="sym"))


def craig_bampton(fe: FEModel, interface: Iterable[DofSpec], n_modes: int,
                  fixed: Iterable[DofSpec] = ()) -> ModalData:
    """Craig–Bampton reduction: constraint modes at the ``interface`` DOFs and ``n_modes``
    fixed-interface normal modes (module docstring); ``fixed`` DOFs held at zero."""
    sub, keep = _free_part(fe, fixed)
    b = dof_indices(sub, interface)
    if not b:
        raise ModelError(f"{fe.name}: Craig–Bampton needs at least one interface DOF")
    i = [k for k in range(sub.n) if k not in set(b)]
    if n_modes > len(i):
        raise ModelError(f"{fe.name}: {n_modes} fixed-interface modes asked, {len(i)} inner DOFs")
    K_ii, K_ib = _sub(sub.K, i, i), _sub(sub.K, i, b)
    K_ib = K_ib.toarray() if sp.issparse(K_ib) else np.asarray(K_ib)
    Psi = -_solve(K_ii, np.asarray(K_ib))
    basis = np.zeros((sub.n, len(b) + n_modes))
    basis[b, : len(b)] = np.eye(len(b))
    basis[i, : len(b)] = Psi
    if n_modes:
        _, Phi_i = normal_modes(K_ii, _sub(sub.M, i, i), n_modes)
        basis[i, len(b):] = Phi_i
    kinds = ("constraint",) * len(b) + ("normal",) * n_modes
    return modal_data(fe, _expand(fe, keep, basis), "Craig-Bampton", kinds)


def _rigid_modes(fe: FEModel) -> np.ndarray:
    """M-orthonormal rigid-body modes of ``fe``: the combinations of the six fields of
    :func:`rigid_fields` that K does not resist (K·Γ·v = 0: supports may hold some, e.g. a
    pin leaves the rotations about itself), made M-orthonormal."""
    Gt, Gr = rigid_fields(fe)
    Gam = np.column_stack([Gt, Gr])
    # M-orthonormalize first (rank-revealing: a model without rotation DOFs on a line of
    # nodes has fewer than six independent fields)
    Mg = Gam.T @ np.asarray(fe.M @ Gam)
    w, V = np.linalg.eigh(0.5 * (Mg + Mg.T))
    ok = w > 1e-12 * w.max()
    Gam = Gam @ (V[:, ok] / np.sqrt(w[ok]))
    # the null space of K on their span: singular values of K·Γ below 1e-8 of ‖K‖·‖Γ‖
    _, sv, Vt = np.linalg.svd(np.asarray(fe.K @ Gam), full_matrices=True)
    k_norm = float(np.abs(fe.K).max())
    rank = int(np.count_nonzero(sv > 1e-8 * k_norm * float(np.abs(Gam).max()) * fe.n))
    Gam = Gam @ Vt[rank:].T
    return Gam  # still M-orthonormal: Vt is orthogonal


def free_modes(fe: FEModel, n_modes: int, correction: Iterable[DofSpec] = (),
               fixed: Iterable[DofSpec] = ()) -> ModalData:
    """``n_modes`` elastic normal modes (the rigid-body modes skipped) and one static
    correction mode per DOF in ``correction`` (module docstring)."""
    sub, keep = _free_part(fe, fixed)
    Gam = _rigid_modes(sub)
    n_rigid = Gam.shape[1]
    lam, Phi = normal_modes(sub.K, sub.M, n_modes + n_rigid)
    lam, Phi = lam[n_rigid:], Phi[:, n_rigid:]
    cols = dof_indices(sub, correction)
    kinds = ["normal"] * n_modes
    basis = Phi
    if cols:
        F = np.zeros((sub.n, len(cols)))
        F[cols, range(len(cols))] = 1.0
        if n_rigid:
            MG = np.asarray(sub.M @ Gam)
            F = F - MG @ (Gam.T @ F)  # inertia relief: Pᵀ·f has no rigid-body part
            # K·x = Pᵀ·f is consistent; one solution holds a statically determinate set of
            # DOFs (as many as rigid modes, chosen by pivoted QR of Γᵀ) at zero, and the
            # elastic one is that solution with its rigid-body part removed
            _, _, piv = sla.qr(Gam.T, mode="economic", pivoting=True)
            held = set(int(i) for i in piv[:n_rigid])
            rest = [i for i in range(sub.n) if i not in held]
            X = np.zeros_like(F)
            X[rest] = _solve(_sub(sub.K, rest, rest), F[rest])
            X = X - Gam @ (Gam.T @ np.asarray(sub.M @ X))
        else:
            X = _solve(sub.K, F)
        X = X - Phi @ ((Phi.T @ F) / lam[:, None])  # the kept modes' share removed
        basis = np.column_stack([Phi, X])
        # K- and M-orthogonal basis: the reduced eigenvectors (Ritz vectors)
        Mr = basis.T @ np.asarray(sub.M @ basis)
        Kr = basis.T @ np.asarray(sub.K @ basis)
        _, V = sla.eigh(0.5 * (Kr + Kr.T), 0.5 * (Mr + Mr.T))
        basis = basis @ V
        kinds = ["ritz"] * basis.shape[1]  # modes and corrections mixed by the Ritz step
    return modal_data(fe, _expand(fe, keep, basis), "free modes + static correction"
                      if cols else "free modes", tuple(kinds))


def clamped_basis(name: str, fe: FEModel, n_modes: int, clamped: Sequence[int],
                  fixed: Sequence[DofSpec], reduction: str = "normal",
                  interface: Sequence[int] = ()) -> ModalData:
    """The basis of an elastic body whose reference frame holds the ``clamped`` nodes, the
    DOFs ``fixed`` (those nodes' among them) held: its ``n_modes`` lowest normal modes
    (``reduction="normal"``), or Craig–Bampton's constraint modes at the DOFs of the
    ``interface`` nodes that are not fixed, with ``n_modes`` fixed-interface modes
    (``"craig_bampton"``: a static load at an interface node is then represented exactly).
    ModelError names the body."""
    if not clamped:
        raise ModelError(f'elastic body "{name}": give the clamped nodes (the reference frame '
                         "holds them); free-free bodies are not built here")
    if reduction == "normal":
        modal = modal_truncation(fe, n_modes, fixed=fixed)
    elif reduction == "craig_bampton":
        held, nodes = set(dof_indices(fe, fixed)), set(interface)
        dofs = [d for i, d in enumerate(fe.dofs) if d[0] in nodes and i not in held]
        if not dofs:
            raise ModelError(f'elastic body "{name}": Craig–Bampton needs interface nodes '
                             "(attach) with DOFs that are not held")
        modal = craig_bampton(fe, dofs, n_modes, fixed=fixed)
    else:
        raise ModelError(f'elastic body "{name}": reduction must be "normal" or '
                         f'"craig_bampton", got {reduction!r}')
    return modal


def modal_damping(modal: ModalData, zeta: float, M_e: np.ndarray | None = None) -> ModalData:
    """``modal`` with the damping ``D_e`` that gives every mode of ``(K_e, M_e)`` the damping
    ratio ``zeta``: ``D_e = M_e·V·diag(2ζω)·Vᵀ·M_e`` with ``K_e·V = M_e·V·diag(ω²)``,
    ``Vᵀ·M_e·V = E`` (``2ζ·diag(ω)`` for mass-normal modes). ``M_e``: the elastic mass the
    body has (lumped masses: not the FE's; default ``modal.M_e``)."""
    if not (np.isfinite(zeta) and zeta >= 0):
        raise ModelError(f"damping_ratio must be a finite number ≥ 0, got {zeta!r}")
    Me = modal.M_e if M_e is None else np.asarray(M_e, dtype=float)
    Ke = 0.5 * (modal.K_e + modal.K_e.T)
    lam, V = sla.eigh(Ke, 0.5 * (Me + Me.T))
    w = np.sqrt(np.clip(lam, 0.0, None))
    MV = Me @ V
    return replace(modal, D_e=MV @ np.diag(2.0 * zeta * w) @ MV.T)
