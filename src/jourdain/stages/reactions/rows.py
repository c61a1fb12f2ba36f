"""Rows of M̄ without inertia (``docs/method.md`` §4, singular inertia): the rows where M̄
vanishes (rotational rows of a point mass, the axial row of a thin rod, a massless body) and,
per body, the inverse of its inertia tensor on its regular axes. Used to form N̂, k̂, q̂ from
the regular rows and to border the reaction equations with the singular ones.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
import symengine as se

from ...errors import ModelError
from ...model.expressions import values_at

if TYPE_CHECKING:
    from ...model.system import System


def _body_rows(system: System) -> dict[str, int]:
    return {b.name: i for i, b in enumerate(system.bodies)}


def _singular_rows(system: System) -> tuple[tuple[int, ...], dict[str, tuple[list[int], Any]]]:
    """Rows where M̄ vanishes and, per body, its regular rotational axes with the inverse of the
    inertia tensor restricted to them."""
    p = len(system.bodies)
    values = dict(system.parameters)

    singular: list[int] = []
    inv: dict[str, tuple[list[int], Any]] = {}
    for i, b in enumerate(system.bodies):
        if b.mass == 0:
            singular.extend(range(3 * i, 3 * i + 3))
        elif abs(values_at([b.mass], values)[0]) == 0.0:
            raise ModelError(f'body "{b.name}": its mass is zero at the default parameters but '
                             "not identically zero; write mass=0 for a massless body")
        I = b.inertia
        regular = [a for a in range(3)
                   if not all(I[a][c] == 0 and I[c][a] == 0 for c in range(3))]
        singular.extend(3 * p + 3 * i + a for a in range(3) if a not in regular)
        if regular:
            sub = [[I[a][c] for c in regular] for a in regular]
            Ir = np.array(values_at([x for r in sub for x in r], values)).reshape(len(sub), -1)
            # |det| <= 1e-12·s^n, s = max|I|, tested as det(I/s): s^n overflows for inertias
            # above 1e102 (a mass of 1e300), and a floor of 1 on s made the small, regular
            # inertias of real robot links (1e-6 kg m², det 1e-18) count as singular
            s = float(np.abs(Ir).max()) or 1.0
            if abs(np.linalg.det(Ir / s)) <= 1e-12:
                raise ModelError(
                    f'body "{b.name}": its inertia tensor is singular, but not along body axes '
                    "(no row and column of zeros); give the inertia in a frame whose axes are "
                    "its principal axes"
                )
            inv[b.name] = (regular, _inverse(sub))
        else:
            inv[b.name] = ([], None)
    return tuple(sorted(singular)), inv


def _inverse(A: list[list[se.Basic]]) -> list[list[se.Basic]]:
    n = len(A)
    if n == 1:
        return [[1 / A[0][0]]]
    if n == 2:
        d = A[0][0] * A[1][1] - A[0][1] * A[1][0]
        return [[A[1][1] / d, -A[0][1] / d], [-A[1][0] / d, A[0][0] / d]]
    # 3x3 via the adjugate (constant parameters only: the expressions stay short)
    c = [[A[(i + 1) % 3][(j + 1) % 3] * A[(i + 2) % 3][(j + 2) % 3]
          - A[(i + 1) % 3][(j + 2) % 3] * A[(i + 2) % 3][(j + 1) % 3] for j in range(3)]
         for i in range(3)]
    d = A[0][0] * c[0][0] + A[0][1] * c[0][1] + A[0][2] * c[0][2]
    return [[c[j][i] / d for j in range(3)] for i in range(3)]
