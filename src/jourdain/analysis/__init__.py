"""Analysis of linearized systems: state space, eigenvalues and modes, stability, frequency
response, parameter sweeps (METHOD.md §6); cyclic coordinates and Routh's reduced system
(:mod:`.cyclic`); Floquet analysis of periodic nominal motions (:mod:`.floquet`); python-control
systems and state feedback (:mod:`.python_control`)."""

from .cyclic import cyclic_coordinates
from .floquet import Floquet, floquet
from .frequency import FrequencyResponse, frequency_response
from .modes import (
    ASYMPTOTICALLY_STABLE,
    MARGINALLY_STABLE,
    UNSTABLE,
    Modes,
    Stability,
    modes,
    stability,
)
from .python_control import MissingDependency, state_feedback, to_control
from .state_space import StateSpace, state_space
from .sweep import Sweep, stability_boundary, sweep

__all__ = [
    "ASYMPTOTICALLY_STABLE", "MARGINALLY_STABLE", "UNSTABLE", "Floquet", "FrequencyResponse",
    "MissingDependency", "Modes", "Stability", "StateSpace", "Sweep", "frequency_response",
    "modes", "stability", "stability_boundary", "state_feedback", "state_space", "sweep",
    "to_control", "cyclic_coordinates", "floquet",
]
