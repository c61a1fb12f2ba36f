"""The nominal motion of a linearization (``docs/method.md`` §5): y_s(t), ẏ_s, ÿ_s and the
inputs u_s read from the user's description (:func:`_nominal`), and the check that it solves the
equations of motion: ``h = q − k − M·ÿ_s`` against the scale of the forces
(:class:`NominalCheck`, :func:`force_scale`, :func:`term_scale`, :data:`NOMINAL_RTOL`), with a
:class:`NominalMotionWarning` where it does not.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import symengine as se

from ...errors import JourdainError, JourdainWarning, ModelError
from ...graph import evaluate_float, free_symbol_names
from ...model.expressions import as_expr

if TYPE_CHECKING:
    from ...model.system import System


ZERO = se.Integer(0)
HALF = se.Rational(1, 2)


#: ``h`` counts as zero where ``|h_i| ≤ NOMINAL_RTOL·scale_i`` (:class:`NominalCheck`): far
#: above the round-off of evaluating q − k − M·ÿ_s (a few eps of the forces summed), and below
#: the error of a nominal value written with 8 significant digits (``phi = 3.1415927``).
NOMINAL_RTOL = 1e-8


class TimeVariantError(JourdainError):
    """An operation that needs a time-invariant linear system got a time-variant one."""


class NominalMotionWarning(JourdainWarning):
    """A claimed equilibrium or steady motion is not a solution of the equations of motion
    (``h ≠ 0``): the linear system describes the motion near a point the system does not stay
    at, so its eigenvalues and stability verdict are not those of the nominal motion."""


@dataclass(frozen=True)
class NominalCheck:
    """Whether a nominal motion solves the equations of motion: the residual
    ``h = q − k − M·ÿ_s`` at one time against the size of the forces at work there.

    Attributes
    ----------
    h : (f,) array
        The residual (METHOD.md §5).
    scale : (f,) array
        :func:`force_scale` at the nominal state, ``‖J̄_i‖·(‖q̄^c‖ + ‖q̄^e‖ + ‖M̄·J̄·ÿ_s‖)`` with
        ``J̄_i`` the column of coordinate i (which bounds ``|k_i|`` and ``|q_i|``): it stays large
        where the forces balance (a pendulum standing upright, where ``q`` itself is round-off).
        Zeros where h is exactly zero (not evaluated).
    relative : float
        ``max |h_i| / scale_i`` (inf where ``scale_i = 0 < |h_i|``).
    kind : str
        ``"equilibrium"`` (y_s constant), ``"steady motion"`` (ÿ_s = 0, constant rates) or
        ``"nominal motion"``.
    t : float
    nominal : str
        The nominal motion in words (for messages).
    coordinate_names, input_names : tuple of str
    u_s : (m,) array
        The nominal inputs.
    B : (f, m) array
        The input matrix ``∂q/∂u`` at the nominal motion.
    """

    h: np.ndarray
    scale: np.ndarray
    relative: float
    kind: str
    t: float
    nominal: str
    coordinate_names: tuple[str, ...]
    input_names: tuple[str, ...]
    u_s: np.ndarray
    B: np.ndarray

    @property
    def is_solution(self) -> bool:
        """True when ``|h_i| ≤ NOMINAL_RTOL·scale_i`` for every coordinate."""
        return self.relative <= NOMINAL_RTOL

    @property
    def holding_inputs(self) -> dict[str, float] | None:
        """Input values that make h vanish, ``u_s − B⁺·h``, where such values exist (h in the
        range of B); None otherwise or when the system has no inputs."""
        if not self.input_names or self.is_solution:
            return None
        du = np.linalg.lstsq(self.B, -self.h, rcond=None)[0]
        rest = self.h + self.B @ du
        if np.any(np.abs(rest) > NOMINAL_RTOL * np.maximum(self.scale, np.abs(self.h))):
            return None
        return {n: float(v) for n, v in zip(self.input_names, self.u_s + du, strict=True)}

    def message(self) -> str:
        """Why the nominal motion is not a solution, and what would make it one."""
        i = int(np.argmax(np.abs(self.h) / np.where(self.scale > 0, self.scale, 1.0)))
        rel = (f"{abs(self.h[i]) / self.scale[i]:.2g} of the forces at work there"
               if self.scale[i] > 0 else "where no force acts")
        text = (f"the nominal {self.kind} {self.nominal} is not a solution of the equations of "
                f"motion at t = {self.t:g}: h = q - k - M*ydd_s = "
                f"{np.array2string(self.h, precision=4)} is not zero (|h| = {abs(self.h[i]):.4g} "
                f'on "{self.coordinate_names[i]}", {rel}); the linear system describes motions '
                "near a point the system does not stay at, so its eigenvalues and stability "
                "verdict are not those of the nominal motion.")
        hold = self.holding_inputs
        if hold is not None:
            vals = ", ".join(f'"{k}": {v:.6g}' for k, v in hold.items())
            return (text + f" The inputs {{{vals}}} hold it: give them with the nominal motion "
                    f"(system.linearize(nominal, inputs={{{vals}}}), or inputs = {{ ... }} in "
                    "the model file's [nominal.<name>]).")
        if self.input_names:
            return (text + " Give the inputs that hold it with the nominal motion "
                    "(system.linearize(nominal, inputs={...}), or inputs = { ... } in the model "
                    "file's [nominal.<name>]), or correct y_s.")
        return text + " Correct y_s (jourdain.find_equilibrium finds equilibria)."


def force_scale(J_bar: np.ndarray, q_c: np.ndarray, q_e: np.ndarray, k: np.ndarray,
                q: np.ndarray, M_bar: np.ndarray | None = None,
                ydd: np.ndarray | None = None) -> np.ndarray:
    """The size of the generalized forces at work on each coordinate at one state, (f,):
    ``‖J̄_i‖·(‖q̄^c‖ + ‖q̄^e‖ + ‖M̄·J̄·ÿ‖) + |k_i| + |q_i|`` (the last norm where ``M_bar`` and
    ``ydd`` are given). By Cauchy–Schwarz on ``q_i = J̄_iᵀ·q̄^e`` it bounds what the body forces
    and torques could make on coordinate i, so it stays large where they balance (a pendulum
    standing upright, where q itself is round-off): the scale against which h (the nominal
    check) and, in text output, k, q and h (round-off) are judged."""
    forces = np.linalg.norm(q_c) + np.linalg.norm(q_e)
    if M_bar is not None and ydd is not None:
        forces += np.linalg.norm(M_bar @ (J_bar @ ydd))
    return (np.linalg.norm(J_bar, axis=0) * forces + np.abs(np.ravel(k))
            + np.abs(np.ravel(q)))


def term_scale(exprs: list[se.Basic], values: Mapping[str, float], f: int) -> np.ndarray:
    """``Σ|term|`` of the sums ``k_i`` and ``q_i`` (``exprs``: the f entries of k, then the
    f of q) at ``values``, (f,): the size of the separate forces in a coordinate's balance.
    Where forces on one body cancel (gravity held by a preloaded spring), its resultant q̄^e
    in :func:`force_scale` is round-off, and so was the scale a correct nominal equilibrium
    was judged against (the quarter car's h = 4.5e-13 N counted as 8 times the forces)."""
    terms: list[se.Basic] = []
    owner: list[int] = []
    for i, e in enumerate(exprs):
        parts = e.args if isinstance(e, se.Add) else (e,)
        terms.extend(parts)
        owner.extend([i % f] * len(parts))
    out = np.zeros(f)
    if terms:
        np.add.at(out, np.array(owner), np.abs(np.array(evaluate_float(terms, values))))
    return out


def _kind(y_s: list[se.Basic], yd_s: list[se.Basic], ydd_s: list[se.Basic]) -> str:
    if not all(_is_zero(a) for a in ydd_s):
        return "nominal motion"
    return "equilibrium" if all(_is_zero(v) for v in yd_s) else "steady motion"

def _nominal_check(h: np.ndarray, scale: np.ndarray, kind: str, t: float, nominal: str,
                   system: System, u_s: np.ndarray, B: np.ndarray) -> NominalCheck:
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.where(h == 0, 0.0, np.abs(h) / scale)
    return NominalCheck(h=h, scale=scale, relative=float(rel.max(initial=0.0)), kind=kind, t=t,
                        nominal=nominal, coordinate_names=tuple(system.coordinate_names),
                        input_names=tuple(system.input_names), u_s=np.asarray(u_s, float),
                        B=np.asarray(B, float).reshape(system.f, len(system.inputs)))

def _nominal(system: System, nominal: Any, inputs: Mapping[Any, Any] | None = None
             ) -> tuple[list[se.Basic], list[se.Basic]]:
    """Check a nominal motion (and nominal inputs) and return ``y_s`` (f) and ``u_s`` (m) as
    expressions."""
    if hasattr(nominal, "nominal") and not isinstance(nominal, Mapping):
        nominal = nominal.nominal
    if not isinstance(nominal, Mapping):
        raise ModelError(f"nominal motion: expected a mapping from coordinate names to values, "
                         f"got {type(nominal).__name__}")
    if inputs is not None and not isinstance(inputs, Mapping):
        raise ModelError(f"nominal inputs: expected a mapping from input names to values, got "
                         f"{type(inputs).__name__}")
    y_names = system.coordinate_names
    u_names = system.input_names
    not_inputs = [str(k) for k in (inputs or {}) if str(k) not in u_names]
    if not_inputs:
        raise ModelError(f"nominal inputs: {not_inputs} are not inputs of the system; inputs are "
                         f"{u_names}")
    given: dict[str, se.Basic] = {}
    for key, value in [*nominal.items(), *(inputs or {}).items()]:
        name = str(key)
        if name not in y_names and name not in u_names:
            raise ModelError(f'nominal motion: "{name}" is neither a coordinate ({y_names}) nor '
                             f"an input ({u_names})")
        if name in given:
            raise ModelError(f'nominal motion: "{name}" is given twice')
        given[name] = as_expr(value, f'nominal motion of "{name}"')
    missing = [n for n in y_names if n not in given]
    if missing:
        raise ModelError(f"nominal motion: no value for coordinate(s) {missing} (give every "
                         "coordinate, e.g. 0 for an equilibrium at the origin)")
    allowed = {"t"} | {k for k, _ in system.parameters}
    for name, e in given.items():
        bad = free_symbol_names([e]) - allowed
        if bad:
            raise ModelError(
                f'nominal motion of "{name}": unknown symbol(s) {sorted(bad)}; a nominal motion '
                "may depend on t and on the parameters of the system only (declare a speed such "
                "as Omega as a parameter of the System)"
            )
    return [given[n] for n in y_names], [given.get(n, ZERO) for n in u_names]

def _is_zero(e: se.Basic) -> bool:
    return e.is_Number and e == 0

def _perturbed(values: dict[str, float], rng: np.random.Generator) -> dict[str, float]:
    """Random parameter values near the defaults for identity tests; a default of zero (a load
    switched off) is replaced by a random value, so that terms it multiplies are seen."""
    return {k: v * rng.uniform(0.7, 1.3) if v != 0 else rng.uniform(0.2, 1.0)
            for k, v in values.items()}

def _describe(system: System, y_s: list[se.Basic]) -> str:
    text = ", ".join(f"{n} = {e}" for n, e in zip(system.coordinate_names, y_s, strict=True))
    return text if len(text) < 120 else text[:117] + "..."
