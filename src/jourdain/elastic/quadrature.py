"""Where an elastic body's mass sits: lumped at the nodes (HRZ), or, for beams, at the elements'
Gauss points, which carry the consistent mass exactly.

The consistent mass matrix of a beam element is an integral over its axis,

    M_el = ∫ ρA·N_tᵀN_t + N_rᵀ·diag(ρI_p, ρI_y, ρI_z)·N_r dx,

of the section's displacement ``u = N_t·d`` and rotation ``θ = N_r·d``
(:func:`jourdain.elastic.beam.section_fields`). Its integrand is a polynomial of degree ≤ 6 in
x, so the 4-point Gauss–Legendre rule evaluates it exactly. Put a body at each Gauss point ``g``
of each element, with the mass ``w_g·ρA`` and the section's inertia
``w_g·diag(ρI_p, ρI_y, ρI_z)`` (``w_g`` the weight times the element's length), moved by the
interpolated field of the modes, ``c_g + Φ_t,g·q_e`` and turned by ``Φ_r,g·q_e``: the kinetic
energy of these bodies on the floating frame is the quadrature of the continuum's, and that
quadrature is exact. So the projected ``M = J̄ᵀ·M̄·J̄`` of the body holds the invariants of the
consistent FE mass — m, m·c, J, C_t, C_r, M_e = Φᵀ·M·Φ — exactly, and, since the same rule
integrates the body's kinetic energy at any deflection, also their terms of first and second
order in q_e (the SID's C_4, G_r, G_e, O_e, which the invariant form truncates); the spin of
the sections gives the FE gyroscopic matrix ``Φᵀ·G·Φ`` (Nelson 1980). Cost: four bodies per
element instead of one per node (:mod:`jourdain.elastic.body` lumps the mass at the nodes).

The foreshortening of a Gauss point (geometric stiffening) is the integral of the squared
slopes from the clamped node to it, as in :mod:`jourdain.elastic.stiffening`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from jourdain.elastic.beam import Beam, FEModel, frame_of_axis, section_fields
from jourdain.elastic.modal import ModalData
from jourdain.elastic.stiffening import foreshortening_at
from jourdain.errors import ModelError

__all__ = ["MassPoints", "gauss_points", "lumped_masses", "mass_kind"]

_GX, _GW = np.polynomial.legendre.leggauss(4)
_XI = 0.5 * (_GX + 1.0)
_WXI = 0.5 * _GW


def lumped_masses(fe: FEModel) -> np.ndarray:
    """The nodes' masses by HRZ lumping (Hinton, Rock & Zienkiewicz 1976): each node gets the
    share of its translational diagonal entries of M in the sum of all of them, times the
    body's mass (Γ_tᵀ·M·Γ_t), so the lumped body keeps its mass exactly."""
    diag = np.asarray(fe.M.diagonal() if hasattr(fe.M, "diagonal") else np.diag(fe.M))
    per_node = np.zeros(len(fe.nodes))
    total = np.zeros(3)
    counts = np.zeros(3)
    for i, (node, name) in enumerate(fe.dofs):
        if name in ("ux", "uy", "uz"):
            per_node[node] += diag[i]
            total[("ux", "uy", "uz").index(name)] += diag[i]
            counts[("ux", "uy", "uz").index(name)] += 1
    ones = np.zeros(fe.n)
    mass = []
    for k, name in enumerate(("ux", "uy", "uz")):
        if counts[k]:
            ones[:] = [1.0 if d[1] == name else 0.0 for d in fe.dofs]
            mass.append(float(ones @ np.asarray(fe.M @ ones)))
    m = float(np.mean(mass)) if mass else 0.0
    s = per_node.sum()
    if not s > 0:
        raise ModelError(f"{fe.name}: the mass matrix has no translational mass to lump")
    return per_node * (m / s)


