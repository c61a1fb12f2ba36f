"""Linearization about a nominal motion (``docs/method.md`` §5) and its physical split (§6).

Produces M̃ (``M``), P, Q, h, B about a nominal motion and D, G, K, N (:class:`Linearization`,
:class:`GeneralLinearization`), symbolic. Their numbers are on the floors above:
``jourdain.numeric.linearization`` (``lin.evaluate``, ``lin.compile``, ``lin.check_nominal`` on
the subclasses that ``jourdain.linearization`` and ``jourdain.System.linearize`` return) and
``jourdain.analysis.numeric_linearization`` (numbers without the symbolic form).

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
``linearize_numeric`` (numbers for given parameter values: the fast path to eigenvalues of
large systems; :mod:`jourdain.analysis.numeric_linearization`).

For a time-invariant result (M̃, P, Q, B free of t) the matrices split into damping ``D``,
gyroscopic ``G``, stiffness ``K`` and circulatory ``N`` parts (§6):
``D = ½(P + Pᵀ)``, ``G = ½(P − Pᵀ)``, ``K = ½(Q + Qᵀ)``, ``N = ½(Q − Qᵀ)``.

A nominal motion may set the inputs too (``u_s``: the motor torque that keeps a rotor turning
against its damping, the force that holds an arm in its pose). Where an equilibrium or a steady
motion (ÿ_s = 0) leaves ``h ≠ 0`` it is not a solution of the equations of motion: the
linearization says so with a :class:`NominalMotionWarning` (:class:`NominalCheck`; at other
times and parameter values ``lin.check_nominal``), and so does the stability verdict built on
it.

Modules
-------
* :mod:`.nominal`: the nominal motion and the check that it solves the equations of motion;
* :mod:`.formation`: the symbolic linearization (:func:`linearization`);
* :mod:`.result`: :class:`Linearization` (the split into D, G, K, N) and its numbers at
  checked values;
* :mod:`.general`: the general form (:func:`linearization_general`).

The numeric path for given parameter values (``linearize_numeric``) is on the analysis floor,
above the compiled code: :mod:`jourdain.analysis.numeric_linearization`.
"""

from .formation import linearization
from .general import GeneralLinearization, linearization_general
from .nominal import (
    NOMINAL_RTOL,
    NominalCheck,
    NominalMotionWarning,
    TimeVariantError,
    force_scale,
    term_scale,
)
from .result import Linearization

__all__ = [
    "NOMINAL_RTOL", "GeneralLinearization", "Linearization",
    "NominalCheck", "NominalMotionWarning", "TimeVariantError", "force_scale", "linearization",
    "linearization_general", "term_scale",
]
