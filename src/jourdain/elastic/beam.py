"""Three-dimensional beam elements (Euler–Bernoulli and Timoshenko) and their assembly.

One element has two nodes with six degrees of freedom each, in the element's frame (x along the
axis from node 1 to node 2):

    (u_x, u_y, u_z, θ_x, θ_y, θ_z)   axial, two transverse, torsion, two bending rotations

so an element vector is ``[node 1 (6), node 2 (6)]``. Bending in the x–y plane (u_y, θ_z = u_y')
uses ``I_z``; bending in the x–z plane (u_z, θ_y = −u_z') uses ``I_y``.

Matrices, with ξ = x/L and, per bending plane, the shear parameter Φ = 12·E·I/(κ·G·A·L²)
(Φ = 0: Euler–Bernoulli):

- stiffness ``K``: axial E·A/L·[[1, −1], [−1, 1]], torsion G·J/L·[[1, −1], [−1, 1]], bending the
  Timoshenko element of Przemieniecki (1968, §5.6) and Friswell, Penny, Garvey & Lees,
  *Dynamics of Rotating Machines* (2010, §5.4.4): E·I/((1+Φ)L³)·[[12, 6L, −12, 6L],
  [6L, (4+Φ)L², −6L, (2−Φ)L²], ...];
- consistent mass ``M``: ρA·∫N_uᵀN_u dx (linear axial, the interdependent cubic/quadratic
  shape functions of Nelson 1980 / Friswell et al. eq. 5.88 for bending) plus the rotary inertia
  ρI·∫N_θᵀN_θ dx of each bending plane and ρ·I_p·∫N_θxᵀN_θx dx for torsion (I_p the polar
  moment of area, I_y + I_z unless given);
- gyroscopic ``G`` of a shaft spinning at Ω about its axis (Nelson & McVaugh 1976, Nelson 1980;
  Friswell et al. §5.4.5): ρ·I_p·∫(N_θyᵀN_θz − N_θzᵀN_θy) dx, skew, to be used as
  M·q̈ + Ω·G·q̇ + K·q = f. It comes from the spin part of the kinetic energy,
  ½ρI_p(Ω − θ̇_z·θ_y)²: the moments I_p·Ω·θ̇_z about y and −I_p·Ω·θ̇_y about z.

All integrals are evaluated by 4-point Gauss–Legendre quadrature, exact for these polynomials
(degree ≤ 6), so K, M and G come from one set of shape functions; the closed forms of the sources
(e.g. ρAL/(840(1+Φ)²)·(312 + 588Φ + 280Φ², ...)) are what the quadrature reproduces
(tests/test_elastic_beam.py checks them).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from jourdain.errors import ModelError

__all__ = ["Beam", "FEModel", "element_matrices", "assemble", "frame_of_axis", "DOF_NAMES",
           "section_fields"]

DOF_NAMES = ("ux", "uy", "uz", "rx", "ry", "rz")

_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(4)
_XI = 0.5 * (_GAUSS_X + 1.0)  # on [0, 1]
_WXI = 0.5 * _GAUSS_W


@dataclass(frozen=True)
class Beam:
    """A straight prismatic beam, meshed into ``n_elements`` equal elements.

    Args:
        length: length of the beam.
        E: Young's modulus.
        rho: density.
        A: cross-section area.
        I_y: second moment of area about the section's y axis (bending in the x–z plane).
        I_z: second moment of area about the section's z axis (bending in the x–y plane).
        J: torsion constant (G·J the torsional stiffness; the polar moment for a circle).
        n_elements: number of equal elements.
        G: shear modulus; give exactly one of G and nu.
        nu: Poisson's ratio (G = E/(2(1+ν))).
        kappa: shear correction factor; ``None`` for Euler–Bernoulli (no shear deformation).
        I_p: polar moment of area for the torsional and gyroscopic inertia (default I_y + I_z).
        rotary_inertia: whether the mass has the bending rotations' inertia ρI·∫N_θᵀN_θ.
        axis: direction of the beam's axis in the body frame.
        origin: position of its first node in the body frame.
        up: a vector not along ``axis`` fixing the element's y axis (default: the body axis
            after the one closest to ``axis``, cyclically: see :func:`frame_of_axis`).
    """

    length: float
    E: float
    rho: float
    A: float
    I_y: float
    I_z: float
    J: float
    n_elements: int = 10
    G: float | None = None
    nu: float | None = None
    kappa: float | None = None
    I_p: float | None = None
    rotary_inertia: bool = True
    axis: tuple[float, float, float] = (1.0, 0.0, 0.0)
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0)
    up: tuple[float, float, float] | None = None

    def __post_init__(self) -> None:
        for name in ("length", "E", "rho", "A", "I_y", "I_z", "J"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise ModelError(f"Beam: {name} must be a positive finite number, got {v!r}")
        if (self.G is None) == (self.nu is None):
            raise ModelError("Beam: give exactly one of G (shear modulus) and nu (Poisson's ratio)")
        if self.nu is not None and not -1.0 < self.nu < 0.5:
            raise ModelError(f"Beam: nu must lie in (-1, 0.5), got {self.nu!r}")
        if self.G is not None and not (np.isfinite(self.G) and self.G > 0):
            raise ModelError(f"Beam: G must be a positive finite number, got {self.G!r}")
        if self.kappa is not None and not (np.isfinite(self.kappa) and self.kappa > 0):
            raise ModelError(f"Beam: kappa must be positive (or None), got {self.kappa!r}")
        if self.I_p is not None and not (np.isfinite(self.I_p) and self.I_p > 0):
            raise ModelError(f"Beam: I_p must be positive (or None), got {self.I_p!r}")
        if int(self.n_elements) != self.n_elements or self.n_elements < 1:
            raise ModelError(f"Beam: n_elements must be a positive integer, got {self.n_elements!r}")
        frame_of_axis(self.axis, self.up)

    @property
    def shear_modulus(self) -> float:
        if self.G is not None:
            return float(self.G)
        return self.E / (2.0 * (1.0 + float(self.nu or 0.0)))

    @property
    def polar(self) -> float:
        return float(self.I_p) if self.I_p is not None else self.I_y + self.I_z

    def phi(self, I: float, L: float) -> float:
        """Shear parameter Φ = 12·E·I/(κ·G·A·L²) of an element of length L (0 without κ)."""
        if self.kappa is None:
            return 0.0
        return 12.0 * self.E * I / (self.kappa * self.shear_modulus * self.A * L * L)


@dataclass(frozen=True)
class FEModel:
    """A finite-element model: M·q̈ + (D + Ω·G)·q̇ + K·q = f on the DOFs ``dofs``.

    ``nodes`` (n, 3) are node coordinates in the body frame; ``dofs`` a tuple of
    ``(node index, name)`` with names from :data:`DOF_NAMES` (any subset per node, in any
    order); M, K (and G, D where present) are square of size ``len(dofs)``, dense ``ndarray``
    or ``scipy.sparse`` matrices.
    """

    nodes: np.ndarray
    dofs: tuple[tuple[int, str], ...]
    M: np.ndarray | sp.spmatrix
    K: np.ndarray | sp.spmatrix
    G: np.ndarray | sp.spmatrix | None = None
    D: np.ndarray | sp.spmatrix | None = None
    name: str = "fe model"
    meta: dict[str, float] = field(default_factory=dict)

    @property
    def n(self) -> int:
        return len(self.dofs)

    def index(self, node: int, name: str) -> int:
        """The position of DOF ``name`` of ``node`` in the matrices."""
        try:
            return self.dofs.index((node, name))
        except ValueError:
            raise ModelError(f"{self.name}: node {node} has no DOF {name!r}") from None

    def node_dofs(self, node: int) -> list[int]:
        """The positions of all DOFs of ``node``, in the order of :data:`DOF_NAMES`."""
        return [i for name in DOF_NAMES for i, d in enumerate(self.dofs) if d == (node, name)]

    def dense(self, which: str) -> np.ndarray:
        """Matrix ``which`` ('M', 'K', 'G', 'D') as a dense array (zeros where absent)."""
        a = getattr(self, which)
        if a is None:
            return np.zeros((self.n, self.n))
        return np.asarray(a.toarray() if sp.issparse(a) else a, dtype=float)


def frame_of_axis(axis: tuple[float, float, float] | np.ndarray,
                  up: tuple[float, float, float] | np.ndarray | None = None) -> np.ndarray:
    """Rotation R (3×3) whose columns are the element's x (along ``axis``), y and z axes in the
    body frame: a vector's body coordinates are R·(element coordinates)."""
    ex = np.asarray(axis, dtype=float)
    nx = float(np.linalg.norm(ex))
    if not (np.all(np.isfinite(ex)) and ex.shape == (3,) and nx > 0):
        raise ModelError(f"Beam: axis must be a nonzero 3-vector, got {axis!r}")
    ex = ex / nx
    if up is None:
        # the next body axis, cyclically, after the one closest to the beam's axis: axis x
        # gives the element frame (x, y, z), axis z gives (z, x, y)
        ref = np.eye(3)[(int(np.argmax(np.abs(ex))) + 1) % 3]
    else:
        ref = np.asarray(up, dtype=float)
    ez = np.cross(ex, ref)
    nz = float(np.linalg.norm(ez))
    if not nz > 1e-12:
        raise ModelError(f"Beam: up {up!r} is along the axis {axis!r}")
    ez /= nz
    ey = np.cross(ez, ex)
    return np.column_stack([ex, ey, ez])


