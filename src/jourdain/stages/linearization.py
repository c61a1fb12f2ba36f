"""Linearization about a nominal motion (METHOD.md §5) and its physical split (§6).

With ``y = y_s(t) + η`` and inputs ``u = u_s(t) + Δu``, the equations of motion
``M(y,t)·ÿ + k(y,ẏ,t) = q(y,ẏ,u,t)`` become, to first order in ``η`` and ``Δu``,

    M̃(t)·η̈ + P(t)·η̇ + Q(t)·η = h(t) + B(t)·Δu

    M̃ = M|_s                         P = (∂k/∂ẏ − ∂q/∂ẏ)|_s
    Q = (∂(M·ÿ_s)/∂y + ∂k/∂y − ∂q/∂y)|_s
    h = (q − k − M·ÿ_s)|_s             B = ∂q/∂u|_s

All are the value and the gradient of the residual ``r = M·ÿ + k − q`` at the nominal point:
``Q = ∂r/∂y``, ``P = ∂r/∂ẏ``, ``B = −∂r/∂u`` and ``h = −r``, with ``ÿ`` replaced by ``ÿ_s``
(which gives the position term ``∂(M·ÿ_s)/∂y`` of the note in METHOD.md §5). k, q and the
entries of M are differentiated in one forward-mode pass over their shared expression graph with
the nominal motion substituted on the way (:func:`jourdain.graph.jet`), the gradients of
M only where ÿ_s ≠ 0. M is never inverted.

Three forms: :func:`linearization` (symbolic in the parameters, about a given nominal motion),
:func:`linearization_general` (symbolic functions of the state: the general form), and
:func:`linearize_numeric` (numbers for given parameter values: the fast path to eigenvalues of
large systems).

For a time-invariant result (M̃, P, Q, B free of t) the matrices split into damping ``D``,
gyroscopic ``G``, stiffness ``K`` and circulatory ``N`` parts (§6):
``D = ½(P + Pᵀ)``, ``G = ½(P − Pᵀ)``, ``K = ½(Q + Qᵀ)``, ``N = ½(Q − Qᵀ)``.

A nominal motion may set the inputs too (``u_s``: the motor torque that keeps a rotor turning
against its damping, the force that holds an arm in its pose). Where an equilibrium or a steady
motion (ÿ_s = 0) leaves ``h ≠ 0`` it is not a solution of the equations of motion: the
linearization says so with a :class:`NominalMotionWarning` (:meth:`Linearization.check_nominal`,
:class:`NominalCheck`), and so does the stability verdict built on it.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import symengine as se

from ..errors import EvaluationError, JourdainError, JourdainWarning, ModelError, warn
from ..graph import Graph, evaluate_float, free_symbol_names, jet, jet_float
from ..model.expressions import as_expr
from ..symbolic import SymMatrix
from .kinematics import kinematics  # the model has no stage methods (issue 16)
from .newton_euler import newton_euler
from .projection import projection

if TYPE_CHECKING:
    from ..model.system import System
    from ..numeric import CompiledFunction
    from .projection import EquationsOfMotion

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


@dataclass(frozen=True)
class Linearization:
    """Result of :func:`linearization`: ``M̃·η̈ + P·η̇ + Q·η = h + B·Δu`` (METHOD.md §5).

    Attributes
    ----------
    equations_of_motion : EquationsOfMotion
        The stage it came from.
    y_s, yd_s, ydd_s : SymMatrix (f×1)
        The nominal motion, its velocity and acceleration (expressions in ``t`` and the
        parameters).
    u_s : SymMatrix (m×1)
        Nominal inputs (zero unless given).
    M_tilde : SymMatrix (f×f)
        ``M(y_s, t)``, symmetric.
    P : SymMatrix (f×f)
        Velocity matrix ``(∂k/∂ẏ − ∂q/∂ẏ)|_s``.
    Q : SymMatrix (f×f)
        Position matrix ``(∂(M·ÿ_s)/∂y + ∂k/∂y − ∂q/∂y)|_s``.
    h : SymMatrix (f×1)
        Excitation ``(q − k − M·ÿ_s)|_s``: zero when the nominal motion solves the equations of
        motion.
    B : SymMatrix (f×m)
        Input matrix ``∂q/∂u|_s`` for the input deviations ``Δu`` (m = number of inputs).
    time_dependence : tuple of str
        Names of the matrices among M̃, P, Q, B that depend on t (empty for a time-invariant
        result). Where t appears but cancels (a symmetric rotor turning at Ω t), numeric tests
        at several times and parameter values decide, and the matrices are stored at t = 0.
    """

    equations_of_motion: EquationsOfMotion
    y_s: SymMatrix
    yd_s: SymMatrix
    ydd_s: SymMatrix
    u_s: SymMatrix
    M_tilde: SymMatrix
    P: SymMatrix
    Q: SymMatrix
    h: SymMatrix
    B: SymMatrix
    time_dependence: tuple[str, ...]

    # --- context -----------------------------------------------------------------------------
    @property
    def system(self) -> System:
        return self.equations_of_motion.system

    @property
    def f(self) -> int:
        return self.system.f

    @property
    def nominal(self) -> dict[str, se.Basic]:
        """The nominal motion by coordinate name (and nominal inputs by input name)."""
        out = {n: self.y_s[i] for i, n in enumerate(self.system.coordinate_names)}
        out.update({n: self.u_s[i] for i, n in enumerate(self.system.input_names)})
        return out

    # --- time dependence and the split of §6 ---------------------------------------------------
    @property
    def is_time_invariant(self) -> bool:
        """True when M̃, P, Q and B do not depend on t (h may: a time-dependent excitation)."""
        return not self.time_dependence

    def _require_time_invariant(self, what: str) -> None:
        dep = self.time_dependence
        if dep:
            raise TimeVariantError(
                f"{what}: the linearization about the nominal motion "
                f"{_describe_nominal(self)} is time-variant ({', '.join(dep)} depend on t); the "
                "split into D, G, K, N (METHOD.md §6) holds for time-invariant systems only. "
                "Use M_tilde, P, Q, h as functions of t (evaluate(t=...))."
            )

    @property
    def D(self) -> SymMatrix:
        """Damping matrix ``D = ½(P + Pᵀ)`` (symmetric); time-invariant results only."""
        self._require_time_invariant("D")
        return _sym_part(self.P, +1)

    @property
    def G(self) -> SymMatrix:
        """Gyroscopic matrix ``G = ½(P − Pᵀ)`` (skew-symmetric); time-invariant results only."""
        self._require_time_invariant("G")
        return _sym_part(self.P, -1)

    @property
    def K(self) -> SymMatrix:
        """Stiffness matrix ``K = ½(Q + Qᵀ)`` (symmetric); time-invariant results only."""
        self._require_time_invariant("K")
        return _sym_part(self.Q, +1)

    @property
    def N(self) -> SymMatrix:
        """Circulatory matrix ``N = ½(Q − Qᵀ)`` (skew-symmetric); time-invariant results only."""
        self._require_time_invariant("N")
        return _sym_part(self.Q, -1)

    @property
    def is_conservative(self) -> bool:
        """True when ``D = 0``, ``N = 0`` and ``h = 0`` (METHOD.md §6).

        Entries that are not zero as written are tested numerically (an identity test): at the
        default parameter values and at two random perturbations of them (each value scaled by a
        factor in [0.7, 1.3], zeros replaced by values in [0.2, 1]), and for h at several times.
        It is a property of the symbolic system, for all parameter values; "zero" means below
        1e-9 relative to the size of M̃, P, Q. Time-invariant results only.
        """
        self._require_time_invariant("is_conservative")
        names = ("D", "N", "h")
        exprs = {"D": self.D.entries(), "N": self.N.entries(), "h": self.h.entries()}
        if all(e.is_Number and e == 0 for n in names for e in exprs[n]):
            return True
        rng = np.random.default_rng(20240601)
        base = self.system.parameter_values
        trials = [base] + [_perturbed(base, rng) for _ in range(2)]
        times = (0.0, 0.37, 1.91) if "t" in free_symbol_names(exprs["h"]) else (0.0,)
        for values in trials:
            for t in times:
                num = self.evaluate(t=t, parameters=values)
                scale = max(1.0, np.abs(num["P"]).max(), np.abs(num["Q"]).max(),
                            np.abs(num["M_tilde"]).max())
                for n in names:
                    if np.abs(num[n]).max(initial=0.0) > 1e-9 * scale:
                        return False
        return True

    # --- does the nominal motion solve the equations of motion? -------------------------------
    def check_nominal(self, t: float = 0.0,
                      parameters: Mapping[str, float] | None = None) -> NominalCheck:
        """``h`` at time ``t`` against the forces at work at the nominal state
        (:class:`NominalCheck`; ``check.is_solution``, ``check.message()``)."""
        from ..numeric import parameter_vector, time_value

        system = self.system
        f, m = system.f, len(system.inputs)
        tv = time_value(t)
        p = parameter_vector(system, parameters)
        values = {str(s): float(v) for s, v in zip(system.parameter_symbols, p, strict=True)}
        values["t"] = tv
        nums = np.array(evaluate_float(
            [*self.y_s.entries(), *self.yd_s.entries(), *self.ydd_s.entries(),
             *self.u_s.entries(), *self.h.entries(), *self.B.entries()], values))
        ys, yds, ydds, us, h = (nums[:f], nums[f:2 * f], nums[2 * f:3 * f],
                                nums[3 * f:3 * f + m], nums[3 * f + m:4 * f + m])
        B = nums[4 * f + m:].reshape(f, m)
        scale = np.zeros(f)
        if np.any(h != 0):
            ne = self.equations_of_motion.newton_euler
            state = dict(values)
            for syms, vals in ((system.y, ys), (system.yd, yds), (system.inputs, us)):
                state.update({str(s): float(v) for s, v in zip(syms, vals, strict=True)})
            # k = J̄ᵀq̄^c and q = J̄ᵀq̄^e add nothing to the bound (Cauchy–Schwarz); M̄ (36p²
            # entries) only where the nominal motion accelerates
            mats = (ne.J_bar, ne.q_c, ne.q_e, *((ne.M_bar,) if np.any(ydds != 0) else ()))
            flat = np.array(evaluate_float([e for mat in mats for e in mat.entries()], state))
            parts, i = [], 0
            for mat in mats:
                r, c = mat.shape
                parts.append(flat[i:i + r * c].reshape(r, c))
                i += r * c
            zero = np.zeros(f)
            scale = force_scale(parts[0], parts[1][:, 0], parts[2][:, 0], zero, zero,
                                parts[3] if len(parts) > 3 else None, ydds)
            if np.any(np.abs(h) > NOMINAL_RTOL * scale):  # forces that cancel within a body?
                eom = self.equations_of_motion
                scale = scale + term_scale([*eom.k.entries(), *eom.q.entries()], state, f)
        return _nominal_check(h, scale, _kind(self.y_s.entries(), self.yd_s.entries(),
                                              self.ydd_s.entries()),
                              tv, _describe_nominal(self), system, us, B)

    # --- numbers -----------------------------------------------------------------------------
    def evaluate(self, t: float = 0.0,
                 parameters: Mapping[str, float] | None = None) -> dict[str, np.ndarray]:
        """NumPy arrays of ``M_tilde, P, Q, h, B`` (h 1-D) at time ``t``, and of ``D, G, K, N``
        for a time-invariant result (for a time-variant one these keys are left out).

        ``parameters`` overrides default parameter values by name. One evaluation walks the
        expression graph once in floating point (no compilation); for many evaluations use
        :meth:`compile`.
        """
        from ..numeric import parameter_vector, time_value

        tv = time_value(t)
        p = parameter_vector(self.system, parameters)
        values = {str(s): float(v) for s, v in zip(self.system.parameter_symbols, p, strict=True)}
        values["t"] = tv
        blocks = self._blocks()
        flat = [e for m in blocks.values() for e in m.entries()]
        try:
            nums = evaluate_float(flat, values)
        except EvaluationError:
            raise
        except JourdainError as exc:
            raise EvaluationError(f"linearization of {self.system.name!r} at t = {tv}: "
                                  f"{exc}") from None
        out: dict[str, np.ndarray] = {}
        i = 0
        for name, m in blocks.items():
            n, c = m.shape
            out[name] = np.asarray(nums[i:i + n * c], dtype=float).reshape(n, c)
            i += n * c
        return self._finish(out)

    def compile(self) -> CompiledLinearization:
        """Machine code for ``M_tilde, P, Q, h, B`` as functions of t and the parameters
        (:func:`jourdain.numeric.lambdify`), for repeated evaluation (sweeps, time-variant
        systems)."""
        from ..numeric import lambdify

        return CompiledLinearization(self, lambdify(self.system, self._blocks()))

    def _blocks(self) -> dict[str, SymMatrix]:
        out = {"M_tilde": self.M_tilde, "P": self.P, "Q": self.Q, "h": self.h}
        if self.system.inputs:
            out["B"] = self.B
        return out

    def _finish(self, out: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        bad = [k for k, v in out.items() if not np.all(np.isfinite(v))]
        if bad:
            raise EvaluationError(f"the linearization has non-finite entries in {bad} at these "
                                  "parameter values (a singular position of the nominal motion?)")
        out["h"] = out["h"].reshape(-1)
        if "B" not in out:
            out["B"] = np.zeros((self.f, 0))
        if self.is_time_invariant:
            P, Q = out["P"], out["Q"]
            out["D"] = 0.5 * (P + P.T)
            out["G"] = 0.5 * (P - P.T)
            out["K"] = 0.5 * (Q + Q.T)
            out["N"] = 0.5 * (Q - Q.T)
        return out

    def __repr__(self) -> str:
        kind = "time-invariant" if self.is_time_invariant else "time-variant"
        return (f"Linearization({self.system.name!r} about {_describe_nominal(self)}: f={self.f}, "
                f"inputs={self.system.input_names}, {kind})")


@dataclass(frozen=True)
class CompiledLinearization:
    """Compiled ``M_tilde, P, Q, h, B`` of a :class:`Linearization`; call with ``(t,
    parameters)`` for the same dict as :meth:`Linearization.evaluate`."""

    linearization: Linearization
    function: CompiledFunction

    def __call__(self, t: float = 0.0,
                 parameters: Mapping[str, float] | None = None) -> dict[str, np.ndarray]:
        from ..numeric import parameter_vector, time_value

        system = self.linearization.system
        p = parameter_vector(system, parameters)
        f = system.f
        out = self.function(np.zeros(f), np.zeros(f), time_value(t), p, np.zeros(len(system.inputs)))
        return self.linearization._finish(dict(out))


def _nominal_check(h: np.ndarray, scale: np.ndarray, kind: str, t: float, nominal: str,
                   system: System, u_s: np.ndarray, B: np.ndarray) -> NominalCheck:
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.where(h == 0, 0.0, np.abs(h) / scale)
    return NominalCheck(h=h, scale=scale, relative=float(rel.max(initial=0.0)), kind=kind, t=t,
                        nominal=nominal, coordinate_names=tuple(system.coordinate_names),
                        input_names=tuple(system.input_names), u_s=np.asarray(u_s, float),
                        B=np.asarray(B, float).reshape(system.f, len(system.inputs)))


def _warn_if_not_solution(lin: Linearization) -> None:
    """A :class:`NominalMotionWarning` when a claimed equilibrium or steady motion leaves
    h ≠ 0 at t = 0 for the default parameter values (a reference trajectory with ÿ_s ≠ 0 is
    not checked: h is its feed-forward)."""
    try:
        result = lin.check_nominal()
    except JourdainError:  # no numbers at the default parameter values: evaluate() will say
        return
    if result.kind != "nominal motion" and not result.is_solution:
        warn(result.message(), NominalMotionWarning)


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
        t = 0 for the default parameter values (:meth:`Linearization.check_nominal`).
    """
    system = eom.system
    y_s, u_s = _nominal(system, nominal, inputs)
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
    )
    _warn_if_not_solution(lin)
    return lin


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