@dataclass(frozen=True, eq=False)
class MassPoints:
    """Bodies at points of an elastic body other than its nodes: positions ``c`` (P, 3) in the
    body frame, the modes' translations ``Phi_t`` and rotations ``Phi_r`` there (P, 3, n_q),
    masses ``mass`` (P,), inertia tensors ``inertia`` (P, 3, 3) about the point, and the
    second-order field ``Psi`` (P, 3, n_q, n_q) or None."""

    c: np.ndarray
    Phi_t: np.ndarray
    Phi_r: np.ndarray
    mass: np.ndarray
    inertia: np.ndarray
    Psi: np.ndarray | None = None

    def check(self, where: str, n_q: int) -> None:
        """ModelError naming ``where`` unless the arrays fit together and are finite."""
        P = len(np.asarray(self.c))
        shapes = {"c": (P, 3), "Phi_t": (P, 3, n_q), "Phi_r": (P, 3, n_q), "mass": (P,),
                  "inertia": (P, 3, 3)}
        if self.Psi is not None:
            shapes["Psi"] = (P, 3, n_q, n_q)
        for name, shape in shapes.items():
            a = np.asarray(getattr(self, name), dtype=float)
            if a.shape != shape or not np.all(np.isfinite(a)):
                raise ModelError(f"{where}: mass points' {name} must be finite, of shape "
                                 f"{shape}, got {a.shape}")
        if np.any(np.asarray(self.mass) < 0):
            raise ModelError(f"{where}: mass points' masses must be ≥ 0")

    def arrays(self) -> tuple[np.ndarray, ...]:
        empty = np.zeros(0)
        return (self.c, self.Phi_t, self.Phi_r, self.mass, self.inertia,
                self.Psi if self.Psi is not None else empty)


def gauss_points(beam: Beam, modal: ModalData, stiffening_from: int | None = None) -> MassPoints:
    """The beam's distributed mass at the 4 Gauss points of each element (module docstring),
    for the modes ``modal`` of :func:`jourdain.elastic.beam.assemble`'s nodes; with the
    foreshortening from node ``stiffening_from`` (the clamped one) when it is given."""
    n_el = int(beam.n_elements)
    nodes = np.asarray(modal.nodes, dtype=float)
    if len(nodes) != n_el + 1:
        raise ModelError(f"gauss_points: {len(nodes)} nodes for a beam of {n_el} elements")
    L = beam.length / n_el
    R = frame_of_axis(beam.axis, beam.up)
    T = np.kron(np.eye(4), R)  # body ← element, for an element's 12 DOFs
    n_q = modal.n_q
    dens = beam.rho * np.diag([beam.polar, beam.I_y if beam.rotary_inertia else 0.0,
                               beam.I_z if beam.rotary_inertia else 0.0])
    inertia_per_length = R @ dens @ R.T
    inertia_per_length = 0.5 * (inertia_per_length + inertia_per_length.T)  # exactly symmetric
    c, Pt, Pr, mass, inertia, where = [], [], [], [], [], []
    for e in range(n_el):
        d_body = np.concatenate([modal.Phi_t[e], modal.Phi_r[e],
                                 modal.Phi_t[e + 1], modal.Phi_r[e + 1]])  # 12 × n_q
        d_el = T.T @ d_body
        for xi, w in zip(_XI, _WXI, strict=True):
            Nt, Nr = section_fields(beam, L, float(xi))
            c.append(nodes[e] + xi * L * R[:, 0])
            Pt.append(R @ Nt @ d_el)
            Pr.append(R @ Nr @ d_el)
            mass.append(w * L * beam.rho * beam.A)
            inertia.append(w * L * inertia_per_length)
            where.append((e, float(xi)))
    Psi = None
    if stiffening_from is not None:
        Psi = foreshortening_at(nodes, R, modal.Phi_t, modal.Phi_r, stiffening_from, where)
    shape = (n_el * 4, 3, n_q)
    return MassPoints(np.array(c), np.array(Pt).reshape(shape), np.array(Pr).reshape(shape),
                      np.array(mass), np.array(inertia), Psi)


def mass_kind(name: str, mass: object) -> bool:
    """True for ``"consistent"``, False for ``"lumped"``; ModelError otherwise."""
    if mass not in ("lumped", "consistent"):
        raise ModelError(f'elastic body "{name}": mass must be "lumped" or "consistent", '
                         f"got {mass!r}")
    return mass == "consistent"
