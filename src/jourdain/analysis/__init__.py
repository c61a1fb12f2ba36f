"""Analysis of linearized systems: state space, eigenvalues and modes, stability, frequency
response, parameter sweeps (METHOD.md §6); cyclic coordinates and Routh's reduced system
(:mod:`.cyclic`); Floquet analysis of periodic nominal motions (:mod:`.floquet`); python-control
systems and state feedback (:mod:`.python_control`); energies (:mod:`.energy`).

The functions named like their modules are not re-exported here (``jourdain.analysis.modes``
is the module): ``jourdain.modes``, ``jourdain.floquet``, ``jourdain.state_space`` and
``jourdain.sweep`` are the functions.
"""

from .cyclic import cyclic_coordinates
from .floquet import Floquet
from .frequency import FrequencyResponse, frequency_response
from .modes import ASYMPTOTICALLY_STABLE, MARGINALLY_STABLE, UNSTABLE, Modes, Stability, stability
from .python_control import MissingDependency, state_feedback, to_control
from .state_space import StateSpace
from .sweep import Sweep, stability_boundary

__all__ = [
    "ASYMPTOTICALLY_STABLE", "MARGINALLY_STABLE", "UNSTABLE",
    "StateSpace", "Modes", "Stability", "stability",
    "FrequencyResponse", "frequency_response",
    "Sweep", "stability_boundary",
    "Floquet", "cyclic_coordinates",
    "MissingDependency", "state_feedback", "to_control",
]