def _residual_parts(eom: EquationsOfMotion, ydd_nonzero: list[bool]
                    ) -> tuple[list[se.Basic], list[bool], list[tuple[int, int]]]:
    """``k`` (f), ``q`` (f) and the upper triangle of ``M``, with the mask of what needs a
    gradient: M_ij only where ÿ_s,i or ÿ_s,j is not zero."""
    f = eom.system.f
    upper = [(i, j) for i in range(f) for j in range(i, f)]
    exprs = [*eom.k.entries(), *eom.q.entries(), *(eom.M[i, j] for i, j in upper)]
    mask = [True] * (2 * f) + [ydd_nonzero[i] or ydd_nonzero[j] for i, j in upper]
    return exprs, mask, upper


def _is_zero(e: se.Basic) -> bool:
    return e.is_Number and e == 0


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
            nums = np.array([evaluate_float(flat, {**values, "t": tv})
                             for tv in (0.0, 0.37, 1.91, 4.3)])
            scale = max(1.0, float(np.abs(nums).max()))
            if not np.all(np.isfinite(nums)) or np.ptp(nums, axis=0).max() > 1e-10 * scale:
                out.append(name)
                break
    return tuple(out)


def _perturbed(values: dict[str, float], rng: np.random.Generator) -> dict[str, float]:
    """Random parameter values near the defaults for identity tests; a default of zero (a load
    switched off) is replaced by a random value, so that terms it multiplies are seen."""
    return {k: v * rng.uniform(0.7, 1.3) if v != 0 else rng.uniform(0.2, 1.0)
            for k, v in values.items()}


