"""What a model file describes, once read: :class:`ModelFile` with the system, its nominal
motions (:class:`NominalMotion`) and simulation settings (:class:`SimulationSettings`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import symengine as se

from ...errors import ModelError
from ...pipeline import System  # jourdain.System: the model with its stages (issue 16)
from ...simulation.simulate import (
    DEFAULT_ATOL,
    DEFAULT_METHOD,
    DEFAULT_RTOL,
    DEFAULT_SAMPLES,
    DEFAULT_T_END,
)
from .errors import Locator, ModelFileError
from .schema import MAX_FILE_BYTES


@dataclass(frozen=True)
class NominalMotion:
    """A nominal motion y_s(t) to linearize about (METHOD §5).

    ``y``, ``yd``, ``ydd`` are tuples (one entry per coordinate, in the system's order) of
    expressions in ``t`` and the parameters; ``yd`` and ``ydd`` are the time derivatives of ``y``
    unless the file gives the rates explicitly. ``inputs`` holds the nominal inputs ``u_s`` as
    ``(name, expression)`` pairs (inputs not given are 0).
    """

    name: str
    y: tuple[se.Basic, ...]
    yd: tuple[se.Basic, ...]
    ydd: tuple[se.Basic, ...]
    description: str = ""
    inputs: tuple[tuple[str, se.Basic], ...] = ()
    #: the period T of a periodic nominal motion (an expression in the parameters; None
    #: otherwise): the report and ``jourdain linearize`` then give its Floquet analysis
    period: se.Basic | None = None

    @property
    def is_equilibrium(self) -> bool:
        """True when y_s is constant (no ``t``) and all rates vanish."""
        t = se.Symbol("t")
        return all(t not in e.free_symbols for e in self.y) and all(e == 0 for e in self.yd)


@dataclass(frozen=True)
class SimulationSettings:
    """How ``jourdain simulate`` integrates the equations of motion.

    ``y0`` and ``yd0`` are the initial coordinates and rates (system order); ``inputs`` maps each
    input name to an expression in ``t`` and the parameters (0 when not given).
    """

    t_end: float = DEFAULT_T_END
    samples: int = DEFAULT_SAMPLES
    method: str = DEFAULT_METHOD
    rtol: float = DEFAULT_RTOL
    atol: float = DEFAULT_ATOL
    y0: tuple[float, ...] = ()
    yd0: tuple[float, ...] = ()
    inputs: tuple[tuple[str, se.Basic], ...] = ()


@dataclass(frozen=True)
class ModelFile:
    """A loaded model file: the :class:`~jourdain.System` (closed by the file's
    ``[closing_joints.<name>]`` where it has any; its open tree is ``system.tree``) and what
    else the file describes."""

    path: str
    system: System
    description: str = ""
    nominal: tuple[NominalMotion, ...] = ()
    simulation: SimulationSettings = field(default_factory=SimulationSettings)
    descriptions: tuple[tuple[str, str], ...] = ()
    view: str | None = None

    def error(self, message: str) -> ModelFileError:
        """A :class:`ModelFileError` for a problem a later stage found in this model (e.g. a
        joint whose constrained directions violate J̄ᵀQ̄ = 0), located in the file by the body,
        joint or force that the message names."""
        try:
            with open(self.path, "rb") as fh:
                text = fh.read(MAX_FILE_BYTES + 1).decode("utf-8")
        except (OSError, UnicodeDecodeError):
            text = ""
        loader = Locator(text if len(text) <= MAX_FILE_BYTES else "", self.path)
        loader.body_names = self.system.body_names
        loader.joint_of_body = {b.name: b.joint.name for b in self.system.bodies}
        path = loader.locate(message)
        if path[:1] == ("bodies",) and len(path) == 3 and (*path, "constrained") in loader.lines:
            path = (*path, "constrained")
        return loader.fail(path, message)

    def nominal_motion(self, name: str | None = None) -> NominalMotion:
        """The nominal motion called ``name`` (the first one when ``None``)."""
        if not self.nominal:
            raise ModelError(f"{self.path}: the model defines no nominal motion ([nominal.<name>])")
        if name is None:
            return self.nominal[0]
        for n in self.nominal:
            if n.name == name:
                return n
        names = ", ".join(n.name for n in self.nominal)
        raise ModelError(f'{self.path}: no nominal motion "{name}"; the model has: {names}')


