"""Bridge to python-control: a linearization as a named ``control.StateSpace``, and a state
feedback law ``Δu = −K·x`` as input expressions for :func:`jourdain.simulation.simulate.simulate`.

The state-space form is that of :mod:`jourdain.analysis.state_space` (METHOD.md §6): with the
state ``x = [η; η̇]`` (2f) and the input deviations ``Δu`` (m),

    ẋ = A·x + B·Δu,   y_out = C·x + D·Δu

where ``C`` selects the chosen outputs among the states and ``D = 0``. The states are named
after the coordinates and their rates (``phi``, ``phi_d``), the inputs after the model's
inputs, so that python-control's block diagrams (``interconnect``) connect by name. The
excitation ``E·h`` is not part of it: about an equilibrium or a steady motion that solves the
equations of motion ``h = 0`` (the linearization warns with a
:class:`~jourdain.stages.linearization.NominalMotionWarning` where it does not).

python-control is an optional dependency: ``pip install "jourdain[control]"``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
import symengine as se

from ..errors import EvaluationError, refuse_closed
from ..stages.linearization import Linearization
from ..stages.linearization.nominal import _nominal
from .state_space import AnyLinearization, StateSpace, state_space
from .state_space import MissingDependency as MissingDependency
from .state_space import output_matrix as output_matrix

if TYPE_CHECKING:
    from ..model.system import System


def to_control(lin: AnyLinearization | StateSpace, t: float | None = None,
               parameters: Mapping[str, float] | None = None,
               outputs: Sequence[str] | None = None, *, allow_time_variant: bool = False,
               name: str | None = None) -> Any:
    """The linearization as a ``control.StateSpace`` ``ẋ = A·x + B·Δu, y = C·x``.

    Parameters
    ----------
    lin : Linearization, CompiledLinearization, NumericLinearization or StateSpace
        The linear system; a :class:`StateSpace` is used as it is (``t`` and ``parameters``
        must then be left out).
    t, parameters, allow_time_variant
        As for :func:`jourdain.analysis.state_space`.
    outputs : sequence of str, optional
        State names to output (coordinates ``q1``, rates ``q1_d``); all states when None.
    name : str, optional
        The system's name in python-control (default: the model's name).

    Returns
    -------
    control.StateSpace
        A (2f×2f), B (2f×m), C (p×2f), D = 0 (p×m); ``state_labels`` ``[y..., y_d...]``,
        ``input_labels`` the model's inputs, ``output_labels`` the outputs chosen.

    Raises
    ------
    MissingDependency
        Without python-control (the message names the extra ``jourdain[control]``).
    """
    if isinstance(lin, StateSpace):
        if t is not None or parameters:
            raise EvaluationError("to_control: a StateSpace holds numbers for one t and one set "
                                  "of parameters; pass t and parameters to state_space instead")
        ss = lin
    else:
        ss = state_space(lin, t, parameters, allow_time_variant=allow_time_variant)
    if name is None:
        base = lin.linearization if hasattr(lin, "linearization") else lin
        name = getattr(getattr(base, "system", None), "name", None)
    return ss.to_control(outputs, name=name)


def state_names(system: System) -> list[str]:
    """The state names ``[y..., y_d...]`` of a system (those of :attr:`StateSpace.state_names`)."""
    c = system.coordinate_names
    return [*c, *(f"{n}_d" for n in c)]


def state_feedback(system: System, K: Any, nominal: Mapping[Any, Any] | Any,
                   inputs: Mapping[Any, Any] | None = None) -> dict[str, se.Basic]:
    """The law ``u = u_s − K·(x − x_s)``, ``x = [y; ẏ]``, as one expression per input: the
    form :func:`jourdain.simulation.simulate.simulate` (``inputs=``) compiles into its C loop.

    Parameters
    ----------
    system : System
    K : (m, 2f) array
        Gain on the state deviations, columns in the order ``[y; ẏ]`` of
        :attr:`StateSpace.state_names` (``control.lqr``'s K for :func:`to_control`'s system).
    nominal : mapping coordinate -> value or expression in t and parameters, or a Linearization
        The nominal motion ``y_s`` (every coordinate, as for :meth:`System.linearize`); its
        rates are its time derivatives. A symbolic :class:`~jourdain.stages.linearization.Linearization`
        gives its own nominal motion and inputs.
    inputs : mapping input -> value or expression, optional
        The nominal inputs ``u_s`` (zero for inputs left out; a Linearization's own otherwise).

    Returns
    -------
    dict input name -> symengine expression in the coordinates, rates, t and parameters.

    Raises
    ------
    EvaluationError
        K of the wrong shape or not finite.
    ModelError
        A nominal motion that names unknown coordinates or leaves some out.
    """
    refuse_closed(system, "a state feedback in the tree's states [y; ẏ] would act on the "
                  "dependent coordinates too; closed systems have no feedback law yet (their "
                  "linearization's states are the independent coordinates)")

    f, names = system.f, system.input_names
    try:
        gain = np.asarray(K, dtype=float)
    except (TypeError, ValueError):
        raise EvaluationError(f"state_feedback: K must be a numeric (m, 2f) array, got "
                              f"{type(K).__name__}") from None
    if gain.ndim == 1 and len(names) == 1:
        gain = gain[None, :]
    if gain.shape != (len(names), 2 * f):
        raise EvaluationError(
            f"state_feedback: K has shape {gain.shape}; {system.name!r} needs "
            f"({len(names)}, {2 * f}): one row per input ({', '.join(names) or 'none'}), one "
            f"column per state ({', '.join(state_names(system))})")
    if not np.all(np.isfinite(gain)):
        raise EvaluationError("state_feedback: K has NaN or inf entries")
    if isinstance(nominal, Linearization):  # its nominal mapping holds u_s too
        nominal = {k: v for k, v in nominal.nominal.items()
                   if inputs is None or k in system.coordinate_names}
    y_s, u_s = _nominal(system, nominal, inputs)
    yd_s = [se.diff(e, system.t) for e in y_s]
    x = [*system.y, *system.yd]
    dx = [xi - xs for xi, xs in zip(x, [*y_s, *yd_s], strict=True)]
    law: dict[str, se.Basic] = {}
    for i, n in enumerate(names):
        terms = [se.Float(float(-gain[i, j])) * dx[j] for j in range(2 * f) if gain[i, j] != 0]
        law[n] = se.Add(u_s[i], *terms)
    return law
