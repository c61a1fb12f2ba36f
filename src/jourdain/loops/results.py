"""Time histories of closed-loop simulations (:class:`LoopResults`), from
:func:`jourdain.loops.simulate.simulate_loop` and the redundant-coordinate forms of
:mod:`jourdain.loops.redundant`."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import EvaluationError
from ..model import System
from .closed_loop import SingularConfiguration
from .reactions import closing_reactions


@dataclass
class LoopResults:
    """Time histories of a closed-loop simulation.

    ``t`` (N,); ``z, zd, zdd`` (N, n): the tree's coordinates (on the manifold); ``Phi``,
    ``Phi_dot`` (N, m): the constraint residuals; ``lam`` (N, m): the closing joints'
    multipliers (labels in ``labels``); ``T``, ``V`` (N,): kinetic and potential energy;
    ``partitions``: ``[(t_start, independent names), ...]``; ``status``, ``message``;
    ``singular``: the :class:`SingularConfiguration` that stopped the run, or None;
    ``method``: the integrator that ran.
    """

    loop: System
    t: np.ndarray
    z: np.ndarray
    zd: np.ndarray
    zdd: np.ndarray
    Phi: np.ndarray
    Phi_dot: np.ndarray
    lam: np.ndarray
    T: np.ndarray
    V: np.ndarray
    labels: list[str]
    partitions: list[tuple[float, tuple[str, ...]]]
    status: str = "finished"
    message: str = ""
    nfev: int = 0
    wall_time: float = 0.0
    singular: SingularConfiguration | None = None
    parameters: dict[str, float] = field(default_factory=dict)
    method: str = "DOP853"

    @property
    def coordinate_names(self) -> list[str]:
        return self.loop.coordinate_names

    @property
    def max_Phi(self) -> float:
        """Largest |Φ_i| along the motion."""
        return float(np.max(np.abs(self.Phi))) if self.Phi.size else 0.0

    @property
    def max_Phi_dot(self) -> float:
        """Largest |Φ̇_i| along the motion."""
        return float(np.max(np.abs(self.Phi_dot))) if self.Phi_dot.size else 0.0

    @property
    def total_energy(self) -> np.ndarray:
        return self.T + self.V

    @property
    def energy_drift(self) -> float:
        """max |E − E₀| / max(|E₀|, max T) (meaningful for a conservative model)."""
        E = self.total_energy
        return float(np.max(np.abs(E - E[0])) / max(abs(E[0]), float(np.max(self.T)), 1e-300))

    def coordinate(self, name: str) -> np.ndarray:
        """Time history of a tree coordinate (``<name>_d``, ``<name>_dd``: its rates)."""
        for suffix, arr in (("_dd", self.zdd), ("_d", self.zd), ("", self.z)):
            base = name[: len(name) - len(suffix)] if suffix and name.endswith(suffix) else name
            if (not suffix or name.endswith(suffix)) and base in self.coordinate_names:
                return arr[:, self.coordinate_names.index(base)]
        raise EvaluationError(f'unknown coordinate "{name}"; coordinates are '
                              f"{self.coordinate_names}")

    def reaction(self, label: str) -> np.ndarray:
        """Multiplier history of one constraint row (``closure.Fx``, ...)."""
        if label not in self.labels:
            raise EvaluationError(f'unknown constraint row "{label}"; rows are {self.labels}')
        return self.lam[:, self.labels.index(label)]

    def closing_reactions(self) -> dict[str, dict[str, np.ndarray]]:
        """Force ``F`` and torque ``T`` (N × 3, in body A's frame, B on A at A's joint point)
        of every closing joint with points, by name (:mod:`jourdain.loops.reactions`)."""
        p = np.array([self.parameters[k] for k, _ in self.loop.tree.parameters])
        return closing_reactions(self.loop, self.z, self.lam, self.t, p)

    def summary(self) -> str:
        parts = "; ".join(f"t ≥ {t0:.6g}: {', '.join(n)}" for t0, n in self.partitions)
        return "\n".join([
            f"{self.loop.name}: {self.status} - {self.message}",
            f"  t = {self.t[0]:.6g} .. {self.t[-1]:.6g} s, {len(self.t)} points, "
            f"{self.nfev} right-hand sides, {self.wall_time:.3f} s",
            f"  independent coordinates: {parts}",
            f"  constraint residuals: max |Φ| = {self.max_Phi:.3e}, max |Φ̇| = "
            f"{self.max_Phi_dot:.3e}",
            f"  relative energy drift {self.energy_drift:.3e} (meaningful when conservative)",
            *self._reaction_lines()])

    def _reaction_lines(self) -> list[str]:
        if not len(self.t):
            return []
        lines = []
        for name, w in self.closing_reactions().items():
            F, T = np.abs(w["F"]).max(axis=0), np.abs(w["T"]).max(axis=0)
            lines.append(f"  closing joint {name}: max |F| = ({F[0]:.4g}, {F[1]:.4g}, "
                         f"{F[2]:.4g}), max |T| = ({T[0]:.4g}, {T[1]:.4g}, {T[2]:.4g}) in "
                         "its body A's axes")
        return lines

    def tree_results(self) -> Any:
        """The motion as :class:`jourdain.Results` of the tree (its coordinates z), for the
        report, CSV/HDF5 and the plots of tree models."""
        from ..simulation.results import Results

        tree = self.loop.tree
        n_u = len(tree.inputs)
        return Results(tree, self.t, self.z, self.zd, self.zdd, np.zeros((len(self.t), n_u)),
                       np.zeros(len(self.t)), dict(self.parameters), method=self.method,
                       status=self.status, message=self.message, nfev=self.nfev,
                       wall_time=self.wall_time)


__all__ = ["LoopResults"]
