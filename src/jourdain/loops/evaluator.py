"""Numeric evaluation of a closed-loop system in its independent coordinates
(:class:`LoopEvaluator`: Newton on the dependent coordinates, the velocity map J_z, M, k, q,
ÿ, the multipliers, the redundant-coordinate accelerations, assembly) and :func:`evaluate`.
The compiled counterpart for simulations is :mod:`jourdain.loops.compiled`."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.linalg.lapack import dgetrf as getrf
from scipy.linalg.lapack import dgetrs as getrs
from scipy.linalg.lapack import dpotrf as potrf
from scipy.linalg.lapack import dpotrs as potrs

from ..errors import warn
from ..numeric import _vector, mkq_function, parameter_vector, time_value
from ..numeric import evaluate as tree_evaluate
from .partitioning import Partition, _cond, _rank_tol, partition
from .system import (
    EPS,
    AssemblyError,
    SingularConfiguration,
    System,
    constraint_function,
    constraints,
)


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


#: Newton's plateau exit (:func:`_newton_stop`): sqrt(eps), the largest scaled residual at
#: which a residual that stopped decreasing is taken as rounding
_PLATEAU = math.sqrt(EPS)


def _newton_stop(Phi: np.ndarray, Phi_z: np.ndarray, Phi_t: np.ndarray, z: np.ndarray,
                 t: float, tol: float, last: float) -> tuple[int, float, float]:
    """Newton's stop for :meth:`LoopEvaluator.solve_positions`, the same test as
    ``jdl_converged`` in ``loop_c.h`` (keep them equal; the reasoning is set out there).
    ``Phi``, ``Phi_z``, ``Phi_t``: the kept rows at ``z``; ``tol``: the relative tolerance
    (``newton_tol``); ``last``: the plateau measure of the previous iterate. Returns 1 (z
    solves Φ = 0 to rounding), 0 (go on) or -1 (Φ not finite), ``|Φ|∞`` and the next ``last``.

    Why: Φ's rows carry the closing joints' units and z mixes radians and metres, so an
    absolute bound (the former ``|Φ| ≤ 1e-13·(1 + max|z|)``) is loose for a small mechanism
    and out of reach for a large one. Row i is scaled by ``w_i = Σ_j |∂Φ_i/∂z_j|·|z_j| +
    |∂Φ_i/∂t|·|t|``, the change of Φ_i when every coordinate moves by its own relative amount,
    in the row's units whatever the coordinates' units: ``|Φ_i| ≤ tol·w_i`` for all rows makes
    z the exact solution for coordinates perturbed by at most ``tol`` relative (a componentwise
    backward error), the same test in metres or micrometres, and a row keeps its scale where
    some of its coordinates are 0. Where rounding in Φ_i exceeds that (terms that do not move
    with z: a mechanism far from the origin, or all the row's coordinates near 0) Newton
    reaches a plateau: an iterate whose residual relative to ``w_i + Σ_j |∂Φ_i/∂z_j|`` (a
    coordinate counted at least 1, a radian for an angle) did not decrease and is below
    √eps is at rounding level. A Newton that does not converge does not stop there: its
    residual is larger by orders, or still decreasing near a singular position, and the
    caller raises :class:`SingularConfiguration` after ``max_newton`` steps."""
    a = np.abs(Phi)
    res = float(np.max(a)) if a.size else 0.0
    if not math.isfinite(res):
        return -1, res, last
    G = np.abs(Phi_z)
    w = G @ np.abs(z) + np.abs(Phi_t * t)
    if np.all(a <= tol * w):
        return 1, res, last
    with np.errstate(divide="ignore", invalid="ignore"):
        q = np.where(a > 0, a / (w + G.sum(axis=1)), 0.0)
    rel = float(np.max(q)) if q.size else 0.0
    if last <= rel <= _PLATEAU:
        return 1, res, last
    return 0, res, rel


class LoopEvaluator:
    """Numeric evaluation of a :class:`System` in its independent coordinates.

    Holds the compiled tree ``M, k, q`` (:func:`jourdain.numeric.mkq_function`), the compiled
    constraints (:func:`constraint_function`), the parameter vector and the current
    :class:`Partition`. ``z_guess`` (the last configuration solved) starts the next Newton
    solve; every result is the converged solution, whatever the guess.
    """

    def __init__(self, loop: System, z0: Any = None, t: float = 0.0,
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

        Converged means a componentwise backward error of at most ``newton_tol`` (relative,
        free of units: each row's residual against the change of that row when every
        coordinate moves by its own relative amount), or a residual at the rounding plateau
        (:func:`_newton_stop`, the test of the C kernel too), so that a mechanism in
        micrometres is solved to the same digits as in metres.
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
        last = math.inf
        for it in range(self.max_newton + 1):
            cd = self._con(z, zero, t)
            Phi = cd["Phi"][rows, 0]
            stop, res, last = _newton_stop(Phi, cd["Phi_z"][rows], cd["Phi_t"][rows, 0], z, t,
                                           self.newton_tol, last)
            if stop > 0:
                return z, cd, it
            if stop < 0 or it == self.max_newton:
                break
            Pd = cd["Phi_z"][np.ix_(rows, dep)]
            lu, piv, info = getrf(Pd)
            if info != 0 or not np.all(np.isfinite(lu)) or np.any(
                    np.abs(np.diag(lu)) <= EPS * np.max(np.abs(Pd)) * len(dep)):
                break
            step, _ = getrs(lu, piv, Phi)
            z[dep] -= step
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
                "Phi_dot": Phi_dot, "Phi_z": c2["Phi_z"]}

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
        z0 = _vector(z0, self.n, "y", names)
        zd0 = np.zeros(self.n) if zd0 is None else _vector(zd0, self.n, "yd",
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
        _warn_dropped_rates(self, zd0, zd)
        c2 = self._con(z, zd, t)
        Phi = float(np.max(np.abs(c2["Phi"])))
        Phi_dot = float(np.max(np.abs(c2["Phi_z"] @ zd + c2["Phi_t"][:, 0])))
        return Assembly(z, zd, Phi, Phi_dot, it, tuple(self.independent_names))

    def rank(self, z: Any, t: float = 0.0) -> int:
        """Rank of the constraint Jacobian Φ_z at ``z`` (mobility n − rank)."""
        Pz = self._con(np.asarray(z, dtype=float), np.zeros(self.n), t)["Phi_z"]
        s = np.linalg.svd(Pz, compute_uv=False)
        return int(np.sum(s > _rank_tol(Pz) * 1e3))


def _warn_dropped_rates(ev: LoopEvaluator, given: np.ndarray, assembled: np.ndarray) -> None:
    """A warning where rates given for dependent coordinates are not those of the assembled
    motion: they follow from the independent rates (held), so a different value the user gave
    would otherwise be dropped without a word (zeros are taken as "not given")."""
    dep = list(ev.part.dependent)
    scale = float(np.max(np.abs(assembled), initial=0.0)) + float(
        np.max(np.abs(given), initial=0.0))
    off = [j for j in dep if given[j] != 0.0
           and abs(given[j] - assembled[j]) > math.sqrt(EPS) * max(scale, 1e-300)]
    if off:
        names = ev.loop.coordinate_names
        pairs = ", ".join(f"{names[j]}_d = {given[j]:.6g} (assembled {assembled[j]:.6g})"
                          for j in off)
        warn(f"{ev.loop.name}: the rates of the dependent coordinates follow from those of the "
             f"independent ones ({', '.join(ev.independent_names)}), held as given: {pairs}; "
             "choose the independent coordinates ([loops] independent) to hold others")


def evaluate(loop: System, z: Any, zd: Any = None, t: float = 0.0,
             parameters: Mapping[str, float] | None = None,
             inputs: Sequence[float] | None = None
             ) -> dict[str, Any]:
    """Assemble ``z, zd`` (independent coordinates held) and evaluate there: ``M, k, q`` in
    the independent coordinates, ``J_z``, ``J_bar = J̄_tree·J_z``, ``ydd``, the multipliers
    ``lambda`` (by row label in ``labels``), the residuals ``Phi``, ``Phi_dot`` and the
    orthogonality ``Phi_z·J_z`` (``orthogonality``, its largest entry)."""
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
                         ([0.0] * len(loop.tree.inputs) if inputs is None else inputs))
    s["J_bar"] = tree["J_bar"] @ s["J_z"]
    s["M_bar"] = tree["M_bar"]
    s["assembly"] = asm
    return s


__all__ = ["Assembly", "LoopEvaluator", "evaluate"]
