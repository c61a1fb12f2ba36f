"""Formation of the symbolic linearization (``docs/method.md`` §5): the residual
``r = M·ÿ + k − q`` differentiated in one forward-mode pass over its shared graph with the
nominal motion substituted on the way (:func:`jourdain.graph.jet`): ``Q = ∂r/∂y``,
``P = ∂r/∂ẏ``, ``B = −∂r/∂u``, ``h = −r`` (:func:`linearization`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np
import symengine as se

from ...errors import JourdainError, warn
from ...graph import evaluate_float_many, free_symbol_names, jet
from ...symbolic import SymMatrix

if TYPE_CHECKING:
    from ...model.system import System
    from ..projection import EquationsOfMotion
from .nominal import ZERO, NominalMotionWarning, _is_zero, _nominal, _perturbed
from .result import Linearization, check_nominal_at, values_at


def nominal_warning(lin: Linearization) -> str | None:
    """The :class:`NominalMotionWarning`'s message when a claimed equilibrium or steady motion
    leaves h ≠ 0 at t = 0 for the default parameter values (a reference trajectory with
    ÿ_s ≠ 0 is not checked: h is its feed-forward), else None."""
    defaults = np.array(list(lin.system.parameter_values.values()), dtype=float)
    try:
        result = check_nominal_at(lin, values_at(lin, 0.0, defaults))
    except JourdainError:  # no numbers at the default parameter values: evaluate() will say
        return None
    if result.kind != "nominal motion" and not result.is_solution:
        return result.message()
    return None


def _warn_if_not_solution(lin: Linearization) -> None:
    message = nominal_warning(lin)
    if message is not None:
        warn(message, NominalMotionWarning)


def linearization(eom: EquationsOfMotion, nominal: Mapping[Any, Any] | Any,
                  inputs: Mapping[Any, Any] | None = None) -> Linearization:
    """Linearize ``M·ÿ + k = q`` about a nominal motion (METHOD.md §5).

    Parameters
    ----------
    eom : EquationsOfMotion
        Result of :func:`jourdain.stages.projection`.
    nominal : mapping
        ``{coordinate: y_s}`` for every coordinate (names or symbols as keys), each a number or
        an expression in ``t`` and the system's parameters: constants for an equilibrium,
        ``Omega*t`` for a steady rotation, any ``y_s(t)`` for a reference trajectory. Inputs may
        be given too (``{"F": F_s}``); inputs not given are zero. An object with a ``nominal``
        attribute (e.g. :class:`jourdain.Equilibrium`) is accepted as well.
    inputs : mapping, optional
        Nominal inputs ``{input: u_s}`` (numbers or expressions in t and the parameters), e.g.
        the motor torque that keeps the nominal motion going; the same as giving them in
        ``nominal``.

    Returns
    -------
    Linearization
        ``M_tilde, P, Q, h, B`` symbolic in the parameters (and t for a time-variant result).

    Raises
    ------
    ModelError
        A coordinate without a nominal value, an unknown name, or a symbol in a nominal value
        that is neither ``t`` nor a parameter of the system.

    Warns
    -----
    NominalMotionWarning
        When the nominal motion is an equilibrium or a steady motion (ÿ_s = 0) and ``h ≠ 0`` at
        t = 0 for the default parameter values (:func:`.result.check_nominal_at`).
    """
    y_s, u_s = _nominal(eom.system, nominal, inputs)
    lin = form(eom, y_s, u_s)
    _warn_if_not_solution(lin)
    return lin


def form(eom: EquationsOfMotion, y_s: list[se.Basic], u_s: list[se.Basic]) -> Linearization:
    """:func:`linearization` about the nominal motion ``y_s`` (f expressions) and inputs
    ``u_s`` (m), already checked (``nominal._nominal``), without the warning."""
    system = eom.system
    t = system.t
    f = system.f
    yd_s = [se.diff(e, t) for e in y_s]
    ydd_s = [se.diff(e, t) for e in yd_s]
    u_names = system.input_names

    # the residual r = M·ÿ + k − q; its gradient at the nominal point gives Q, P, −B. k, q and
    # the entries of M are differentiated separately and combined (building r as one expression
    # would let SymEngine flatten M_ij·ÿ_j into new nodes that share nothing with M)
    exprs, mask, upper = _residual_parts(eom, [not _is_zero(a) for a in ydd_s])
    variables = [*system.y, *system.yd, *system.inputs]
    point: dict[se.Symbol, se.Basic] = {}
    point.update(zip(system.y, y_s, strict=True))
    point.update(zip(system.yd, yd_s, strict=True))
    point.update(zip(system.inputs, u_s, strict=True))
    J = jet(exprs, variables, point, mask)
    m = len(u_names)
    nv = len(variables)
    grad_r: list[list[list[se.Basic]]] = [[[] for _ in range(nv)] for _ in range(f)]
    for i in range(f):
        for j, d in J.gradients[i].items():
            grad_r[i][j].append(d)
        for j, d in J.gradients[f + i].items():
            grad_r[i][j].append(-d)
    val_r = [[J.values[i], -J.values[f + i]] for i in range(f)]
    Mvals = dict(zip(upper, J.values[2 * f:], strict=True))
    Mgrads = dict(zip(upper, J.gradients[2 * f:], strict=True))
    for i in range(f):
        for j in range(f):
            a = ydd_s[j]
            if _is_zero(a):
                continue
            key = (min(i, j), max(i, j))
            val_r[i].append(Mvals[key] * a)
            for v, d in Mgrads[key].items():
                grad_r[i][v].append(d * a)

    def total(terms: list[se.Basic]) -> se.Basic:
        return ZERO if not terms else terms[0] if len(terms) == 1 else se.Add(*terms)

    Q = [[total(grad_r[i][v]) for v in range(f)] for i in range(f)]
    P = [[total(grad_r[i][f + v]) for v in range(f)] for i in range(f)]
    B = [[-total(grad_r[i][2 * f + v]) for v in range(m)] for i in range(f)]
    h = [-total(val_r[i]) for i in range(f)]
    Mt = [[ZERO] * f for _ in range(f)]
    for (i, j), v in Mvals.items():
        Mt[i][j] = v
        Mt[j][i] = v
    matrices = {"M_tilde": Mt, "P": P, "Q": Q, "B": B}
    dependence = _time_dependence(system, matrices)
    if not dependence:
        # t may still appear where it cancels (sin²Ωt + cos²Ωt of a symmetric rotor): the
        # matrices equal their values at t = 0, which read shorter
        for name, rows in matrices.items():
            flat = [e for row in rows for e in row]
            if "t" in free_symbol_names(flat):
                vals = iter(jet(flat, [], {t: ZERO}).values)
                matrices[name] = [[next(vals) for _ in row] for row in rows]
        Mt, P, Q, B = (matrices[n] for n in ("M_tilde", "P", "Q", "B"))
    lin = Linearization(
        equations_of_motion=eom, time_dependence=dependence,
        y_s=SymMatrix.column(y_s), yd_s=SymMatrix.column(yd_s), ydd_s=SymMatrix.column(ydd_s),
        u_s=SymMatrix.column(u_s) if m else SymMatrix(()),
        M_tilde=SymMatrix.from_rows(Mt), P=SymMatrix.from_rows(P), Q=SymMatrix.from_rows(Q),
        h=SymMatrix.column(h), B=SymMatrix(tuple(tuple(row) for row in B)),
        switches=J.switches,
    )
    return lin

def _residual_parts(eom: EquationsOfMotion, ydd_nonzero: list[bool]
                    ) -> tuple[list[se.Basic], list[bool], list[tuple[int, int]]]:
    """``k`` (f), ``q`` (f) and the upper triangle of ``M``, with the mask of what needs a
    gradient: M_ij only where ÿ_s,i or ÿ_s,j is not zero."""
    f = eom.system.f
    upper = [(i, j) for i in range(f) for j in range(i, f)]
    exprs = [*eom.k.entries(), *eom.q.entries(), *(eom.M[i, j] for i, j in upper)]
    mask = [True] * (2 * f) + [ydd_nonzero[i] or ydd_nonzero[j] for i, j in upper]
    return exprs, mask, upper


def _time_dependence(system: System, matrices: dict[str, list[list[se.Basic]]]
                     ) -> tuple[str, ...]:
    """Names of the matrices that depend on t. Where t appears in an expression it is tested
    numerically whether it cancels: the matrix at four times, for the default parameter values
    and two random perturbations of them, must agree to 1e-10 relative to its size."""
    rng = np.random.default_rng(7)
    base = system.parameter_values
    trials = [base] + [_perturbed(base, rng) for _ in range(2)]
    out = []
    for name, rows in matrices.items():
        flat = [e for row in rows for e in row]
        if "t" not in free_symbol_names(flat):
            continue
        for values in trials:
            nums = evaluate_float_many(flat, [{**values, "t": tv}
                                              for tv in (0.0, 0.37, 1.91, 4.3)])
            scale = max(1.0, float(np.abs(nums).max()))
            if not np.all(np.isfinite(nums)) or np.ptp(nums, axis=0).max() > 1e-10 * scale:
                out.append(name)
                break
    return tuple(out)
