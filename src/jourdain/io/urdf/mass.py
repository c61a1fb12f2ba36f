"""Mass data of links merged into jourdain bodies (fixed joints weld links together, as
Pinocchio does): Steiner's theorem, and the mass each body carries.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .model import UrdfError
from .source import _float, _matrix, _Source


@dataclass
class _Mass:
    """Mass data being merged into one body (body frame): m, m·c and the inertia about the
    body frame's origin."""

    m: float = 0.0
    mc: np.ndarray = field(default_factory=lambda: np.zeros(3))
    I_o: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    rotational: bool = False  # some link has a nonzero inertia tensor

    def add(self, m: float, c: np.ndarray, I_c: np.ndarray) -> None:
        """Add a body of mass ``m``, centre of mass ``c`` and inertia ``I_c`` about it (all in
        the body frame): Steiner's theorem moves the inertia to the origin."""
        self.m += m
        self.mc += m * c
        self.I_o += I_c + m * (float(c @ c) * np.eye(3) - np.outer(c, c))
        self.rotational = self.rotational or bool(np.any(I_c != 0.0))

    def com_inertia(self) -> tuple[np.ndarray, np.ndarray]:
        """Centre of mass and inertia about it (symmetrized)."""
        if self.m == 0.0:
            return np.zeros(3), self.I_o.copy()
        c = self.mc / self.m
        I = self.I_o - self.m * (float(c @ c) * np.eye(3) - np.outer(c, c))
        return c, 0.5 * (I + I.T)



def _add_inertial(md: _Mass, lk: Any, pose: np.ndarray, src: _Source) -> None:
    """Merge the link's ``<inertial>`` (mass, origin, inertia about the centre of mass in the
    inertial frame) into the body's mass data; ``pose`` is the link's frame in the body frame."""
    inertial = lk.inertial
    if inertial is None:
        return
    path, line = src.path, src.line("link", lk.name)
    m = _float(inertial.mass, f'link "{lk.name}" <mass value>', path, line, 0.0)
    if m is None or m < 0.0:
        raise UrdfError(f'link "{lk.name}": the mass must be a number ≥ 0, got {m}', path, line)
    To = _matrix(inertial.origin, f'link "{lk.name}" <inertial><origin>', path, line)
    I = np.zeros((3, 3)) if inertial.inertia is None else np.asarray(inertial.inertia, float)
    if I.shape != (3, 3) or not np.all(np.isfinite(I)):
        raise UrdfError(f'link "{lk.name}": the inertia must be finite numbers', path, line)
    T = pose @ To  # the inertial frame in the body frame
    R = T[:3, :3]
    md.add(float(m), T[:3, 3].copy(), R @ I @ R.T)


def _mass_below(order: Sequence[str], spec: Mapping[str, dict],
                mass: Mapping[str, _Mass]) -> dict[str, float]:
    """Mass of each body together with all bodies it carries."""
    total = {b: mass[b].m for b in order}
    for b in reversed(order):  # children after parents: accumulate upward
        p = spec[b]["parent"]
        if p != "world":
            total[p] += total[b]
    return total

