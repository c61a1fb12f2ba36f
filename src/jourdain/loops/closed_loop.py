"""Closed kinematic loops in independent coordinates (issue 11).

A :class:`ClosedLoopSystem` is a spanning tree (a :class:`jourdain.System` in the coordinates
``z``, n of them) cut open at its closing joints, whose m independent scalar constraints
``Φ(z, t) = 0`` (:mod:`jourdain.loops.constraints`) tie the tree's coordinates together. The
method stays the seed's (METHOD.md §1–3) with one more kinematic stage:

* **Coordinate partitioning.** ``z = (y, d)``: f = n − m independent coordinates y and m
  dependent ones d, chosen by QR with column pivoting on ``Φ_z`` at the initial
  configuration (the best-conditioned ``Φ_d``) or by the user (:func:`partition`).
* **Kinematics on the manifold.** With ``Φ_z = [Φ_y Φ_d]``, ``ż = J_z·ẏ + ż_r`` where the
  dependent rows of ``J_z`` are ``−Φ_d⁻¹Φ_y`` and ``ż_r,d = −Φ_d⁻¹Φ_t`` (the implicit function
  theorem, kept as a linear solve with ``Φ_d``, never a symbolic inverse), and
  ``z̈ = J_z·ÿ + γ`` with ``γ_d = −Φ_d⁻¹·c``, ``c = Φ̈`` at ``z̈ = 0`` (the convective term
  ``(Φ_z ż)_z ż + 2 Φ_zt ż + Φ_tt``, generated symbolically and compiled).
* **Projection.** The tree's Jacobian ``J̄_tree`` becomes ``J̄ = J̄_tree·J_z`` and the seed's
  projection gives, in the independent coordinates,
  ``M = J_zᵀ M_tree J_z``, ``k = J_zᵀ(k_tree + M_tree·γ)``, ``q = J_zᵀ q_tree``: the closing
  joints' constraint forces ``Φ_zᵀλ`` drop out because ``Φ_z·J_z = 0`` (the orthogonality
  relation of the closing joints, checked by :func:`evaluate`).
* **Reactions of the closing joints** (Lagrange multipliers) from the tree's equations
  ``M_tree·z̈ + k_tree − q_tree = Φ_zᵀ·λ`` with the z̈ of the projected equations
  (:meth:`LoopEvaluator.multipliers`).

The redundant-coordinate form, side by side: ``[M_tree Φ_zᵀ; Φ_z 0]·[z̈; −λ] = [q − k; −c]``
(index 1), :meth:`LoopEvaluator.redundant_accelerations`, optionally with Baumgarte's
stabilization. It needs no partition and so no singular ``Φ_d``, but its positions drift off
the manifold unless projected back; the independent form stays on the manifold by
construction (the dependent coordinates are solved by Newton at every evaluation). Where
Φ_z itself loses rank (a mechanism's flat or bifurcation positions) neither a partition nor
the bordered matrix can be solved; the augmented-Lagrangian form
(:func:`jourdain.loops.simulate.simulate_penalty`) passes there.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np
import scipy.linalg as sla
import symengine as se
from scipy.linalg.lapack import dgetrf as getrf
from scipy.linalg.lapack import dgetrs as getrs
from scipy.linalg.lapack import dpotrf as potrf
from scipy.linalg.lapack import dpotrs as potrs

from ..errors import JourdainError, ModelError
from ..model import System
from ..model.forces import rate
from ..numeric import _vector, lambdify, mkq_function, parameter_vector, time_value
from ..stages.kinematics import kinematics  # the model has no stage methods (issue 16)
from ..symbolic import SymMatrix
from .constraints import ClosingJoint, ConstraintRow, constraint_rows, grubler

EPS = float(np.finfo(float).eps)


class SingularConfiguration(JourdainError, ArithmeticError):
    """The dependent coordinates cannot be solved: ``Φ_d`` is singular or too ill-conditioned
    at the time and state given (a change of the partition may help where the constraint
    Jacobian ``Φ_z`` itself keeps full rank). Attributes ``t``, ``z``, ``zd``, ``cond``,
    ``rank`` (of Φ_z), ``suggestion`` (a partition that is well-conditioned there, or None)."""

    def __init__(self, message: str, t: float = float("nan"), z: Any = None, zd: Any = None,
                 cond: float = float("inf"), rank: int | None = None,
                 suggestion: tuple[str, ...] | None = None) -> None:
        super().__init__(message)
        self.t, self.z, self.zd, self.cond, self.rank = t, z, zd, cond, rank
        self.suggestion = suggestion


class AssemblyError(JourdainError, ValueError):
    """Newton's method found no configuration on the manifold near the one given."""


