"""The general form of the linearization (``docs/method.md`` §5): M, P, Q and the residual as
symbolic functions of the state y, ẏ, ÿ (:func:`linearization_general`,
:class:`GeneralLinearization`), for any operating point.

Floor: stages. The result is symbolic; :func:`evaluate_general_at` walks it in floating point
at a state already checked. The public ``glin.evaluate(y, yd, ydd, t, parameters, inputs)``,
which checks the state, is on the numeric floor: :mod:`jourdain.numeric.linearization`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import symengine as se

from ...graph import evaluate_float, jet
from ...graph.piecewise import Switch, switches_at
from ...symbolic import SymMatrix

if TYPE_CHECKING:
    from ...model.system import System
    from ..projection import EquationsOfMotion
from .formation import _residual_parts
from .nominal import ZERO


@dataclass(frozen=True)
class GeneralLinearization:
    """The linearization about an arbitrary state, as functions of it (the general form):
    ``M_tilde(y, t)``, ``P(y, ẏ, u, t)``, ``Q(y, ẏ, ÿ, u, t)``, ``h`` and ``B``; the
    accelerations appear as the symbols ``<name>_dd`` (:attr:`System.ydd`). Substituting a
    nominal motion gives :func:`linearization`'s result."""

    equations_of_motion: EquationsOfMotion
    M_tilde: SymMatrix
    P: SymMatrix
    Q: SymMatrix
    h: SymMatrix
    B: SymMatrix
    #: piecewise functions whose branch depends on the state: (what, expression whose zero is
    #: the switching point), refused there by :func:`evaluate_general_at`
    switches: tuple[Switch, ...] = ()

    @property
    def system(self) -> System:
        return self.equations_of_motion.system


def evaluate_general_at(glin: GeneralLinearization, values: Mapping[str, float]
                        ) -> dict[str, np.ndarray]:
    """Arrays of ``M_tilde, P, Q, h, B`` (h 1-D) at ``values``: the value of every symbol of
    the system's ``y``, ``yd``, ``ydd``, parameters and inputs, and of ``t``, by name, already
    checked (``glin.evaluate`` of :mod:`jourdain.numeric.linearization` checks them)."""
    mats = {"M_tilde": glin.M_tilde, "P": glin.P, "Q": glin.Q, "h": glin.h, "B": glin.B}
    flat = [e for m in mats.values() for e in m.entries()]
    switches_at(glin.switches, values, evaluate_float)
    nums = iter(evaluate_float(flat, dict(values)))
    out: dict[str, np.ndarray] = {}
    for name, m in mats.items():
        n, c = m.shape
        out[name] = np.array([next(nums) for _ in range(n * c)]).reshape(n, c)
    out["h"] = out["h"].reshape(-1)
    return out


def linearization_general(eom: EquationsOfMotion) -> GeneralLinearization:
    """M̃, P, Q, h, B as functions of the state (y, ẏ, ÿ, u, t): the general form that
    sympy's ``Linearizer.linearize()`` gives, without inverting M."""
    system = eom.system
    f, m = system.f, len(system.inputs)
    exprs, mask, upper = _residual_parts(eom, [True] * f)
    variables = [*system.y, *system.yd, *system.inputs]
    J = jet(exprs, variables, {}, mask)
    ydd = system.ydd
    nv = len(variables)
    grad_r: list[list[list[se.Basic]]] = [[[] for _ in range(nv)] for _ in range(f)]
    val_r: list[list[se.Basic]] = [[J.values[i], -J.values[f + i]] for i in range(f)]
    for i in range(f):
        for j, d in J.gradients[i].items():
            grad_r[i][j].append(d)
        for j, d in J.gradients[f + i].items():
            grad_r[i][j].append(-d)
    Mt = [[ZERO] * f for _ in range(f)]
    for (i, j), v, g in zip(upper, J.values[2 * f:], J.gradients[2 * f:], strict=True):
        Mt[i][j] = Mt[j][i] = v
        for a, b in ((i, j), (j, i)) if i != j else ((i, j),):
            val_r[a].append(v * ydd[b])
            for w, d in g.items():
                grad_r[a][w].append(d * ydd[b])

    def total(terms: list[se.Basic]) -> se.Basic:
        return ZERO if not terms else terms[0] if len(terms) == 1 else se.Add(*terms)

    return GeneralLinearization(
        equations_of_motion=eom, M_tilde=SymMatrix.from_rows(Mt),
        Q=SymMatrix.from_rows([[total(grad_r[i][v]) for v in range(f)] for i in range(f)]),
        P=SymMatrix.from_rows([[total(grad_r[i][f + v]) for v in range(f)] for i in range(f)]),
        B=SymMatrix(tuple(tuple(-total(grad_r[i][2 * f + v]) for v in range(m))
                          for i in range(f))),
        h=SymMatrix.column([-total(val_r[i]) for i in range(f)]),
        switches=J.switches,
    )