def _bending_shapes(xi: float, L: float, phi: float) -> tuple[np.ndarray, np.ndarray]:
    """Shape functions of the Timoshenko element in a plane with DOFs (v1, ψ1, v2, ψ2), ψ the
    section's rotation (ψ = v' for Φ = 0): displacement N_v and rotation N_ψ (Nelson 1980;
    Friswell et al. eq. 5.88)."""
    c = 1.0 / (1.0 + phi)
    x2, x3 = xi * xi, xi**3
    Nv = c * np.array([1 - 3 * x2 + 2 * x3 + phi * (1 - xi),
                       L * (xi - 2 * x2 + x3 + 0.5 * phi * (xi - x2)),
                       3 * x2 - 2 * x3 + phi * xi,
                       L * (-x2 + x3 - 0.5 * phi * (xi - x2))])
    Npsi = c * np.array([6 * (x2 - xi) / L,
                         1 - 4 * xi + 3 * x2 + phi * (1 - xi),
                         6 * (xi - x2) / L,
                         -2 * xi + 3 * x2 + phi * xi])
    return Nv, Npsi


def _plane_rows(L: float, phi: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """At the Gauss points: N_v, N_ψ and ψ' (each 4 × 4: point × DOF) of one bending plane."""
    Nv = np.empty((4, 4))
    Np = np.empty((4, 4))
    dNp = np.empty((4, 4))
    c = 1.0 / (1.0 + phi)
    for g, xi in enumerate(_XI):
        Nv[g], Np[g] = _bending_shapes(xi, L, phi)
        dNp[g] = c / L * np.array([6 * (2 * xi - 1) / L, -4 + 6 * xi - phi,
                                   6 * (1 - 2 * xi) / L, -2 + 6 * xi + phi])
    return Nv, Np, dNp


# element DOF positions: the x–y plane (u_y, θ_z) and the x–z plane (u_z, θ_y)
_XY = np.array([1, 5, 7, 11])
_XZ = np.array([2, 4, 8, 10])
_SIGN_XZ = np.array([1.0, -1.0, 1.0, -1.0])  # (w, −θ_y) behaves as (v, θ_z)


def element_matrices(beam: Beam, L: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Stiffness K, consistent mass M and gyroscopic G (per unit spin Ω) of one element of
    length ``L``, each 12 × 12 in the element's frame (DOF order in the module docstring)."""
    E, Gs, rho, A = beam.E, beam.shear_modulus, beam.rho, beam.A
    K = np.zeros((12, 12))
    M = np.zeros((12, 12))
    w = _WXI * L
    # axial and torsion: linear shape functions
    Nl = np.column_stack([1 - _XI, _XI])
    lin_m = Nl.T @ (w[:, None] * Nl)
    lin_k = np.array([[1.0, -1.0], [-1.0, 1.0]]) / L
    for idx, k, m in (([0, 6], E * A, rho * A), ([3, 9], Gs * beam.J, rho * beam.polar)):
        K[np.ix_(idx, idx)] += k * lin_k
        M[np.ix_(idx, idx)] += m * lin_m
    # bending: the two planes; N_θ maps element DOFs to the rotations θ_z and θ_y
    Ntheta = {}
    for dofs, I, sign, key in ((_XY, beam.I_z, np.ones(4), "z"), (_XZ, beam.I_y, _SIGN_XZ, "y")):
        phi = beam.phi(I, L)
        Nv, Np, dNp = _plane_rows(L, phi)
        Nv, Np, dNp = Nv * sign, Np * sign, dNp * sign
        kb = E * I * dNp.T @ (w[:, None] * dNp)
        if phi > 0:
            # shear energy ½κGA∫(v' − ψ)²: the shear strain is constant on the element
            sh = _shear_strain(L, phi) * sign
            kb += float(beam.kappa) * Gs * A * L * np.outer(sh, sh)  # type: ignore[arg-type]
        K[np.ix_(dofs, dofs)] += kb
        mb = rho * A * Nv.T @ (w[:, None] * Nv)
        if beam.rotary_inertia:
            mb += rho * I * Np.T @ (w[:, None] * Np)
        M[np.ix_(dofs, dofs)] += mb
        full = np.zeros((4, 12))
        full[:, dofs] = Np if key == "z" else -Np
        Ntheta[key] = full
    Gm = rho * beam.polar * (Ntheta["y"].T @ (w[:, None] * Ntheta["z"])
                             - Ntheta["z"].T @ (w[:, None] * Ntheta["y"]))
    return K, M, Gm


def section_fields(beam: Beam, L: float, xi: float) -> tuple[np.ndarray, np.ndarray]:
    """The element's fields at ``ξ = x/L``: the section's displacement ``N_t`` and its rotation
    ``N_r`` (each 3 × 12, element frame), ``u = N_t·d``, ``θ = N_r·d`` for the element DOFs
    ``d``: linear axial and torsion, and in each bending plane the shape functions of
    :func:`element_matrices`, so that ``∫ρA·N_tᵀN_t + N_rᵀ·diag(ρI_p, ρI_y, ρI_z)·N_r dx``
    (the bending rotations' terms where ``beam.rotary_inertia``) is the element's M."""
    Nt = np.zeros((3, 12))
    Nr = np.zeros((3, 12))
    Nt[0, [0, 6]] = Nr[0, [3, 9]] = (1.0 - xi, xi)
    for row, dofs, I, sign in ((1, _XY, beam.I_z, np.ones(4)), (2, _XZ, beam.I_y, _SIGN_XZ)):
        Nv, Np = _bending_shapes(xi, L, beam.phi(I, L))
        Nt[row, dofs] = Nv * sign
        # θ_z = ψ of the x–y plane; θ_y = −ψ of the x–z plane
        Nr[3 - row, dofs] = Np * sign if row == 1 else -Np * sign
    return Nt, Nr


def _shear_strain(L: float, phi: float) -> np.ndarray:
    """The (constant) shear strain v' − ψ of the Timoshenko element per DOF (v1, ψ1, v2, ψ2)."""
    c = 1.0 / (1.0 + phi)
    dNv0 = c / L * np.array([-phi, L * (1 + 0.5 * phi), phi, -0.5 * phi * L])
    _, Np0 = _bending_shapes(0.0, L, phi)
    return dNv0 - Np0


def assemble(beam: Beam, sparse: bool = False) -> FEModel:
    """The beam's finite-element model: ``n_elements + 1`` nodes along its axis from
    ``origin``, six DOFs each (:data:`DOF_NAMES`, in the body frame), K, M and G assembled
    from :func:`element_matrices` rotated into the body frame (K_body = T·K_el·Tᵀ with
    T = diag(R, R, R, R), R from :func:`frame_of_axis`). Free ends: boundary conditions are
    applied by :func:`jourdain.elastic.reduction.constrain`."""
    n_el = int(beam.n_elements)
    L = beam.length / n_el
    R = frame_of_axis(beam.axis, beam.up)
    x = np.linspace(0.0, beam.length, n_el + 1)
    nodes = np.asarray(beam.origin, dtype=float)[None, :] + x[:, None] * R[:, 0][None, :]
    Ke, Me, Ge = element_matrices(beam, L)
    T = np.kron(np.eye(4), R)
    Ke, Me, Ge = (T @ a @ T.T for a in (Ke, Me, Ge))
    n = 6 * (n_el + 1)
    rows, cols = np.meshgrid(np.arange(12), np.arange(12), indexing="ij")
    r = np.concatenate([(rows + 6 * e).ravel() for e in range(n_el)])
    c = np.concatenate([(cols + 6 * e).ravel() for e in range(n_el)])

    def glue(a: np.ndarray) -> np.ndarray | sp.spmatrix:
        m = sp.coo_matrix((np.tile(a.ravel(), n_el), (r, c)), shape=(n, n)).tocsr()
        return m if sparse else m.toarray()

    dofs = tuple((i, name) for i in range(n_el + 1) for name in DOF_NAMES)
    meta = {"length": beam.length, "mass": beam.rho * beam.A * beam.length}
    return FEModel(nodes=nodes, dofs=dofs, M=glue(Me), K=glue(Ke), G=glue(Ge),
                   name="beam", meta=meta)