@dataclass(frozen=True)
class ClosedLoopSystem:
    """A tree :class:`~jourdain.System` (coordinates z) closed by closing joints.

    Parameters
    ----------
    tree : System
        The spanning tree; its coordinates are the redundant coordinates z.
    closing : sequence of ClosingJoint
    independent : sequence of coordinate names, optional
        The independent coordinates y (else chosen by pivoting at the initial configuration).
    name : str, optional
    """

    tree: System
    closing: tuple[ClosingJoint, ...]
    independent: tuple[str, ...] | None = None
    name: str = ""

    def __init__(self, tree: System, closing: Sequence[ClosingJoint],
                 independent: Sequence[str] | None = None, name: str | None = None) -> None:
        set_ = object.__setattr__
        if not isinstance(tree, System):
            raise ModelError(f"ClosedLoopSystem: tree must be a System, got {type(tree).__name__}")
        set_(self, "tree", tree)
        closing = tuple(closing)
        if not closing:
            raise ModelError("ClosedLoopSystem: no closing joints (a tree needs none)")
        names: set[str] = set()
        bodies = set(tree.body_names) | {"world"}
        joint_names = {b.joint.name for b in tree.bodies}
        params = {k for k, _ in tree.parameters}
        coords = set(tree.coordinate_names)
        for cj in closing:
            if not isinstance(cj, ClosingJoint):
                raise ModelError(f"closing joints: expected ClosingJoint objects, got "
                                 f"{type(cj).__name__}")
            if cj.name in names or cj.name in joint_names:
                raise ModelError(f'closing joint "{cj.name}": the name is used twice')
            names.add(cj.name)
            for side in (cj.body_a, cj.body_b):
                if side not in bodies:
                    raise ModelError(f'closing joint "{cj.name}": unknown body "{side}"; bodies '
                                     f"are {', '.join(sorted(bodies))}")
            allowed = params | (coords | {"t"} if cj.type == "constraint" else set())
            unknown = sorted(cj.symbols() - allowed)
            if unknown:
                what = ("coordinates, t and parameters" if cj.type == "constraint"
                        else "parameters (points and axes are constant in their bodies)")
                raise ModelError(f'closing joint "{cj.name}": unknown name(s) '
                                 f"{', '.join(unknown)}; it may use {what}")
        set_(self, "closing", closing)
        if independent is not None:
            ind = tuple(str(c) for c in independent)
            for c in ind:
                if c not in coords:
                    raise ModelError(f'independent coordinate "{c}" is not a coordinate of the '
                                     f"tree ({', '.join(tree.coordinate_names)})")
            if len(set(ind)) != len(ind):
                raise ModelError(f"independent coordinates {list(ind)} name one twice")
            set_(self, "independent", ind)
        else:
            set_(self, "independent", None)
        set_(self, "name", tree.name if name is None else str(name))

    @property
    def n(self) -> int:
        """Number of tree coordinates z."""
        return self.tree.f

    @property
    def coordinate_names(self) -> list[str]:
        return self.tree.coordinate_names

    def grubler(self) -> int:
        """Degrees of freedom by the Grübler–Kutzbach count (spatial: 6 per body)."""
        return grubler(len(self.tree.bodies), [len(b.joint.coordinates)
                                               for b in self.tree.bodies], self.closing)

    def constraints(self) -> Constraints:
        return constraints(self)

    def evaluator(self, z0: Any = None, t: float = 0.0,
                  parameters: Mapping[str, float] | None = None) -> LoopEvaluator:
        """A :class:`LoopEvaluator` partitioned at ``z0`` (default: zeros)."""
        return LoopEvaluator(self, z0, t, parameters)


