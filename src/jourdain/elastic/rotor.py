"""A flexible rotor from beam elements: rigid discs and bearings at nodes, natural frequencies
over speed (Campbell diagram) and critical speeds.

The rotor spins at Ω about the beam's axis; with the beam's FE model (:func:`assemble`) plus
discs and bearings, the equations of motion of small vibrations are

    M·q̈ + (C + Ω·G)·q̇ + K·q = 0

(Friswell, Penny, Garvey & Lees, *Dynamics of Rotating Machines*, 2010, ch. 5–6; the same
form as ROSS's ``Rotor``). A disc at node k adds m·E to the translations, R·diag(I_p, I_d, I_d)·Rᵀ
to the rotations and I_p·(θ_y·θ̇_z-coupling) to G (the same sign as the shaft's gyroscopic
matrix, :mod:`jourdain.elastic.beam`); a bearing adds its 2 × 2 stiffness and damping in the
two transverse directions of the beam's frame (``k_yy``, ``k_yz``, ``k_zy``, ``k_zz``: the
element frame's y and z, which are the body's x and y for a rotor along z). Eigenvalues λ of
the first-order system ``[[0, E], [−M⁻¹K, −M⁻¹(C + ΩG)]]``: damped natural frequencies
ω_d = Im λ > 0, ascending.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from jourdain.elastic.beam import Beam, FEModel, assemble, frame_of_axis
from jourdain.errors import ModelError

__all__ = ["Disc", "Bearing", "Rotor", "rotor", "eigenvalues", "campbell", "critical_speeds"]


@dataclass(frozen=True)
class Disc:
    """A rigid disc at ``node``: mass ``m``, diametral and polar moments of inertia ``Id``,
    ``Ip`` about its centre (on the axis)."""

    node: int
    m: float
    Id: float
    Ip: float


@dataclass(frozen=True)
class Bearing:
    """A linear bearing at ``node``: stiffness and damping in the beam frame's transverse
    directions y, z (isotropic: k_yy = k_zz, no cross terms)."""

    node: int
    k_yy: float
    k_zz: float
    k_yz: float = 0.0
    k_zy: float = 0.0
    c_yy: float = 0.0
    c_zz: float = 0.0
    c_yz: float = 0.0
    c_zy: float = 0.0


@dataclass(frozen=True)
class Rotor:
    """The assembled rotor: the shaft's FE model and M, C, G, K (dense, n × n) of
    M·q̈ + (C + Ω·G)·q̇ + K·q = 0 on its DOFs."""

    fe: FEModel
    M: np.ndarray
    C: np.ndarray
    G: np.ndarray
    K: np.ndarray


def rotor(shaft: Beam, discs: Sequence[Disc] = (), bearings: Sequence[Bearing] = ()) -> Rotor:
    """The rotor of ``shaft`` with ``discs`` and ``bearings`` (module docstring)."""
    fe = assemble(shaft)
    # copies: the discs and bearings go into the rotor's matrices, not the shaft's (dense()
    # hands out the FE model's own array where it is dense)
    M, K, G = (fe.dense(x).copy() for x in ("M", "K", "G"))
    C = np.zeros_like(M)
    R = frame_of_axis(shaft.axis, shaft.up)
    n_nodes = len(fe.nodes)

    def dofs(node: int, what: str) -> list[int]:
        if not 0 <= node < n_nodes:
            raise ModelError(f"rotor: {what} at node {node}, the shaft has nodes 0..{n_nodes - 1}")
        return fe.node_dofs(node)

    for d in discs:
        i = dofs(d.node, "disc")
        t, r = np.ix_(i[:3], i[:3]), np.ix_(i[3:], i[3:])
        M[t] += d.m * np.eye(3)
        M[r] += R @ np.diag([d.Ip, d.Id, d.Id]) @ R.T
        G[r] += R @ (d.Ip * np.array([[0.0, 0, 0], [0, 0, 1], [0, -1, 0]])) @ R.T
    T = R[:, 1:]  # the transverse directions y, z of the beam frame
    for b in bearings:
        i = dofs(b.node, "bearing")
        t = np.ix_(i[:3], i[:3])
        K[t] += T @ np.array([[b.k_yy, b.k_yz], [b.k_zy, b.k_zz]]) @ T.T
        C[t] += T @ np.array([[b.c_yy, b.c_yz], [b.c_zy, b.c_zz]]) @ T.T
    return Rotor(fe=fe, M=M, C=C, G=G, K=K)


def eigenvalues(r: Rotor, speed: float, keep: Sequence[int] | None = None) -> np.ndarray:
    """Eigenvalues λ of the rotor's first-order system at spin ``speed`` (rad/s), on the DOFs
    ``keep`` (all by default: leave out e.g. the free axial and torsional DOFs), ordered by
    Im λ ascending."""
    idx = np.arange(r.M.shape[0]) if keep is None else np.asarray(keep)
    ix = np.ix_(idx, idx)
    M, K, D = r.M[ix], r.K[ix], r.C[ix] + speed * r.G[ix]
    n = len(idx)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, K), -np.linalg.solve(M, D)]])
    lam = sla.eigvals(A)
    return lam[np.argsort(lam.imag)]


def campbell(r: Rotor, speeds: Sequence[float] | np.ndarray, n_modes: int,
             keep: Sequence[int] | None = None) -> np.ndarray:
    """Damped natural frequencies ω_d = Im λ (rad/s) of the ``n_modes`` lowest modes
    (Im λ > 0) at each speed: an array (len(speeds), n_modes)."""
    out = np.empty((len(speeds), n_modes))
    for k, s in enumerate(speeds):
        lam = eigenvalues(r, float(s), keep)
        wd = np.sort(lam.imag[lam.imag > 0])
        if len(wd) < n_modes:
            raise ModelError(f"rotor: {len(wd)} oscillating modes at speed {s}, {n_modes} asked")
        out[k] = wd[:n_modes]
    return out


def critical_speeds(r: Rotor, n_modes: int, speed_max: float, keep: Sequence[int] | None = None,
                    n_grid: int = 200) -> np.ndarray:
    """Critical speeds up to ``speed_max``: the speeds Ω where the i-th damped natural frequency
    (ascending, i < ``n_modes``) equals Ω, i.e. the roots of ω_d,i(Ω) − Ω (bracketed on a grid
    of ``n_grid`` speeds, then ``scipy.optimize.brentq`` to machine precision). Sorted; a mode
    whose frequency stays above Ω on the grid (a forward mode stiffened faster than Ω) has none.
    """
    from scipy.optimize import brentq

    def f(s: float, i: int) -> float:
        return float(campbell(r, [s], n_modes, keep)[0, i] - s)

    grid = np.linspace(0.0, speed_max, n_grid)
    vals = campbell(r, grid, n_modes, keep) - grid[:, None]
    out = []
    for i in range(n_modes):
        for k in np.nonzero(np.sign(vals[:-1, i]) != np.sign(vals[1:, i]))[0]:
            out.append(brentq(f, grid[k], grid[k + 1], args=(i,), xtol=1e-14, rtol=1e-15))
    return np.sort(np.asarray(out))