def _sym_part(A: SymMatrix, sign: int) -> SymMatrix:
    n = A.shape[0]
    rows = [[ZERO] * n for _ in range(n)]
    for i in range(n):
        for j in range(n):
            a, b = A[i, j], A[j, i]
            e = a + b if sign > 0 else a - b
            rows[i][j] = ZERO if e.is_Number and e == 0 else HALF * e
    return SymMatrix.from_rows(rows)


def _describe_nominal(lin: Linearization) -> str:
    return _describe(lin.system, lin.y_s.entries())


def _describe(system: System, y_s: list[se.Basic]) -> str:
    text = ", ".join(f"{n} = {e}" for n, e in zip(system.coordinate_names, y_s, strict=True))
    return text if len(text) < 120 else text[:117] + "..."



@dataclass(frozen=True)
class NumericLinearization:
    """``M̃·η̈ + P·η̇ + Q·η = h + B·Δu`` in numbers, at one time and for given parameter values
    (:func:`linearize_numeric`): the fast path for eigen-analysis of large systems, which skips
    the symbolic matrices.

    Attributes
    ----------
    system : System
    M_tilde, P, Q : (f, f) arrays
    h : (f,) array
    B : (f, m) array
    t : float
    parameters : dict
        All parameter values used.
    time_dependence : tuple of str
        Names of the matrices among M̃, P, Q, B that change with t (tested at three times where
        t appears at all).
    nominal_check : NominalCheck or None
        Whether the nominal motion solves the equations of motion at ``t``
        (:meth:`check_nominal`).
    equations_of_motion : EquationsOfMotion or None
        The stage it came from (for the cyclic coordinates of a stability verdict).
    """

    system: System
    M_tilde: np.ndarray
    P: np.ndarray
    Q: np.ndarray
    h: np.ndarray
    B: np.ndarray
    t: float
    parameters: dict[str, float]
    time_dependence: tuple[str, ...]
    nominal_check: NominalCheck | None = None
    equations_of_motion: EquationsOfMotion | None = field(default=None, repr=False,
                                                          compare=False)

    @property
    def is_time_invariant(self) -> bool:
        return not self.time_dependence

    def check_nominal(self, t: float | None = None,
                      parameters: Mapping[str, float] | None = None) -> NominalCheck:
        """``h`` against the forces at work at the nominal state (:class:`NominalCheck`), at
        the one time and parameter values of this result."""
        if (t is not None and float(t) != self.t) or parameters:
            raise EvaluationError("a NumericLinearization holds numbers for one t and one set "
                                  "of parameters; call linearize_numeric again for others")
        if self.nominal_check is None:
            raise EvaluationError("this NumericLinearization was built without the check of its "
                                  "nominal motion; linearize_numeric makes one with it")
        return self.nominal_check

    def _split(self, what: str, A: np.ndarray, sign: int) -> np.ndarray:
        if self.time_dependence:
            raise TimeVariantError(f"{what}: the linearization is time-variant "
                                   f"({', '.join(self.time_dependence)} depend on t)")
        return 0.5 * (A + sign * A.T)

    @property
    def D(self) -> np.ndarray:
        return self._split("D", self.P, +1)

    @property
    def G(self) -> np.ndarray:
        return self._split("G", self.P, -1)

    @property
    def K(self) -> np.ndarray:
        return self._split("K", self.Q, +1)

    @property
    def N(self) -> np.ndarray:
        return self._split("N", self.Q, -1)

    def evaluate(self, t: float | None = None,
                 parameters: Mapping[str, float] | None = None) -> dict[str, np.ndarray]:
        """The arrays as a dict (like :meth:`Linearization.evaluate`); they exist for one time
        and one set of parameters only, so other values are refused."""
        if (t is not None and float(t) != self.t) or parameters:
            raise EvaluationError("a NumericLinearization holds numbers for one t and one set "
                                  "of parameters; call linearize_numeric again for others")
        out = {"M_tilde": self.M_tilde, "P": self.P, "Q": self.Q, "h": self.h, "B": self.B}
        if self.is_time_invariant:
            out.update(D=self.D, G=self.G, K=self.K, N=self.N)
        return out


