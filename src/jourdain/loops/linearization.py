"""Linearization of a closed-loop system in its independent coordinates (METHOD.md §5, §6).

About a nominal motion ``y_s`` (with ``ẏ_s``, ``ÿ_s``) of the independent coordinates:

    M̃ = M(y_s),  P = ∂(k − q)/∂ẏ |_s,  Q = ∂(M·ÿ_s + k − q)/∂y |_s,  h = q − k − M·ÿ_s

and ``D, G, K, N`` as the symmetric and skew parts of P and Q. M, k and q are those of
:class:`jourdain.loops.closed_loop.LoopEvaluator` (dependent coordinates by Newton on the
manifold), so their derivatives are taken by central differences of the compiled
evaluation: the step ``δ = ε^(1/3)·(1 + |y_i|)`` balances truncation (δ²) against rounding
(ε/δ), about 1e-10 relative; a symbolic derivative would need the dependent coordinates as
functions of y, which exist only implicitly.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
import symengine as se

from ..errors import EvaluationError, SingularConfiguration
from ..model import System
from ..model.forces import rate
from ..numeric import CompiledFunction, lambdify
from ..stages.kinematics import kinematics
from ..stages.newton_euler import newton_euler
from ..stages.projection import projection
from ..symbolic import SymMatrix
from .closed_loop import AssemblyError, LoopEvaluator, constraints


@dataclass(frozen=True)
class LoopLinearization:
    """``M_tilde, P, Q, h`` and ``D, G, K, N`` (f×f, f) in the independent coordinates
    ``names``; ``A`` (2f×2f) the state matrix of ``x = (η, η̇)``; ``eigenvalues`` of A
    sorted by real part, then imaginary part."""

    names: tuple[str, ...]
    y_s: np.ndarray
    z_s: np.ndarray
    M_tilde: np.ndarray
    P: np.ndarray
    Q: np.ndarray
    h: np.ndarray
    D: np.ndarray
    G: np.ndarray
    K: np.ndarray
    N: np.ndarray
    A: np.ndarray
    eigenvalues: np.ndarray
    #: the closed system (None where built without it), the time and parameters used
    system: Any = None
    t: float = 0.0
    parameters: dict[str, float] | None = None

    @property
    def coordinate_names(self) -> tuple[str, ...]:
        """The independent coordinates η refers to (the same as :attr:`names`)."""
        return self.names

    def evaluate(self, t: float | None = None,
                 parameters: Mapping[str, float] | None = None) -> dict[str, np.ndarray]:
        """The numbers by the seed's names, like a tree's linearization's ``evaluate``."""
        if (t is not None and float(t) != self.t) or parameters:
            raise EvaluationError("a closed system's linearization holds numbers for one t "
                                  "and one set of parameters; linearize again for others")
        f = len(self.names)
        return {"M_tilde": self.M_tilde, "P": self.P, "Q": self.Q, "h": self.h,
                "B": np.zeros((f, 0)), "D": self.D, "G": self.G, "K": self.K, "N": self.N}

    def state_space(self) -> Any:
        """The state-space form ``ẋ = A·x + E·h`` in ``x = [η; η̇]`` of the independent
        coordinates (:class:`jourdain.analysis.StateSpace`; no inputs)."""
        from ..analysis.state_space import StateSpace

        f = len(self.names)
        E = np.zeros((2 * f, f))
        E[f:] = np.linalg.inv(self.M_tilde)
        pars = dict(self.parameters or {})
        if not pars and self.system is not None:
            pars = self.system.parameter_values
        return StateSpace(A=self.A, B=np.zeros((2 * f, 0)), E=E, M_tilde=self.M_tilde,
                          P=self.P, Q=self.Q, B_u=np.zeros((f, 0)), h=self.h,
                          coordinate_names=tuple(self.names), input_names=(), t=self.t,
                          parameters=pars)


