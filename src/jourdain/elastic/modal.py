"""Modal data of an elastic body and the invariants of the floating frame of reference.

A material point of the body is at ``R = r + S·(c + u(c, t))`` with the elastic displacement
``u = Φ_t(c)·q_e`` (and section rotations ``θ = Φ_r(c)·q_e`` for beams and shells). From the
finite-element mass matrix ``M`` of the *unconstrained* body (every DOF, constrained ones
included: their mass moves with the frame) and the basis ``Φ`` (one column per elastic
coordinate, zero at constrained DOFs), with the rigid-body fields of the frame ``Γ_t`` (unit
translations along x, y, z: u = e_k, θ = 0) and ``Γ_r`` (unit rotations about x, y, z through the
frame's origin: u = e_k × c, θ = e_k), the invariants in the body frame are

    m·E    = Γ_tᵀ·M·Γ_t          mass (the mean of the diagonal over the directions present)
    m·c̃ᵀ   = Γ_tᵀ·M·Γ_r          first moment (m·c = (x, y, z) read from the skew matrix)
    J      = Γ_rᵀ·M·Γ_r          inertia tensor about the frame's origin, ∫ρ(c̃ᵀc̃) dV
    C_t    = Γ_tᵀ·M·Φ            ∫ρ·Φ_t dV                       (3 × n_q)
    C_r    = Γ_rᵀ·M·Φ            ∫ρ·c̃·Φ_t dV (+ the sections' rotary inertia · Φ_r)
    M_e    = Φᵀ·M·Φ,  K_e = Φᵀ·K·Φ,  D_e = Φᵀ·D·Φ,  G_e(Ω) = Φᵀ·G·Φ (spin)

(Wallrapp 1994, "Standardization of flexible body modeling in multibody system codes, Part I",
Mech. Struct. Mach. 22(3); Schwertassek & Wallrapp 1999, *Dynamik flexibler Mehrkörpersysteme*,
§6: the names m, mc, J, C_t (Ct), C_r (Cr), M_e (Me), K_e (Ke), D_e (De) of the SID.)

Exactness. With a consistent mass matrix whose shape functions contain the rigid-body motions
(the beam elements of :mod:`jourdain.elastic.beam`: linear axial and torsion, Hermite/Timoshenko
bending), every product above is the exact integral of the discretized field: M is the exact
∫ρ·(uᵀu + θᵀ·I_section·θ) of the element fields, and Γ_t, Γ_r are exactly representable. So m,
m·c, J, C_t, C_r, M_e, K_e are exact for the discretized body (J includes the sections' own
rotary inertia when the mass has it; without rotary inertia the beam's J misses the section
terms ρ·I_y·L, ρ·I_z·L, ρ·I_p·L). With a lumped (diagonal) mass they are the lumped sums
Σ m_i·(...), a quadrature of the integrals. Not computed here (they need the 3-D product of
shape functions, not M alone): the first-order terms in q_e of J (C_4), the G_r, G_e, O_e of the
SID's velocity-dependent terms and the geometric stiffness k_σ; jourdain's multibody
integration will add them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from jourdain.elastic.beam import DOF_NAMES, FEModel
from jourdain.errors import ModelError

__all__ = ["ModalData", "rigid_fields", "modal_data", "skew"]


def skew(v: np.ndarray) -> np.ndarray:
    """ṽ with ṽ·w = v × w."""
    x, y, z = v
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


@dataclass(frozen=True)
class ModalData:
    """An elastic body's reduced (modal) description in its body frame.

    Fields: ``nodes`` (n, 3) node coordinates c; ``dofs`` the FE DOF labels (node, name);
    ``Phi`` (n_dofs, n_q) the basis at every DOF (zeros at constrained DOFs); ``Phi_t``,
    ``Phi_r`` (n, 3, n_q) its translations and rotations per node (zeros where a node has no
    such DOF); ``M_e``, ``K_e``, ``D_e``, ``G_e`` (n_q, n_q) modal mass, stiffness, damping and
    gyroscopic matrix per unit spin; ``omega`` (rad/s) the undamped natural frequencies of the
    reduced model, ascending; ``mass``, ``mc`` (3,), ``J`` (3, 3) about the frame's origin,
    ``C_t``, ``C_r`` (3, n_q): the invariants of the module docstring; ``method`` and ``kinds``
    (one word per coordinate: 'normal', 'constraint', 'static', ...) say how the basis was made.
    """

    nodes: np.ndarray
    dofs: tuple[tuple[int, str], ...]
    Phi: np.ndarray
    M_e: np.ndarray
    K_e: np.ndarray
    D_e: np.ndarray
    G_e: np.ndarray
    omega: np.ndarray
    mass: float
    mc: np.ndarray
    J: np.ndarray
    C_t: np.ndarray
    C_r: np.ndarray
    method: str = ""
    kinds: tuple[str, ...] = ()
    meta: dict[str, float] = field(default_factory=dict)

    @property
    def n_q(self) -> int:
        return int(self.Phi.shape[1])

    @property
    def center_of_mass(self) -> np.ndarray:
        return self.mc / self.mass

    @property
    def Phi_t(self) -> np.ndarray:
        return self._per_node(("ux", "uy", "uz"))

    @property
    def Phi_r(self) -> np.ndarray:
        return self._per_node(("rx", "ry", "rz"))

    @property
    def frequencies_hz(self) -> np.ndarray:
        return self.omega / (2.0 * np.pi)

    def _per_node(self, names: tuple[str, str, str]) -> np.ndarray:
        out = np.zeros((len(self.nodes), 3, self.n_q))
        for i, (node, name) in enumerate(self.dofs):
            if name in names:
                out[node, names.index(name)] = self.Phi[i]
        return out


def rigid_fields(fe: FEModel) -> tuple[np.ndarray, np.ndarray]:
    """Γ_t, Γ_r (n_dofs × 3 each): the DOF values of unit translations along, and unit rotations
    about, the body axes through the origin (u = e_k × c, θ = e_k)."""
    Gt = np.zeros((fe.n, 3))
    Gr = np.zeros((fe.n, 3))
    for i, (node, name) in enumerate(fe.dofs):
        k = DOF_NAMES.index(name)
        if k < 3:
            Gt[i, k] = 1.0
            # (e_j × c)_k for the rotation about e_j
            Gr[i] = skew(fe.nodes[node])[k] * -1.0
        else:
            Gr[i, k - 3] = 1.0
    return Gt, Gr


def _sym(a: np.ndarray) -> np.ndarray:
    return 0.5 * (a + a.T)


def modal_data(fe: FEModel, Phi: np.ndarray, method: str, kinds: tuple[str, ...]) -> ModalData:
    """The :class:`ModalData` of basis ``Phi`` (n_dofs × n_q, over all of ``fe``'s DOFs):
    projections and invariants as in the module docstring."""
    Phi = np.asarray(Phi, dtype=float)
    if Phi.ndim != 2 or Phi.shape[0] != fe.n:
        raise ModelError(f"{fe.name}: basis of shape {Phi.shape}, expected ({fe.n}, n_q)")
    M, K, D, G = (fe.M, fe.K, fe.D, fe.G)
    MPhi = np.asarray(M @ Phi)
    M_e = _sym(Phi.T @ MPhi)
    K_e = _sym(Phi.T @ np.asarray(K @ Phi))
    D_e = _sym(Phi.T @ np.asarray(D @ Phi)) if D is not None else np.zeros_like(M_e)
    G_e = Phi.T @ np.asarray(G @ Phi) if G is not None else np.zeros_like(M_e)
    G_e = 0.5 * (G_e - G_e.T)
    Gt, Gr = rigid_fields(fe)
    MGt = np.asarray(M @ Gt)
    MGr = np.asarray(M @ Gr)
    mE = Gt.T @ MGt
    # the directions the model has translations in (all three for beams and solids)
    present = np.abs(Gt).sum(axis=0) > 0
    mass = float(np.mean(np.diag(mE)[present])) if present.any() else 0.0
    # Γ_tᵀ·M·Γ_r = m·c̃ᵀ = −m·c̃
    S = -(Gt.T @ MGr)  # = m·c̃
    mc = np.array([S[2, 1] - S[1, 2], S[0, 2] - S[2, 0], S[1, 0] - S[0, 1]]) / 2.0
    J = _sym(Gr.T @ MGr)
    C_t = MGt.T @ Phi
    C_r = MGr.T @ Phi
    lam = sla.eigh(K_e, M_e, eigvals_only=True) if Phi.shape[1] else np.zeros(0)
    omega = np.sqrt(np.clip(np.sort(lam), 0.0, None))
    return ModalData(nodes=np.asarray(fe.nodes, dtype=float), dofs=tuple(fe.dofs), Phi=Phi,
                     M_e=M_e, K_e=K_e, D_e=D_e, G_e=G_e, omega=omega, mass=mass, mc=mc, J=J,
                     C_t=C_t, C_r=C_r, method=method, kinds=tuple(kinds), meta=dict(fe.meta))
