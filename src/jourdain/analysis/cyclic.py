"""Cyclic (ignorable) coordinates and the reduced system of Routh.

A coordinate ``y_c`` is *cyclic* when it appears in no equation of motion: ``M``, ``k`` and ``q``
do not depend on it, only on its rate ``ẏ_c`` (the spin angle of a symmetric top, the
precession angle about the direction of gravity, the position of a free cart). Its generalized
momentum is then conserved, and a steady motion in which it turns at a constant rate is a
member of a family of such motions: ``y_c`` drifts (a double zero eigenvalue with a single
eigenvector in the linearization), but that drift is no instability of the motion.

Routh's reduction: in the linearization ``M̃·η̈ + P·η̇ + Q·η = h`` the columns of Q that belong
to cyclic coordinates vanish, so ``η_c`` enters only through ``η̇_c`` and ``η̈_c``. The reduced
state ``[η_r; η̇]`` (η_r the other coordinates, η̇ all rates) obeys

    ẋ_r = A_r·x_r,   A_r = A with the rows and columns of η_c removed

and ``eig A = eig A_r ∪ {0, ..., 0}`` (one zero per cyclic coordinate). The stability verdict
in Routh's sense is the verdict on ``A_r``: stability with respect to the non-cyclic
coordinates and all rates (E. J. Routh, *A Treatise on the Stability of a Given State of
Motion*, 1877; Schiehlen & Eberhard, *Applied Dynamics*, on steady motions).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import EvaluationError, JourdainError
from ..graph import Graph, evaluate_float, free_symbol_names, jet_float
from ..graph.memo import Memo
from ..numeric import mkq_function, parameter_vector
from ..stages.kinematics import kinematics  # the model has no stage methods (issue 16)
from ..stages.linearization.nominal import _perturbed
from ..stages.newton_euler import newton_euler
from ..stages.projection import EquationsOfMotion, projection
from .state_space import ZERO_RTOL

if TYPE_CHECKING:
    from ..model.system import System

#: a derivative ``∂e/∂y_c`` counts as zero below this fraction of the largest value or
#: derivative of M, k, q at the trial state (an identity test: round-off of terms that cancel,
#: such as ∂(sin²φ + cos²φ)/∂φ, is a few eps of their size)
CYCLIC_RTOL = 1e-9


def cyclic_coordinates(source: System | EquationsOfMotion) -> tuple[str, ...]:
    """Names of the cyclic coordinates: those on which ``M``, ``k`` and ``q`` do not depend.

    A coordinate whose symbol does not occur in ``k``, ``q`` and ``J̄`` (``M = J̄ᵀM̄J̄``,
    METHOD.md §3) is cyclic. One that occurs (possibly in terms that cancel,
    ``A·sin²φ + A·cos²φ``) is tested numerically: first by the compiled M, k, q
    (:func:`_screen_compiled`: shifted by three angles at two random states, no entry may
    change); where that cannot decide (no compiler, no real value), by the exact derivatives ``∂k/∂y_c``,
    ``∂q/∂y_c`` and ``∂M/∂y_c = (∂J̄/∂y_c)ᵀM̄J̄ + J̄ᵀM̄(∂J̄/∂y_c)`` (forward mode,
    :func:`jourdain.graph.jet_float`) at two random states and times, at the
    default parameter values and at a random set near them, must vanish to
    :data:`CYCLIC_RTOL` of the largest value or derivative there. The result is a property of
    the model, for all parameter values: it is found once per model (:data:`CYCLIC`, keyed by
    the model's content), not at every ``jd.stability`` call.
    """
    system = source.system if isinstance(source, EquationsOfMotion) else source
    return CYCLIC.get(system, lambda: _find(source))


#: the cyclic coordinates of each model (by content: an equal model built anew is the same key)
CYCLIC: Memo[tuple[str, ...]] = Memo("cyclic coordinates", 128)


def _find(source: System | EquationsOfMotion) -> tuple[str, ...]:

    eom = source if isinstance(source, EquationsOfMotion) else projection(newton_euler(kinematics(source)))
    system = eom.system
    f = system.f
    ne = eom.newton_euler
    n6 = ne.J_bar.shape[0]
    exprs = [*eom.k.entries(), *eom.q.entries(), *ne.J_bar.entries()]
    present = free_symbol_names(exprs)
    names = system.coordinate_names
    candidates = [i for i, n in enumerate(names) if str(system.y[i]) in present]
    cyclic = {i for i in range(f) if i not in candidates}
    if candidates:
        screened = _screen_compiled(system, candidates)
        if screened is not None:  # the compiled M, k, q decided every candidate
            return tuple(names[i] for i in sorted(cyclic | screened))
        graph = Graph(exprs)
        rng = np.random.default_rng(20261123)
        base = system.parameter_values
        still = set(candidates)
        done = 0
        # two trials; a random state where the expressions have no real value (sqrt of a
        # negative number, a singular position) is skipped, at most six are drawn
        for attempt in range(6):
            if done == 2:
                break
            values = dict(base) if attempt == 0 else _perturbed(base, rng)
            values["t"] = float(rng.uniform(0.0, 2.0))
            for syms, lo, hi in ((system.y, -np.pi, np.pi), (system.yd, -1.0, 1.0),
                                 (system.inputs, -1.0, 1.0)):
                values.update({str(s): float(rng.uniform(lo, hi)) for s in syms})
            # after the first trial only the coordinates still in question are differentiated
            remaining = sorted(still)
            try:
                M_bar = np.array(evaluate_float(ne.M_bar.entries(), values)).reshape(n6, n6)
                jet = jet_float(graph, [system.y[i] for i in remaining], values)
            except JourdainError:
                continue
            done += 1
            J = jet.values[2 * f:].reshape(n6, f)
            dJ = jet.jacobian[2 * f:].reshape(n6, f, len(remaining))
            MJ = M_bar @ J
            dM = np.einsum("rjv,rk->jkv", dJ, MJ)
            dM = dM + np.swapaxes(dM, 0, 1)
            terms = np.einsum("rjv,rk->jkv", np.abs(dJ), np.abs(M_bar) @ np.abs(J))
            scale = max(float(np.abs(jet.values[:2 * f]).max(initial=0.0)),
                        float(np.abs(jet.jacobian[:2 * f]).max(initial=0.0)),
                        float((np.abs(J).T @ np.abs(MJ)).max(initial=0.0)),
                        float(terms.max(initial=0.0)), np.finfo(float).tiny)
            column = np.maximum(np.abs(jet.jacobian[:2 * f]).max(axis=0, initial=0.0),
                                np.abs(dM).max(axis=(0, 1), initial=0.0))
            for j, i in enumerate(remaining):
                if not np.isfinite(column[j]) or column[j] > CYCLIC_RTOL * scale:
                    still.discard(i)
            if not still:
                break
        if done:  # no state with numbers: nothing is called cyclic that occurs at all
            cyclic |= still
    return tuple(names[i] for i in sorted(cyclic))


#: shifts of a candidate coordinate in the compiled screen, at each of the random states
SCREEN_SHIFTS = (0.9, -2.1, 2.9)


def _screen_compiled(system: System, candidates: list[int]) -> set[int] | None:
    """The cyclic ones among ``candidates`` by the compiled ``M, k, q`` (the integrator's
    code, compiled once per model and cached on disk), or None where it cannot decide.

    At two random states (coordinates, rates, inputs, time; default and perturbed parameter
    values) each candidate is shifted by :data:`SCREEN_SHIFTS` rad: a cyclic coordinate leaves
    every entry unchanged but for round-off (whatever the shift, a stronger test than a
    derivative at a point), while a coordinate that acts changes some entry by far more than
    :data:`CYCLIC_RTOL` of the largest. This takes microseconds where the exact derivatives of
    the expression graph in Python took 0.3–0.5 s for a 7-joint arm. None (the caller then
    differentiates) when there is no compiler or a state has no real value."""

    try:
        fn = mkq_function(system)
    except JourdainError:
        return None
    f = system.f
    rng = np.random.default_rng(20261123)
    base = system.parameter_values
    still = set(candidates)
    for trial in range(2):
        values = base if trial == 0 else _perturbed(base, rng)
        try:
            p = parameter_vector(system, values)
        except JourdainError:  # perturbed mass data that are not physical: the defaults
            p = parameter_vector(system, base)
        y = rng.uniform(-np.pi, np.pi, f)
        yd = rng.uniform(-1.0, 1.0, f)
        u = rng.uniform(-1.0, 1.0, len(system.inputs))
        t = float(rng.uniform(0.0, 2.0))
        Y = np.repeat(y[None, :], 1 + len(SCREEN_SHIFTS) * len(candidates), axis=0)
        for j, i in enumerate(candidates):
            for k, d in enumerate(SCREEN_SHIFTS):
                Y[1 + j * len(SCREEN_SHIFTS) + k, i] += d
        n = len(Y)
        try:
            out = fn.batch(Y, np.repeat(yd[None, :], n, axis=0), np.full(n, t), p,
                           np.repeat(u[None, :], n, axis=0) if len(u) else None)
        except JourdainError:
            return None
        flat = np.concatenate([out[k].reshape(n, -1) for k in ("M", "k", "q")], axis=1)
        if not np.all(np.isfinite(flat)):
            return None
        scale = max(float(np.abs(flat).max()), np.finfo(float).tiny)
        change = np.abs(flat[1:] - flat[0]).max(axis=1).reshape(len(candidates), -1).max(axis=1)
        for j, i in enumerate(candidates):
            if change[j] > CYCLIC_RTOL * scale:
                still.discard(i)
    return still


def reduced_matrix(A: np.ndarray, coordinate_names: tuple[str, ...] | list[str],
                   cyclic: tuple[str, ...] | list[str]) -> np.ndarray:
    """``A_r``: the state matrix for ``[η_r; η̇]`` with the rows and columns of the cyclic
    coordinates' positions removed (see the module docstring). ``A`` is (2f, 2f)."""
    names = list(coordinate_names)
    f = len(names)
    drop = {names.index(c) for c in cyclic}
    keep = [i for i in range(2 * f) if i not in drop]
    return A[np.ix_(keep, keep)]


def check_cyclic(A: np.ndarray, coordinate_names: tuple[str, ...] | list[str],
                 cyclic: Any) -> tuple[str, ...]:
    """The names in ``cyclic``, checked: each must be a coordinate, and its position must not
    act on the motion at this nominal motion (the column of ``A`` of ``η_c`` is zero to
    round-off of A). Raises :class:`jourdain.errors.EvaluationError` otherwise."""

    names = list(coordinate_names)
    out = []
    scale = max(1.0, float(np.abs(A).max(initial=0.0)))
    for c in cyclic:
        c = str(c)
        if c not in names:
            raise EvaluationError(f'cyclic: "{c}" is not a coordinate; coordinates are '
                                  f"{', '.join(names)}")
        col = np.abs(A[:, names.index(c)]).max(initial=0.0)
        if col > ZERO_RTOL * scale:
            raise EvaluationError(
                f'cyclic: the coordinate "{c}" is not cyclic here: its deviation acts on the '
                f"motion (largest entry {col:.3g} in its column of A); a cyclic coordinate "
                "appears in no equation of motion, only its rate")
        if c not in out:
            out.append(c)
    return tuple(c for c in names if c in out)