def mass_inverse(system: Any, M: np.ndarray) -> np.ndarray:
    """M⁻¹ of a linearization's mass matrix, by Cholesky: SingularConfiguration naming the
    system where M is not positive definite (a mass of zero, a singular position), instead
    of NumPy's LinAlgError."""
    try:
        if not np.all(np.isfinite(M)):
            raise np.linalg.LinAlgError("not finite")
        C = np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        raise SingularConfiguration(
            f"{getattr(system, 'name', 'the system')}: M is not positive definite at the "
            "nominal state (a massless coordinate or a singular position): no linearization "
            "there") from None
    Ci = np.linalg.inv(C)
    return Ci.T @ Ci


def linearize_loop(loop: System, z_s: Any, zd_s: Any = None, t: float = 0.0,
                   ydd_s: Any = None, parameters: Mapping[str, float] | None = None
                   ) -> LoopLinearization:
    """Linearize ``loop`` about the configuration assembled from ``z_s`` (independent
    coordinates held), with rates from ``zd_s`` (default rest) and ``ÿ_s`` (default 0)."""
    ev = LoopEvaluator(loop, z_s, t, parameters)
    asm = ev.assemble(z_s, zd_s, t)
    ind = list(ev.part.independent)
    y0, yd0 = asm.z[ind], asm.zd[ind]
    f = len(ind)
    ydd = np.zeros(f) if ydd_s is None else np.asarray(ydd_s, dtype=float).reshape(f)
    z_ref = asm.z.copy()

    def parts(y: np.ndarray, yd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        ev.z_guess = z_ref.copy()
        ev._last = None
        s = ev.mkq(y, yd, t)
        return s["M"], s["k"] - s["q"]

    M0, r0 = parts(y0, yd0)
    step = np.finfo(float).eps ** (1 / 3)
    P = np.zeros((f, f))
    Q = np.zeros((f, f))
    for i in range(f):
        e = np.zeros(f)
        e[i] = step * (1 + abs(y0[i]))
        Mp, rp = parts(y0 + e, yd0)
        Mm, rm = parts(y0 - e, yd0)
        Q[:, i] = ((Mp - Mm) @ ydd + rp - rm) / (2 * e[i])
        e[i] = step * (1 + abs(yd0[i]))
        _, rp = parts(y0, yd0 + e)
        _, rm = parts(y0, yd0 - e)
        P[:, i] = (rp - rm) / (2 * e[i])
    h = -r0 - M0 @ ydd
    Minv = mass_inverse(loop, M0)
    A = np.block([[np.zeros((f, f)), np.eye(f)], [-Minv @ Q, -Minv @ P]])
    lam = np.linalg.eigvals(A)
    order = np.lexsort((lam.imag, lam.real))
    return LoopLinearization(tuple(ev.independent_names), y0, asm.z, M0, P, Q, h,
                             (P + P.T) / 2, (P - P.T) / 2, (Q + Q.T) / 2, (Q - Q.T) / 2, A,
                             lam[order])


@lru_cache(maxsize=16)
def _exact_parts(loop: System) -> CompiledFunction:
    """Compiled ``∂(k − q)/∂z``, ``∂(k − q)/∂ż`` of the tree and the Hessians ``∂²Φ_i/∂z²``
    (stacked, m·n × n)."""
    tree = loop.tree
    eom = projection(newton_euler(kinematics(tree)))
    z = tree.coordinates
    zd = [rate(c) for c in z]
    r = [eom.k.rows[i][0] - eom.q.rows[i][0] for i in range(len(z))]
    con = constraints(loop)
    H = [[se.diff(con.Phi_y.rows[i][j], zk) for zk in z]
         for i in range(len(con.rows)) for j in range(len(z))]
    return lambdify(tree, {"R_z": SymMatrix.from_rows([[se.diff(e, c) for c in z] for e in r]),
                           "R_zd": SymMatrix.from_rows([[se.diff(e, c) for c in zd]
                                                        for e in r]),
                           "H": SymMatrix.from_rows(H)})


def linearize_loop_exact(loop: System, z_s: Any, t: float = 0.0,
                         parameters: Mapping[str, float] | None = None) -> LoopLinearization:
    """The linearization about an equilibrium at rest (``ẏ_s = ÿ_s = 0``, scleronomic
    constraints) from symbolic derivatives instead of differences. With the multipliers λ of
    the equilibrium (``Φ_zᵀλ = k − q`` there) and ``J_z`` of the partition::

        M̃ = J_zᵀ M_tree J_z,  P = J_zᵀ ∂(k − q)/∂ż J_z,
        Q = J_zᵀ (∂(k − q)/∂z − Σ λ_i ∂²Φ_i/∂z²) J_z

    (the derivative of ``J_zᵀ(k − q)`` along the manifold: ``J_zᵀΦ_zᵀ = 0`` turns the change
    of ``J_z`` into the constraint forces' geometric stiffness ``−Σ λ_i H_i``)."""
    ev = LoopEvaluator(loop, z_s, t, parameters)
    asm = ev.assemble(z_s, None, t)
    ind = list(ev.part.independent)
    f = len(ind)
    s = ev.accelerations(asm.z[ind], np.zeros(f), t)
    lam = ev.multipliers(s)
    n = loop.f
    parts = _exact_parts(loop).split(_exact_parts(loop).raw(
        np.ascontiguousarray(asm.z), np.zeros(n), t, ev.p, ev.u))
    H = parts["H"].reshape(len(lam), n, n)
    J = s["J_z"]
    M0 = J.T @ s["M_tree"] @ J
    P = J.T @ parts["R_zd"] @ J
    Q = J.T @ (parts["R_z"] - np.einsum("i,ijk->jk", lam, H)) @ J
    h = s["q"] - s["k"]
    Minv = mass_inverse(loop, M0)
    A = np.block([[np.zeros((f, f)), np.eye(f)], [-Minv @ Q, -Minv @ P]])
    eig = np.linalg.eigvals(A)
    order = np.lexsort((eig.imag, eig.real))
    return LoopLinearization(tuple(ev.independent_names), asm.z[ind], asm.z, M0, P, Q, h,
                             (P + P.T) / 2, (P - P.T) / 2, (Q + Q.T) / 2, (Q - Q.T) / 2, A,
                             eig[order])


def equilibrium(loop: System, z_guess: Any, t: float = 0.0,
                parameters: Mapping[str, float] | None = None, tol: float = 1e-12,
                max_iter: int = 50) -> np.ndarray:
    """An equilibrium ``q − k = 0`` at rest near ``z_guess`` (Newton in the independent
    coordinates with the finite-difference stiffness of :func:`linearize_loop`); returns z."""
    z = np.asarray(z_guess, dtype=float).copy()
    for _ in range(max_iter):
        lin = linearize_loop(loop, z, None, t, None, parameters)
        if np.max(np.abs(lin.h)) <= tol * (1 + np.max(np.abs(lin.Q))):
            return lin.z_s
        # the Newton step in the coordinates Q and h are in: the linearization's own
        ind = [loop.coordinate_names.index(c) for c in lin.names]
        z = lin.z_s.copy()
        try:
            z[ind] += np.linalg.solve(lin.Q, lin.h)
        except np.linalg.LinAlgError:
            raise AssemblyError(f"{loop.name}: no isolated equilibrium near z = "
                                f"{np.round(np.asarray(z_guess, dtype=float), 6).tolist()}: "
                                "the stiffness Q in the independent coordinates "
                                f"{', '.join(lin.names)} is singular there (a neutral "
                                "direction)") from None
    raise AssemblyError(f"{loop.name}: no equilibrium found near z = "
                        f"{np.round(np.asarray(z_guess, dtype=float), 6).tolist()}")


__all__ = ["LoopLinearization", "equilibrium", "linearize_loop", "linearize_loop_exact"]