# ------------------------------------------------------------------------------------------
# symbolic constraints
# ------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Constraints:
    """The constraint equations of a loop system (symbolic, in z, ż, t and parameters).

    ``rows`` (m ConstraintRow), ``Phi`` (m×1), ``Phi_z`` (m×n), ``Phi_t`` (m×1), ``c``
    (m×1): ``Φ̈ = Φ_z·z̈ + c``.
    """

    rows: tuple[ConstraintRow, ...]
    Phi: SymMatrix
    Phi_z: SymMatrix
    Phi_t: SymMatrix
    c: SymMatrix

    @property
    def labels(self) -> list[str]:
        return [r.label for r in self.rows]


@lru_cache(maxsize=16)
def constraints(loop: ClosedLoopSystem) -> Constraints:
    """Φ, Φ_z, Φ_t and the convective term c of ``loop`` from the tree's kinematics."""
    tree = loop.tree
    rows = constraint_rows(kinematics(tree), loop.closing)
    if not rows:
        raise ModelError(f"{loop.name}: the closing joints give no constraint equation (every "
                         "row vanishes identically)")
    z = tree.coordinates
    zd = [rate(c) for c in z]
    t = tree.t
    Phi = [r.expr for r in rows]
    Phi_z = [[se.diff(e, zj) for zj in z] for e in Phi]
    Phi_t = [se.diff(e, t) for e in Phi]
    # w = Φ̇ = Φ_z ż + Φ_t; c = ∂w/∂z·ż + ∂w/∂t (the part of Φ̈ without z̈)
    c = []
    for i in range(len(Phi)):
        w = sum((Phi_z[i][j] * zd[j] for j in range(len(z))), se.Integer(0)) + Phi_t[i]
        ci = sum((se.diff(w, z[j]) * zd[j] for j in range(len(z))), se.Integer(0)) \
            + se.diff(w, t)
        c.append(ci)
    return Constraints(tuple(rows), SymMatrix.column(Phi), SymMatrix.from_rows(Phi_z),
                       SymMatrix.column(Phi_t), SymMatrix.column(c))


@lru_cache(maxsize=16)
def constraint_function(loop: ClosedLoopSystem) -> Any:
    """Compiled ``Phi, Phi_z, Phi_t, c`` and the tree's energies ``T, V`` (memoized)."""
    from ..analysis.energy import energy

    con = constraints(loop)
    e = energy(kinematics(loop.tree))
    return lambdify(loop.tree, {"Phi": con.Phi, "Phi_z": con.Phi_z, "Phi_t": con.Phi_t,
                                "c": con.c, "T": SymMatrix.column([e.T]),
                                "V": SymMatrix.column([e.V])})


# ------------------------------------------------------------------------------------------
# partition
# ------------------------------------------------------------------------------------------

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
    s = np.linalg.svd(A, compute_uv=False) if A.size else np.ones(1)
    return float(s[0] / s[-1]) if s[-1] > 0 else float("inf")


