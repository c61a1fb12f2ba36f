"""What the runs of one system with the same options share, prepared once: the ``jd_problem``
structure that the C loop reads (:class:`.problem._Setup`: the parameter vector, the inputs'
numbers, the tolerances, the compiled functions' addresses) and the constant fields of the
results (parameter values by name, coordinate and input names, units). Issue 35 asks for a
``simulate()`` call that costs at most 20 µs outside its C loop, and building these took about
20 of the 72 µs that a call cost.

:func:`run_template` serves the runs with numbers as inputs and no events from a small LRU memo
keyed by

    (system, its compiled M, k, q, the parameter values given, the inputs, method, rtol, the
     tolerances, max_step, first_step)

each part a value: the system by its content (its hash computed once), the compiled function by
identity (a cleared and recompiled one is a new key), the parameter values and tolerances as the
bytes of their checked vectors, the inputs as their (name, number) pairs. A template is built
from its key alone, so an entry holds nothing that its key does not say; a check that raises
leaves no entry, so a bad value raises on every call. Runs with events, or with inputs other
than numbers (tables, expressions, callables, which may carry state of their own), get a fresh
template each time. Nothing in a template is written by a run (the C loop reads the problem
through const pointers, and the results copy what they keep), so runs in threads may share one.
:func:`clear_templates` empties the memo.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from functools import lru_cache
from typing import TYPE_CHECKING, Any

import numpy as np

from ..numeric import CompiledFunction, parameter_vector
from ..numeric.first_run import run_function
from ..units import model_units
from .options import C_METHODS
from .problem import Event, _Setup

if TYPE_CHECKING:
    from ..model.system import System

#: templates kept (a sweep over parameter values builds one per value and keeps the last ones)
MEMO_SIZE = 32


class RunTemplate:
    """The problem of a run and its results' constant fields (see the module docs).

    Attributes
    ----------
    setup : the C loop's problem (:class:`.problem._Setup`; ``setup.problem_ref`` its pointer)
    method, rtol : as checked; ``atol`` the 2f absolute tolerances (read-only)
    parameters : parameter values by name (each results object gets a copy)
    coordinate_names, input_names, units, name : the results' labels (copied likewise)
    u_row : the inputs' values where all are numbers (nu,), else None (read-only)
    """

    __slots__ = ("atol", "coordinate_names", "input_names", "method", "name", "parameters",
                 "rtol", "setup", "u_row", "units")

    def __init__(self, system: System, mkq: CompiledFunction, p: np.ndarray,
                 inputs: Mapping[str, Any] | None, events: Sequence[Event],
                 method: str, rtol: float, atol_x: np.ndarray, max_step: float,
                 first_step: float) -> None:
        self.setup = setup = _Setup(system, mkq, p, inputs, events, C_METHODS.get(method, 1),
                                    rtol, atol_x, max_step, first_step)
        self.method, self.rtol = method, rtol
        self.atol = atol_x[:-1]
        self.parameters = dict(zip((k for k, _ in system.parameters), setup.p.tolist(),
                                   strict=True))
        self.coordinate_names = system.coordinate_names
        self.input_names = system.input_names
        self.units = model_units(system)
        self.name = system.name
        nu = len(self.input_names)
        if setup.callables or setup.uexpr is not None or setup.u_kind[:nu].any():
            self.u_row = None
        else:
            self.u_row = setup.u_const[:nu].copy()
            self.u_row.flags.writeable = False

    def inputs_at(self, t: np.ndarray, x: np.ndarray) -> np.ndarray:
        """The inputs at the output times ``t`` (states ``x``), (N, nu): numbers repeated, else
        :meth:`.problem._Setup.inputs_at`."""
        if self.u_row is None:
            return self.setup.inputs_at(t, x)
        U = np.empty((len(t), self.u_row.size))
        U[:] = self.u_row
        return U


def run_template(system: System, parameters: Mapping[str, float] | None,
                 inputs: Mapping[str, Any] | None, events: Sequence[Event],
                 method: str, rtol: float, atol_x: np.ndarray, max_step: float,
                 first_step: float) -> RunTemplate:
    """The template of a run of ``system``'s compiled M, k, q (:func:`run_function`), from
    the memo where the run has numbers as inputs and no events (see the module docs). Checked
    in this order, as before the memo: the parameters (unknown names, values that are not
    finite or not physical), the model compiled, then the inputs and events
    (:class:`~jourdain.errors.EvaluationError`)."""
    inputs_key = _number_inputs(inputs)
    fresh = bool(events) or inputs_key is None
    p = parameter_vector(system, parameters) if parameters or fresh else None
    mkq = run_function(system)
    if fresh:
        return RunTemplate(system, mkq, parameter_vector(system, None) if p is None else p,
                           inputs, events, method, rtol, atol_x, max_step, first_step)
    return _memo(system, mkq, None if p is None else p.tobytes(), inputs_key, method, rtol,
                 atol_x.tobytes(), max_step, first_step)


@lru_cache(maxsize=MEMO_SIZE)
def _memo(system: System, mkq: CompiledFunction, p_key: bytes | None,
          inputs_key: tuple[tuple[str, float], ...], method: str, rtol: float, atol_key: bytes,
          max_step: float, first_step: float) -> RunTemplate:
    """The template built from its key alone (``p_key`` None: the defaults)."""
    p = parameter_vector(system, None) if p_key is None else np.frombuffer(p_key).copy()
    return RunTemplate(system, mkq, p, dict(inputs_key), (), method, rtol,
                       np.frombuffer(atol_key), max_step, first_step)


def _number_inputs(inputs: Any) -> tuple[tuple[str, float], ...] | None:
    """``inputs`` as a key where it is None or a dict of plain numbers (``float`` or ``int``,
    exact types: not ``bool``, not NumPy scalars), else None."""
    if inputs is None:
        return ()
    if type(inputs) is not dict:
        return None
    items = tuple(inputs.items())
    for _, v in items:
        kind = type(v)
        if kind is not float and kind is not int:
            return None
    return items


def clear_templates() -> None:
    """Forget every template (they are rebuilt on the next runs)."""
    _memo.cache_clear()
