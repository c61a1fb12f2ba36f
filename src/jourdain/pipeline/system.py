"""``jourdain.System``: the model description with the stages of the method as cached methods.

Each symbolic stage runs at most once per system and is kept on the instance (the system is
immutable, so are the stages' results): ``kinematics`` (``docs/method.md`` §2),
``newton_euler`` (§3), ``equations_of_motion`` (§4, the projection), ``reactions`` (§4). The
numeric methods (``evaluate``, ``linearize``, ``simulate``) call the memoized compiled code of
:mod:`jourdain.numeric`. The kept stages belong to one process: a pickled system (sent to a
study's worker) travels without them and derives its own, and a lock per system makes
concurrent first calls from threads compute each stage once.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np

from ..errors import ModelError, refuse_closed
from ..model.system import System as Model
from ..numeric import evaluate as evaluate_eom
from ..simulation.results import Results
from ..simulation.simulate import DEFAULT_ATOL, DEFAULT_METHOD, DEFAULT_RTOL, simulate
from ..stages.constraints import Constraints, constraints
from ..stages.kinematics import Kinematics, kinematics
from ..stages.newton_euler import NewtonEuler, newton_euler
from ..stages.projection import EquationsOfMotion, projection
from ..stages.reactions import Reactions, reactions

if TYPE_CHECKING:
    # imported where used: a closed system's linearizations (jourdain.loops loads SciPy), and
    # the analysis, the linearization and the derivatives, which building a system and
    # simulating it do not need (a script that does only that waits for every module it
    # imports: issue 35)
    from ..loops.derivatives import ClosedDerivatives
    from ..loops.linearization import LoopLinearization
    from ..loops.periodic import ClosedLinearization
    from ..numeric.derivatives import Derivatives
    from ..numeric.linearization import Linearization

_T = TypeVar("_T")


def derivatives(system: Model) -> Derivatives | ClosedDerivatives:
    """The first derivatives of ``system``'s dynamics per state.

    A tree: compiled (:func:`jourdain.numeric.derivatives.derivatives`): ``.forward(y, yd, u)``
    gives ÿ, ∂ÿ/∂y, ∂ÿ/∂ẏ, ∂ÿ/∂u; ``.inverse(y, yd, ydd, u)`` gives τ = M·ÿ + k − q and its
    derivatives; one state or a batch in one call; ``.export_c(folder)`` the C sources. A
    closed system (closing joints, contacts, speeds of its own): in its state ``x = (y_i, z)``
    by the complex step (:mod:`jourdain.loops.derivatives`), ``.forward(y, yd, u)`` gives ẋ,
    ∂ẋ/∂x, ∂ẋ/∂u and ``.inverse(y, yd, zd, u)`` τ = M·ż + k − q and its derivatives."""
    if system.is_closed:
        from ..loops.derivatives import closed_derivatives

        return closed_derivatives(system)
    from ..numeric.derivatives import derivatives as compiled_derivatives

    return compiled_derivatives(system)
_LOCKS = threading.Lock()  # guards the creation of the per-system locks


class System(Model):
    """A multibody system with the method's stages as methods, each computed once and kept.

    Built as :class:`jourdain.model.System` (the same parameters: ``coordinates``, ``bodies``,
    ``forces``, ``parameters``, ``inputs``, ``units``, ``name``; the same checks):

    >>> import jourdain as jd
    >>> from jourdain.models import double_pendulum
    >>> system = double_pendulum()          # a jourdain.System
    >>> eom = system.equations_of_motion()  # M·ÿ + k = q, derived once
    >>> eom is system.equations_of_motion()
    True

    Methods: :meth:`kinematics`, :meth:`newton_euler`, :meth:`equations_of_motion`,
    :meth:`reactions` (symbolic, kept), :meth:`linearize`, :meth:`evaluate`, :meth:`simulate`,
    :meth:`derivatives`.
    Equal to another ``jourdain.System`` with the same description; the kept stages take no
    part in equality, hashing or pickling.
    """

    def _stage(self, key: str, compute: Callable[[], _T]) -> _T:
        d = self.__dict__
        if key in d:
            return d[key]  # the value compute() stored
        with _LOCKS:
            lock = d.setdefault("_lock", threading.RLock())
        with lock:  # reentrant: equations_of_motion asks for newton_euler inside its own
            if key not in d:
                d[key] = compute()
            return d[key]

    def kinematics(self) -> Kinematics:
        """Kinematics of every body (METHOD §1); see :func:`jourdain.stages.kinematics.kinematics`.
        A closed system's bodies move as its tree's: the tree's kinematics (``.system`` is
        :attr:`tree`)."""
        if self.closing or self.is_general:
            return self.tree.kinematics()
        return self._stage("_kinematics", lambda: kinematics(self))

    def constraints(self) -> Constraints:
        """The constraint stage (METHOD §7): the closing joints' rows Φ, Φ_y, Φ_t, c and their
        constrained directions Q̄_c; zero rows for a tree. See
        :func:`jourdain.stages.constraints.constraints`."""
        return self._stage("_constraints",
                           lambda: constraints(self.tree.kinematics(), self.closing,
                                               self.contacts))

    def _symbolic(self, stage: str) -> None:
        refuse_closed(self, f"the symbolic {stage} of a closed system need its velocity map "
                      "ẏ = L·ẏ_i + l, which exists in numbers only (coordinate partitioning at "
                      "a configuration)",
                      f"system.evaluate(y, yd) gives J̄ = J̄_tree·L, M, k, q and the reactions "
                      f"in numbers; system.constraints() gives Φ, Φ_y; "
                      f"system.tree.{stage.replace(' ', '_')}() the open tree's")

    def newton_euler(self) -> NewtonEuler:
        """Newton–Euler equations M̄·J̄·ÿ + q̄^c = q̄^e + Q̄·g (METHOD §2)."""
        self._symbolic("newton euler")
        return self._stage("_newton_euler", lambda: newton_euler(self.kinematics()))

    def equations_of_motion(self) -> EquationsOfMotion:
        """Equations of motion M·ÿ + k = q by projection with J̄ᵀ (METHOD §3)."""
        self._symbolic("equations of motion")
        return self._stage("_equations_of_motion", lambda: projection(self.newton_euler()))

    def reactions(self) -> Reactions:
        """Reaction forces: Q̄ from the joints, N̂·g = k̂ − q̂ (METHOD §4)."""
        self._symbolic("reactions")
        return self._stage("_reactions", lambda: reactions(self.newton_euler()))

    def linearize(self, nominal: Mapping[Any, Any] | Any,
                  inputs: Mapping[Any, Any] | None = None
                  ) -> Linearization | LoopLinearization | ClosedLinearization:
        """Linearization M̃·η̈ + P·η̇ + Q·η = h + B·Δu about a nominal motion (METHOD §5), with
        nominal ``inputs`` ``{input: u_s}`` where given (zero otherwise); see
        :func:`jourdain.stages.linearization.linearization`. The result has its numbers as
        methods (``evaluate``, ``compile``, ``check_nominal``:
        :class:`jourdain.numeric.linearization.Linearization`).

        A closed system is linearized in its independent coordinates about the state
        ``nominal`` (``{coordinate: value, "<coordinate>_d": rate}`` or the f tree
        coordinates; assembled onto the manifold): a
        :class:`jourdain.loops.linearization.LoopLinearization` with ``M_tilde, P, Q, h, D,
        G, K, N``, the state matrix ``A`` and its ``eigenvalues`` (symbolic derivatives at an
        equilibrium at rest, else central differences of the compiled M, k, q on the
        manifold); about a motion (expressions of t) or in a rheonomic system, a time-variant
        :class:`jourdain.loops.periodic.ClosedLinearization` (``jd.floquet``)."""
        if self.frictions:
            names = ", ".join(f.name for f in self.frictions)
            raise ModelError(f"{self.name}: joint friction ({names}) depends on the reaction "
                             "forces and is not linearized; system.evaluate(y, yd) gives its "
                             "numbers at a state")
        if self.is_general:
            from ..loops.general_linear import linearize_general

            if inputs:
                refuse_closed(self, "a linearization with nominal inputs is not available "
                              "for systems with velocity constraints yet")
            return linearize_general(self, nominal)
        if self.closing:
            from ..loops.nominal import linearize_closed

            return linearize_closed(self, nominal, inputs)
        from ..numeric.linearization import linearization  # with its numbers

        return linearization(self.equations_of_motion(), nominal, inputs)

    def evaluate(self, y: Any, yd: Any, t: float = 0.0,
                 parameters: Mapping[str, float] | None = None,
                 inputs: Mapping[str, float] | Sequence[float] | None = None
                 ) -> dict[str, Any]:
        """Numbers at one state: a dict from the seed's names to NumPy arrays.

        Keys: ``M_bar, J_bar, q_c, q_e, M, k, q``, and the reactions ``Q_bar, N_hat, k_hat,
        q_hat, g, g_names, g_undetermined`` and ``joint_wrenches``
        (:func:`jourdain.analysis.reactions.evaluate_reactions`; only ``reactions_error`` where
        the model's reactions cannot be formed). ``parameters`` overrides default values by
        name; ``inputs`` gives the inputs by name (or in the order of :attr:`input_names`).
        With joint friction, the friction forces are solved with the reactions (and are in
        ``q_e``, ``q``, ``q_hat``, ``g``; also ``q_f``, ``ydd``, ``friction``:
        :func:`jourdain.analysis.friction.evaluate_friction`).
        """
        if self.frictions:
            from ..analysis.friction import evaluate_friction

            return evaluate_friction(self, y, yd, t, parameters, inputs)
        if self.is_general:  # velocity constraints (METHOD §7): jourdain.loops.general
            from ..loops.general_eval import evaluate_general

            return evaluate_general(self, y, yd, t, parameters, inputs)  # type: ignore[arg-type]
        if self.closing:  # the closed system's numbers (METHOD §7): jourdain.loops.evaluation
            from ..loops.evaluation import evaluate_closed

            return evaluate_closed(self, y, yd, t, parameters, inputs)
        out: dict[str, Any] = dict(evaluate_eom(self, y, yd, t=t, parameters=parameters,
                                                inputs=inputs))
        eom: dict[str, np.ndarray] = dict(out)
        if self.groups:  # elastic bodies: the ordinary joints' (jourdain.analysis.group_reactions)
            from ..analysis.group_reactions import group_reactions

            out.update(group_reactions(self, y, yd, t, parameters, inputs))
            return out
        from ..analysis.reactions import evaluate_keys

        out.update(evaluate_keys(self, y, yd, t, parameters, inputs, eom=eom))
        return out

    def derivatives(self) -> Derivatives | ClosedDerivatives:
        """The first derivatives of the forward and inverse dynamics per state
        (:func:`derivatives`)."""
        return derivatives(self)

    def simulate(self, t_span: tuple[float, float], y0: Any, yd0: Any,
                 parameters: Mapping[str, float] | None = None,
                 inputs: Mapping[str, Any] | None = None, method: str | None = None,
                 rtol: float | None = None, atol: Any = None, t_eval: Any = None,
                 **options: Any) -> Results:
        """Integrate the equations of motion from ``y0, ẏ0`` over ``t_span``; returns a
        :class:`jourdain.simulation.results.Results` (see
        :func:`jourdain.simulation.simulate.simulate` for the methods, inputs, events and
        options). ``method``, ``rtol``, ``atol`` left out: the defaults of
        :mod:`jourdain.simulation.simulate` (DOP853, 1e-8, 1e-10), the same as model files'.

        A closed system moves on its constraint manifold: ``y0, yd0`` are assembled (the
        independent coordinates held) and the results carry the closing rows' residuals and
        multipliers (:func:`jourdain.loops.simulate.simulate_closed`)."""
        if self.is_general:
            from ..loops.general_sim import simulate_general

            return simulate_general(self, t_span, y0, yd0, parameters=parameters,
                                    inputs=inputs,
                                    method=DEFAULT_METHOD if method is None else method,
                                    rtol=DEFAULT_RTOL if rtol is None else rtol,
                                    atol=DEFAULT_ATOL if atol is None else atol,
                                    t_eval=t_eval, **options)
        if self.closing:
            from ..loops.simulate import simulate_closed

            return simulate_closed(self, t_span, y0, yd0, parameters=parameters, inputs=inputs,
                                   method=DEFAULT_METHOD if method is None else method,
                                   rtol=DEFAULT_RTOL if rtol is None else rtol,
                                   atol=DEFAULT_ATOL if atol is None else atol,
                                   t_eval=t_eval, **options)
        return simulate(self, t_span, y0, yd0, parameters=parameters, inputs=inputs,
                        method=DEFAULT_METHOD if method is None else method,
                        rtol=DEFAULT_RTOL if rtol is None else rtol,
                        atol=DEFAULT_ATOL if atol is None else atol, t_eval=t_eval, **options)


def tree_linearization(lin: Linearization | LoopLinearization | ClosedLinearization
                       ) -> Linearization:
    """``lin`` as the symbolic linearization of a tree (what :meth:`System.linearize` gives a
    system without closing joints), for code on the tree's path after its closed branch."""
    from ..numeric.linearization import Linearization

    if not isinstance(lin, Linearization):
        raise TypeError(f"expected a tree's Linearization, got {type(lin).__name__}")
    return lin