def partition(loop: ClosedLoopSystem, Phi_z: np.ndarray,
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


# ------------------------------------------------------------------------------------------
# numeric evaluation on the manifold
# ------------------------------------------------------------------------------------------

@dataclass
class Assembly:
    """Result of :meth:`LoopEvaluator.assemble`: consistent ``z``, ``zd`` and the residuals
    ``|Φ|∞``, ``|Φ̇|∞`` left, with the Newton iterations taken."""

    z: np.ndarray
    zd: np.ndarray
    Phi: float
    Phi_dot: float
    iterations: int
    independent: tuple[str, ...]


class LoopEvaluator:
    """Numeric evaluation of a :class:`ClosedLoopSystem` in its independent coordinates.

    Holds the compiled tree ``M, k, q`` (:func:`jourdain.numeric.mkq_function`), the compiled
    constraints (:func:`constraint_function`), the parameter vector and the current
    :class:`Partition`. ``z_guess`` (the last configuration solved) starts the next Newton
    solve; every result is the converged solution, whatever the guess.
    """

    def __init__(self, loop: ClosedLoopSystem, z0: Any = None, t: float = 0.0,
                 parameters: Mapping[str, float] | None = None, inputs: Any = None) -> None:
        self.loop = loop
        tree = loop.tree
        self.n = tree.f
        self.p = parameter_vector(tree, parameters)
        self.u = (np.zeros(len(tree.inputs)) if inputs is None
                  else np.ascontiguousarray(inputs, dtype=float))
        self.tree_mkq = mkq_function(tree)
        self.con = constraint_function(loop)
        self.labels = constraints(loop).labels
        z = np.zeros(self.n) if z0 is None else _vector(z0, self.n, "z0", loop.coordinate_names)
        self.z_guess = z.copy()
        self._last: tuple | None = None
        self.newton_tol = 1e-13
        self.max_newton = 25
        Phi_z = self._con(z, np.zeros(self.n), time_value(t))["Phi_z"]
        self.part = partition(loop, Phi_z, loop.independent)

    # --- low level -----------------------------------------------------------------------
    def _con(self, z: np.ndarray, zd: np.ndarray, t: float) -> dict[str, np.ndarray]:
        return self.con.split(self.con.raw(np.ascontiguousarray(z), np.ascontiguousarray(zd),
                                           t, self.p, self.u))

    def set_partition(self, part: Partition) -> None:
        self.part = part

    def repartition(self, z: np.ndarray, t: float) -> Partition:
        """A new automatic partition at ``z`` (not yet set)."""
        Phi_z = self._con(z, np.zeros(self.n), t)["Phi_z"]
        return partition(self.loop, Phi_z, None)

    def merge(self, y: np.ndarray, d: np.ndarray) -> np.ndarray:
        z = np.empty(self.n)
        z[list(self.part.independent)] = y
        z[list(self.part.dependent)] = d
        return z

    def solve_positions(self, y: np.ndarray, t: float, z_guess: np.ndarray | None = None
                        ) -> tuple[np.ndarray, dict[str, np.ndarray], int]:
        """Newton on ``Φ(y, d, t) = 0`` for d, y held: the configuration z, the constraint
        data there (``Phi_z`` at the converged z) and the iterations. Raises
        :class:`SingularConfiguration` when ``Φ_d`` is singular or Newton does not converge.
        """
        part = self.part
        ind, dep, rows = list(part.independent), list(part.dependent), list(part.rows)
        if z_guess is None:
            z = self.z_guess.copy()
            if self._last is not None and self._last[2] is part:
                # first-order prediction along the manifold: d ≈ d₀ + J_z,d·(y − y₀)
                y0, J_z, _ = self._last
                z += J_z @ (y - y0)
        else:
            z = z_guess.copy()
        z[ind] = y
        zero = np.zeros(self.n)
        scale = 1.0 + float(np.max(np.abs(z))) if self.n else 1.0
        last = math.inf
        for it in range(self.max_newton + 1):
            cd = self._con(z, zero, t)
            Phi = cd["Phi"][rows, 0]
            res = float(np.max(np.abs(Phi))) if Phi.size else 0.0
            if res <= self.newton_tol * scale or (res >= last and res <= 1e-10 * scale):
                return z, cd, it
            if it == self.max_newton:
                break
            Pd = cd["Phi_z"][np.ix_(rows, dep)]
            lu, piv, info = getrf(Pd)
            if info != 0 or not np.all(np.isfinite(lu)) or np.any(
                    np.abs(np.diag(lu)) <= EPS * np.max(np.abs(Pd)) * len(dep)):
                break
            step, _ = getrs(lu, piv, Phi)
            z[dep] -= step
            last = res
        raise SingularConfiguration(
            f"{self.loop.name}: no configuration on the manifold with the independent "
            f"coordinates {self._named(y)} at t = {t:.6g} (|Φ| = {res:.3g} after "
            f"{it} Newton steps with dependent {', '.join(self.dependent_names)})",
            t=t, z=z, cond=self.cond(z, t))

    @property
    def dependent_names(self) -> list[str]:
        return [self.loop.coordinate_names[j] for j in self.part.dependent]

    @property
    def independent_names(self) -> list[str]:
        return [self.loop.coordinate_names[j] for j in self.part.independent]

    def _named(self, y: np.ndarray) -> str:
        return ", ".join(f"{n} = {v:.6g}" for n, v in zip(self.independent_names, y,
                                                          strict=True))

    def cond(self, z: np.ndarray, t: float, Phi_z: np.ndarray | None = None) -> float:
        """Condition number of Φ_d at ``z`` (2-norm); ``Phi_z``: Φ_z there, if already
        evaluated (as :meth:`solve_positions` returns it)."""
        Pz = self._con(z, np.zeros(self.n), t)["Phi_z"] if Phi_z is None else Phi_z
        return _cond(Pz[np.ix_(list(self.part.rows), list(self.part.dependent))])

    def velocity_map(self, Phi_z: np.ndarray, Phi_t: np.ndarray
                     ) -> tuple[np.ndarray, np.ndarray, Any]:
        """``J_z`` (n×f) and ``ż_r`` (n) with ``ż = J_z·ẏ + ż_r``, and the LU of Φ_d."""
        part = self.part
        rows, dep, ind = list(part.rows), list(part.dependent), list(part.independent)
        lu = getrf(Phi_z[np.ix_(rows, dep)])[:2]
        rhs = np.concatenate([Phi_z[np.ix_(rows, ind)], Phi_t[rows, :]], axis=1)
        # column by column: getrs with a matrix right-hand side goes through multithreaded
        # BLAS (dtrsm), 200 µs and more on a loaded machine against 1 µs per vector
        sol = np.empty(rhs.shape)
        for j in range(rhs.shape[1]):
            sol[:, j] = getrs(lu[0], lu[1], rhs[:, j])[0]
        J_z = np.zeros((self.n, part.f))
        J_z[ind, np.arange(part.f)] = 1.0
        J_z[dep, :] = -sol[:, :part.f]
        zd_r = np.zeros(self.n)
        zd_r[dep] = -sol[:, part.f]
        return J_z, zd_r, lu

    def state(self, y: Any, yd: Any, t: float) -> dict[str, Any]:
        """Everything at an independent state (y, ẏ, t): ``z, zd, J_z, gamma`` (z̈ = J_z ÿ +
        γ), ``Phi`` and ``Phi_dot`` (the residuals), ``Phi_z``."""
        y = np.asarray(y, dtype=float)
        yd = np.asarray(yd, dtype=float)
        z, cd, _ = self.solve_positions(y, t)
        self.z_guess = z
        J_z, zd_r, lu = self.velocity_map(cd["Phi_z"], cd["Phi_t"])
        self._last = (y.copy(), J_z, self.part)
        zd = J_z @ yd + zd_r
        c2 = self._con(z, zd, t)
        rows = list(self.part.rows)
        gamma = np.zeros(self.n)
        gamma[list(self.part.dependent)] = -getrs(lu[0], lu[1], c2["c"][rows, 0])[0]
        Phi_dot = c2["Phi_z"] @ zd + c2["Phi_t"][:, 0]
        return {"z": z, "zd": zd, "J_z": J_z, "gamma": gamma, "Phi": c2["Phi"][:, 0],
                "Phi_dot": Phi_dot, "Phi_z": c2["Phi_z"], "T": float(c2["T"][0, 0]),
                "V": float(c2["V"][0, 0])}

    def mkq(self, y: Any, yd: Any, t: float, u: Any = None) -> dict[str, Any]:
        """``M, k, q`` in the independent coordinates (with :meth:`state`'s fields and the
        tree's ``M_tree, k_tree, q_tree``)."""
        s = self.state(y, yd, t)
        uu = self.u if u is None else np.ascontiguousarray(u, dtype=float)
        tr = self.tree_mkq.split(self.tree_mkq.raw(s["z"], s["zd"], t, self.p, uu))
        Mt, kt, qt = tr["M"], tr["k"][:, 0], tr["q"][:, 0]
        J = s["J_z"]
        s.update(M_tree=Mt, k_tree=kt, q_tree=qt, M=J.T @ Mt @ J,
                 k=J.T @ (kt + Mt @ s["gamma"]), q=J.T @ qt)
        return s

    def accelerations(self, y: Any, yd: Any, t: float, u: Any = None) -> dict[str, Any]:
        """:meth:`mkq` with ``ydd = M⁻¹(q − k)`` and ``zdd = J_z·ÿ + γ``."""
        s = self.mkq(y, yd, t, u)
        L, info = potrf(s["M"], lower=1)
        if info != 0:
            raise SingularConfiguration(f"{self.loop.name}: M in the independent coordinates "
                                        f"is not positive definite at t = {t:.6g}", t=t,
                                        z=s["z"], zd=s["zd"])
        ydd = potrs(L, s["q"] - s["k"], lower=1)[0]
        s["ydd"] = ydd
        s["zdd"] = s["J_z"] @ ydd + s["gamma"]
        return s

    def multipliers(self, s: dict[str, Any]) -> np.ndarray:
        """Lagrange multipliers λ (one per constraint row) from the tree's equations
        ``M_tree·z̈ + k_tree − q_tree = Φ_zᵀ·λ`` at the state ``s`` of :meth:`accelerations`
        (rows dropped by the rank test get 0: their share is carried by the rows kept)."""
        rows = list(self.part.rows)
        r = s["M_tree"] @ s["zdd"] + s["k_tree"] - s["q_tree"]
        A = s["Phi_z"][rows, :].T
        lam_r, *_ = np.linalg.lstsq(A, r, rcond=None)
        lam = np.zeros(len(self.labels))
        lam[rows] = lam_r
        return lam

    def redundant_accelerations(self, z: Any, zd: Any, t: float, alpha: float = 0.0,
                                beta: float = 0.0, u: Any = None) -> tuple[np.ndarray, np.ndarray]:
        """The redundant-coordinate (index-1) form: ``z̈`` and λ from
        ``[M_tree −Φ_zᵀ; Φ_z 0]·[z̈; λ] = [q − k; −c − 2αΦ̇ − β²Φ]`` (Baumgarte's
        stabilization with α, β; 0, 0: none)."""
        z = np.ascontiguousarray(z, dtype=float)
        zd = np.ascontiguousarray(zd, dtype=float)
        uu = self.u if u is None else np.ascontiguousarray(u, dtype=float)
        tr = self.tree_mkq.split(self.tree_mkq.raw(z, zd, t, self.p, uu))
        cd = self._con(z, zd, t)
        rows = list(self.part.rows)
        G = cd["Phi_z"][rows, :]
        m = len(rows)
        Phi = cd["Phi"][rows, 0]
        Phi_dot = G @ zd + cd["Phi_t"][rows, 0]
        A = np.block([[tr["M"], -G.T], [G, np.zeros((m, m))]])
        b = np.concatenate([tr["q"][:, 0] - tr["k"][:, 0],
                            -cd["c"][rows, 0] - 2 * alpha * Phi_dot - beta ** 2 * Phi])
        x = np.linalg.solve(A, b)
        lam = np.zeros(len(self.labels))
        lam[rows] = x[self.n:]
        return x[:self.n], lam

    def assemble(self, z0: Any, zd0: Any = None, t: float = 0.0) -> Assembly:
        """Consistent initial positions and velocities from approximate ones: Newton on
        ``Φ = 0`` with the independent coordinates of ``z0`` held, then ``ż`` from the
        independent rates of ``zd0`` (``Φ̇ = 0``). The residuals left are reported."""
        names = self.loop.coordinate_names
        z0 = _vector(z0, self.n, "z0", names)
        zd0 = np.zeros(self.n) if zd0 is None else _vector(zd0, self.n, "zd0",
                                                            [f"{c}_d" for c in names])
        ind = list(self.part.independent)
        self.z_guess = z0.copy()
        self._last = None
        try:
            z, cd, it = self.solve_positions(z0[ind], t, z0)
        except SingularConfiguration as exc:
            raise AssemblyError(f"assembly failed: {exc}") from None
        self.z_guess = z
        J_z, zd_r, _ = self.velocity_map(cd["Phi_z"], cd["Phi_t"])
        zd = J_z @ zd0[ind] + zd_r
        c2 = self._con(z, zd, t)
        Phi = float(np.max(np.abs(c2["Phi"])))
        Phi_dot = float(np.max(np.abs(c2["Phi_z"] @ zd + c2["Phi_t"][:, 0])))
        return Assembly(z, zd, Phi, Phi_dot, it, tuple(self.independent_names))

    def rank(self, z: Any, t: float = 0.0) -> int:
        """Rank of the constraint Jacobian Φ_z at ``z`` (mobility n − rank)."""
        Pz = self._con(np.asarray(z, dtype=float), np.zeros(self.n), t)["Phi_z"]
        s = np.linalg.svd(Pz, compute_uv=False)
        return int(np.sum(s > _rank_tol(Pz) * 1e3))


def evaluate(loop: ClosedLoopSystem, z: Any, zd: Any = None, t: float = 0.0,
             parameters: Mapping[str, float] | None = None, inputs: Any = None
             ) -> dict[str, Any]:
    """Assemble ``z, zd`` (independent coordinates held) and evaluate there: ``M, k, q`` in
    the independent coordinates, ``J_z``, ``J_bar = J̄_tree·J_z``, ``ydd``, the multipliers
    ``lambda`` (by row label in ``labels``), the residuals ``Phi``, ``Phi_dot`` and the
    orthogonality ``Phi_z·J_z`` (``orthogonality``, its largest entry)."""
    from ..numeric import evaluate as tree_evaluate

    ev = LoopEvaluator(loop, z, t, parameters, inputs)
    asm = ev.assemble(z, zd, t)
    ind = list(ev.part.independent)
    s = ev.accelerations(asm.z[ind], asm.zd[ind], t)
    s["lambda"] = ev.multipliers(s)
    s["labels"] = list(ev.labels)
    s["independent"] = list(ev.independent_names)
    s["dependent"] = list(ev.dependent_names)
    s["y"], s["yd"] = asm.z[ind], asm.zd[ind]
    s["orthogonality"] = float(np.max(np.abs(s["Phi_z"][list(ev.part.rows)] @ s["J_z"])))
    tree = tree_evaluate(loop.tree, s["z"], s["zd"], t, parameters,
                         None if not loop.tree.inputs else
                         (np.zeros(len(loop.tree.inputs)) if inputs is None else inputs))
    s["J_bar"] = tree["J_bar"] @ s["J_z"]
    s["M_bar"] = tree["M_bar"]
    s["assembly"] = asm
    return s


__all__ = ["Assembly", "AssemblyError", "ClosedLoopSystem", "Constraints", "LoopEvaluator",
           "Partition", "SingularConfiguration", "constraint_function", "constraints",
           "evaluate", "partition"]