def linearize_numeric(source: System | EquationsOfMotion, nominal: Mapping[Any, Any] | Any,
                      t: float = 0.0,
                      parameters: Mapping[str, float] | None = None,
                      inputs: Mapping[Any, Any] | None = None) -> NumericLinearization:
    """M̃, P, Q, h, B as numbers for given parameter values, by forward-mode differentiation in
    floating point over the graphs of k, q and J̄ (:func:`jourdain.graph.jet_float`),
    with ``M̃ = J̄ᵀ·M̄·J̄`` in numbers.

    Same equations, nominal motions, nominal inputs and :class:`NominalMotionWarning` as
    :func:`linearization` (here at ``t`` and for ``parameters``), without forming symbolic
    matrices: the way to eigenvalues of large systems (a spatial chain of 16 bodies in well
    under a second, derivation included).
    """
    from ..numeric import parameter_vector, time_value
    from .projection import EquationsOfMotion

    eom = source if isinstance(source, EquationsOfMotion) else projection(newton_euler(kinematics(source)))
    system = eom.system
    tv = time_value(t)
    y_s, u_s = _nominal(system, nominal, inputs)
    ts = system.t
    yd_s = [se.diff(e, ts) for e in y_s]
    ydd_s = [se.diff(e, ts) for e in yd_s]
    p = parameter_vector(system, parameters)
    pars = {str(s): float(v) for s, v in zip(system.parameter_symbols, p, strict=True)}
    nominal_exprs = [*y_s, *yd_s, *ydd_s, *u_s]
    nominal_has_t = "t" in free_symbol_names(nominal_exprs)
    ydd_nonzero = [not _is_zero(a) for a in ydd_s]
    f, m = system.f, len(system.inputs)
    # M = J̄ᵀ·M̄·J̄ (METHOD.md §3) is formed in numbers from J̄: the graph of J̄ is a fraction of
    # the graph of M's f(f+1)/2 entries, and M̄ holds parameters only
    ne = eom.newton_euler
    J_bar = ne.J_bar.entries()
    n6 = ne.J_bar.shape[0]
    M_bar = evaluate_float(ne.M_bar.entries(), pars)  # raises if M̄ depended on more
    M_bar = np.array(M_bar).reshape(n6, n6)
    # q̄^c and q̄^e (values only) give the scale of the forces for the check of h
    exprs = [*eom.k.entries(), *eom.q.entries(), *J_bar, *ne.q_c.entries(), *ne.q_e.entries()]
    mask = [True] * (2 * f) + [any(ydd_nonzero)] * len(J_bar) + [False] * (2 * n6)
    graph = Graph(exprs)
    variables = [*system.y, *system.yd, *system.inputs]
    nv = len(variables)

    def at(time: float) -> dict[str, np.ndarray]:
        values = {**pars, "t": time}
        nums = evaluate_float(nominal_exprs, values)
        ys, yds, ydds, us = (nums[:f], nums[f:2 * f], np.array(nums[2 * f:3 * f]),
                             nums[3 * f:])
        values.update({str(s): v for s, v in zip(system.y, ys, strict=True)})
        values.update({str(s): v for s, v in zip(system.yd, yds, strict=True)})
        values.update({str(s): v for s, v in zip(system.inputs, us, strict=True)})
        J = jet_float(graph, variables, values, mask)
        nJ = 2 * f + n6 * f
        Jb = J.values[2 * f:nJ].reshape(n6, f)
        MJ = M_bar @ Jb
        Mt = Jb.T @ MJ
        Mt = 0.5 * (Mt + Mt.T)
        # r = M·ÿ_s + k − q
        r = Mt @ ydds + J.values[:f] - J.values[f:2 * f]
        dr = J.jacobian[:f] - J.jacobian[f:2 * f]
        if np.any(ydds != 0.0):
            # ∂(J̄ᵀM̄J̄·ÿ_s)/∂y_v = (∂J̄/∂y_v)ᵀ·M̄J̄ÿ_s + J̄ᵀM̄·(∂J̄/∂y_v)·ÿ_s
            dJ = J.jacobian[2 * f:nJ].reshape(n6, f, nv)
            dJa = np.einsum("rjv,j->rv", dJ, ydds)
            dr = dr + np.einsum("rjv,r->jv", dJ, MJ @ ydds) + MJ.T @ dJa
        scale = force_scale(Jb, J.values[nJ:nJ + n6], J.values[nJ + n6:], J.values[:f],
                            J.values[f:2 * f], M_bar, ydds)
        if np.any(np.abs(r) > NOMINAL_RTOL * scale):  # forces that cancel within a body?
            scale = scale + term_scale(exprs[:2 * f], values, f)
        return {"M_tilde": Mt, "Q": dr[:, :f], "P": dr[:, f:2 * f],
                "B": -dr[:, 2 * f:2 * f + m], "h": -r, "h_scale": scale,
                "u_s": np.array(us, dtype=float)}

    out = at(tv)
    dependence: tuple[str, ...] = ()
    if nominal_has_t or "t" in graph.symbol_names():
        others = [at(tv + dt) for dt in (0.37, 1.91)]
        dependence = tuple(
            n for n in ("M_tilde", "P", "Q", "B")
            if any(np.abs(o[n] - out[n]).max(initial=0.0)
                   > 1e-10 * max(1.0, np.abs(out[n]).max(initial=0.0)) for o in others))
    for name, arr in out.items():
        if not np.all(np.isfinite(arr)):
            raise EvaluationError(f"the linearization has non-finite entries in {name}")
    check = _nominal_check(out["h"], np.where(out["h"] == 0, 0.0, out["h_scale"]),
                           _kind(y_s, yd_s, ydd_s), tv, _describe(system, y_s), system,
                           out["u_s"], out["B"])
    if check.kind != "nominal motion" and not check.is_solution:
        warn(check.message(), NominalMotionWarning)
    return NumericLinearization(system=system, M_tilde=out["M_tilde"], P=out["P"], Q=out["Q"],
                                h=out["h"], B=out["B"], t=tv, parameters=pars,
                                time_dependence=dependence, nominal_check=check,
                                equations_of_motion=eom)


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

    @property
    def system(self) -> System:
        return self.equations_of_motion.system

    def evaluate(self, y: Any, yd: Any, ydd: Any, t: float = 0.0,
                 parameters: Mapping[str, float] | None = None,
                 inputs: Mapping[str, float] | None = None) -> dict[str, np.ndarray]:
        """Arrays of ``M_tilde, P, Q, h, B`` at one state."""
        from ..numeric import state_vectors

        system = self.system
        yv, ydv, tv, pv, uv = state_vectors(system, y, yd, t, parameters, inputs)
        yddv = np.asarray(ydd, dtype=float).reshape(-1)
        if yddv.size != system.f or not np.all(np.isfinite(yddv)):
            raise EvaluationError(f"ydd must be {system.f} finite numbers")
        values = {"t": tv}
        for syms, vals in ((system.y, yv), (system.yd, ydv), (system.ydd, yddv),
                           (system.parameter_symbols, pv), (system.inputs, uv)):
            values.update({str(s): float(v) for s, v in zip(syms, vals, strict=True)})
        mats = {"M_tilde": self.M_tilde, "P": self.P, "Q": self.Q, "h": self.h, "B": self.B}
        flat = [e for m in mats.values() for e in m.entries()]
        nums = iter(evaluate_float(flat, values))
        out = {}
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
    )
