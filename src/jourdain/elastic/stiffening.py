"""Geometric stiffening of a beam body: the second-order (foreshortening) field of its modes.

A beam that bends by ``v(s)``, ``w(s)`` (the transverse displacements in its element frame,
``s`` along the axis) draws its points towards the reference section ``s_0`` by

    Δs(s) = −½ ∫_{s_0}^{s} (v'² + w'²) dσ           (s > s_0; mirrored for s < s_0)

when its axis does not stretch (Kane, Ryan & Banerjee 1987; Schwertassek & Wallrapp 1999, §6.5
on the geometric stiffness k_σ). With the modal fields ``v = Σ v_k q_k`` this is a quadratic
form ``Δs = ½ qᵀ·P(s)·q`` with ``P_jk(s) = −∫ (v_j' v_k' + w_j' w_k') dσ``. Kept in the node
positions, it lets the kinetic energy carry the work of the inertia forces along the axis on
the shortening: a beam spinning at Ω gains the stiffness ∫ ½ρA·Ω²·(L² − s²)·v'² ds (the
centrifugal stiffening; without it the linear modal beam softens and, spun up past its first
bending frequency, diverges). It is the same term as the SID's k_σ for the centrifugal,
Euler and translational load cases, all at once and consistently with the mass matrix.

The slopes come from the nodal translations and rotations of the modes by the Hermite
(Euler–Bernoulli) interpolation of each element, integrated by 3-point Gauss–Legendre
quadrature, exact for the quartic integrand.
"""

from __future__ import annotations

import numpy as np

from jourdain.errors import ModelError

__all__ = ["foreshortening", "foreshortening_at"]

_GX, _GW = np.polynomial.legendre.leggauss(3)
_XI = 0.5 * (_GX + 1.0)
_WXI = 0.5 * _GW


def _slope_rows(xi: float, L: float) -> np.ndarray:
    """d/ds of the Hermite interpolation of (v1, θ1, v2, θ2) at ξ, an element of length L."""
    return np.array([(-6 * xi + 6 * xi * xi) / L, 1 - 4 * xi + 3 * xi * xi,
                     (6 * xi - 6 * xi * xi) / L, -2 * xi + 3 * xi * xi])


def foreshortening(nodes: np.ndarray, R: np.ndarray, Phi_t: np.ndarray, Phi_r: np.ndarray,
                   reference: int = 0) -> np.ndarray:
    """Ψ (n_nodes, 3, n_q, n_q) with the node displacement ``½·qᵀ·Ψ[n]·q`` (body frame) of the
    module docstring, for a straight beam whose nodes are in order along its axis ``R[:, 0]``
    (``R`` from :func:`jourdain.elastic.beam.frame_of_axis`); ``Phi_t``, ``Phi_r`` (n, 3, n_q)
    the modes' nodal translations and rotations in the body frame; ``reference`` the node that
    keeps its axial place (the clamped one)."""
    nodes = np.asarray(nodes, dtype=float)
    return foreshortening_at(nodes, R, Phi_t, Phi_r, reference,
                             [(min(k, len(nodes) - 2), 0.0 if k < len(nodes) - 1 else 1.0)
                              for k in range(len(nodes))] if len(nodes) > 1 else [])


def foreshortening_at(nodes: np.ndarray, R: np.ndarray, Phi_t: np.ndarray, Phi_r: np.ndarray,
                      reference: int, points: list[tuple[int, float]]) -> np.ndarray:
    """Ψ (P, 3, n_q, n_q) as :func:`foreshortening`, at the points ``(e, ξ)`` of the beam:
    element ``e`` (between nodes e and e + 1) at ``ξ`` ∈ [0, 1] of its length."""
    nodes = np.asarray(nodes, dtype=float)
    n, nq = len(nodes), Phi_t.shape[2]
    if Phi_r.shape != Phi_t.shape or Phi_t.shape[:2] != (n, 3):
        raise ModelError(f"foreshortening: mode arrays of shapes {Phi_t.shape}, {Phi_r.shape} "
                         f"for {n} nodes")
    ex = R[:, 0]
    s = (nodes - nodes[0]) @ ex
    if n > 1 and not np.all(np.diff(s) > 0):
        raise ModelError("foreshortening: the nodes are not in order along the beam's axis")
    # the element frame's components: v along y with slope θ_z, w along z with slope −θ_y
    loc_t = np.einsum("ji,njk->nik", R, Phi_t)
    loc_r = np.einsum("ji,njk->nik", R, Phi_r)

    def integral(e: int, a: float, b: float) -> np.ndarray:
        """∫ (v'v'ᵀ + w'w'ᵀ) ds over ξ ∈ [a, b] of element e (3-point Gauss, exact)."""
        L = s[e + 1] - s[e]
        v = np.stack([loc_t[e, 1], loc_r[e, 2], loc_t[e + 1, 1], loc_r[e + 1, 2]])
        w = np.stack([loc_t[e, 2], -loc_r[e, 1], loc_t[e + 1, 2], -loc_r[e + 1, 1]])
        out = np.zeros((nq, nq))
        for xi, wt in zip(a + (b - a) * _XI, (b - a) * _WXI, strict=True):
            d = _slope_rows(float(xi), L)
            dv, dw = d @ v, d @ w
            out += wt * L * (np.outer(dv, dv) + np.outer(dw, dw))
        return out

    whole = [integral(e, 0.0, 1.0) for e in range(n - 1)]
    Psi = np.zeros((len(points), 3, nq, nq))
    for k, (e, xi) in enumerate(points):
        if e >= reference:  # from the reference node forward to the point
            P = -(sum(whole[reference:e], np.zeros((nq, nq))) + integral(e, 0.0, xi))
            sign = 1.0
        else:  # back from the reference node to the point
            P = -(sum(whole[e + 1:reference], np.zeros((nq, nq))) + integral(e, xi, 1.0))
            sign = -1.0
        Psi[k] = sign * ex[:, None, None] * P[None, :, :]
    return Psi
