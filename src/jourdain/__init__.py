"""jourdain: multibody dynamics by Schiehlen's Newton–Euler projection method.

Describe a :class:`System` of rigid bodies, joints and force elements, then run the stages
:func:`kinematics` → :func:`newton_euler` → :func:`projection` to get M̄, J̄, q̄^c, q̄^e and the
equations of motion M·ÿ + k = q; :func:`reactions` gives the reaction forces g,
:func:`linearization` the linear equations about a nominal motion, :func:`simulate` the motion.

The public API is :data:`__all__`, listed once below by topic (docs/architecture.md shows
where each part lives): the model, the stages, simulation, analysis, files, errors. Its
classes and functions carry their own documentation; the names that are values are these:

- ``t``: the symbol of time, shared by every model; ``WORLD``: ``"world"``, the inertial frame
  as a parent or a force element's frame.
- ``elongation``, ``elongation_d``: in a spring-damper's ``law``, its elongation L − L0 and its
  rate; ``deflection``, ``deflection_d``: in a generalized force's or a bushing's law, the
  deflection and its rate.
- ``sin``, ``cos``, ``tan``, ``atan2``, ``exp``, ``log``, ``sqrt`` and ``pi``: SymEngine's
  functions and π, for the expressions of a model.

Each name is imported from its submodule on first use (module ``__getattr__``, PEP 562), so
``import jourdain`` loads SymEngine and NumPy and nothing of its own beyond the errors' and the
version's modules: a script that builds a model and simulates it never waits for the model
files' readers, the report, URDF or the analysis it does not call (issue 35: 0.24 → 0.13 s).
"""

from importlib import import_module
from importlib.util import find_spec
from typing import TYPE_CHECKING, Any

from symengine import atan2, cos, exp, log, pi, sin, sqrt, tan

from .version import __version__ as __version__

if TYPE_CHECKING:  # the same names for type checkers and readers; at run time __getattr__
    from .analysis import (
        Floquet,
        FrequencyResponse,
        Modes,
        Stability,
        StateSpace,
        Sweep,
        cyclic_coordinates,
        frequency_response,
        stability,
        stability_boundary,
        state_feedback,
        to_control,
    )
    from .analysis.energy import Energy, energy
    from .analysis.floquet import floquet
    from .analysis.mode_motion import mode_motion
    from .analysis.modes import modes
    from .analysis.numeric_linearization import NumericLinearization, linearize_numeric
    from .analysis.reactions import evaluate_reactions, joint_reactions
    from .analysis.state_space import state_space
    from .analysis.sweep import sweep
    from .elastic.body import ElasticBody
    from .equilibrium import Equilibrium, NoEquilibrium, find_equilibria, find_equilibrium
    from .errors import (
        AssemblyError,
        ClosedSystemError,
        EvaluationError,
        JourdainError,
        JourdainWarning,
        ModelError,
        SingularConfiguration,
        SingularMassMatrix,
    )
    from .io import ModelFile, ModelFileError, load_model
    from .io.casadi import CasadiDynamics, to_casadi
    from .io.urdf import load_urdf
    from .io.viewer import MeshVisual, View, view
    from .model import (
        WORLD,
        Body,
        Bushing,
        Cylindrical,
        Fixed,
        Force,
        Free,
        General,
        GeneralizedForce,
        Gravity,
        Joint,
        JointFriction,
        Planar,
        Prismatic,
        Quantity,
        Revolute,
        Rot,
        RotationalSpringDamper,
        Spherical,
        SpringDamper,
        Torque,
        Trans,
        Universal,
        acceleration,
        angular_velocity,
        box,
        cylinder,
        deflection,
        deflection_d,
        disc,
        distance,
        distance_rate,
        elongation,
        elongation_d,
        planar_inertia,
        point_acceleration,
        point_mass,
        position,
        rate,
        relative_position,
        relative_velocity,
        rod,
        symbols,
        t,
        velocity,
    )
    from .model.closing import ClosingJoint
    from .model.contacts import KnifeEdge, RollingDisc, VelocityConstraint
    from .numeric.derivatives import Derivatives
    from .numeric.linearization import (  # the stage's results with their numbers (issue 16)
        CompiledLinearization,
        GeneralLinearization,
        Linearization,
        linearization,
        linearization_general,
    )
    from .pipeline import System
    from .pipeline.system import derivatives
    from .simulation.results import Results
    from .simulation.simulate import Event, IntegrationError, simulate
    from .stages.constraints import ConstraintRow, Constraints, constraints
    from .stages.kinematics import BodyKinematics, Kinematics, kinematics
    from .stages.linearization import NominalCheck, NominalMotionWarning, TimeVariantError
    from .stages.newton_euler import NewtonEuler, newton_euler
    from .stages.projection import EquationsOfMotion, projection
    from .stages.reactions import JointReactions, Reactions, reactions
    from .symbolic import SymMatrix
    from .wrenches import JointWrench, joint_wrenches

#: where each public name lives (the package's submodule, relative): imported on first use
_WHERE: dict[str, tuple[str, ...]] = {
    "analysis": ("Floquet", "FrequencyResponse", "Modes", "Stability", "StateSpace", "Sweep",
        "cyclic_coordinates", "frequency_response", "stability", "stability_boundary",
        "state_feedback", "to_control"),
    "analysis.energy": ("Energy", "energy"),
    "analysis.floquet": ("floquet",),
    "analysis.mode_motion": ("mode_motion",),
    "analysis.modes": ("modes",),
    "analysis.numeric_linearization": ("NumericLinearization", "linearize_numeric"),
    "analysis.reactions": ("evaluate_reactions", "joint_reactions"),
    "analysis.state_space": ("state_space",),
    "analysis.sweep": ("sweep",),
    "equilibrium": ("Equilibrium", "NoEquilibrium", "find_equilibria", "find_equilibrium"),
    "errors": ("AssemblyError", "ClosedSystemError", "EvaluationError", "JourdainError",
        "JourdainWarning", "ModelError", "SingularConfiguration", "SingularMassMatrix"),
    "elastic.body": ("ElasticBody",),
    "io": ("ModelFile", "ModelFileError", "load_model"),
    "io.casadi": ("CasadiDynamics", "to_casadi"),
    "io.urdf": ("load_urdf",),
    "io.viewer": ("MeshVisual", "View", "view"),
    "model": ("WORLD", "Body", "Bushing", "Cylindrical", "Fixed", "Force", "Free", "General",
        "GeneralizedForce", "Gravity", "Joint", "JointFriction", "Planar", "Prismatic",
        "Quantity", "Revolute", "Rot", "RotationalSpringDamper", "Spherical", "SpringDamper",
        "Torque", "Trans", "Universal", "acceleration", "angular_velocity", "box", "cylinder",
        "deflection", "deflection_d", "disc", "distance", "distance_rate", "elongation",
        "elongation_d", "planar_inertia", "point_acceleration", "point_mass", "position", "rate",
        "relative_position", "relative_velocity", "rod", "symbols", "t", "velocity"),
    "model.closing": ("ClosingJoint",),
    "model.contacts": ("KnifeEdge", "RollingDisc", "VelocityConstraint"),
    "numeric.derivatives": ("Derivatives",),
    "numeric.linearization": ("CompiledLinearization", "GeneralLinearization", "Linearization",
        "linearization", "linearization_general"),
    "pipeline": ("System",),
    "pipeline.system": ("derivatives",),
    "simulation.results": ("Results",),
    "simulation.simulate": ("Event", "IntegrationError", "simulate"),
    "stages.constraints": ("ConstraintRow", "Constraints", "constraints"),
    "stages.kinematics": ("BodyKinematics", "Kinematics", "kinematics"),
    "stages.linearization": ("NominalCheck", "NominalMotionWarning", "TimeVariantError"),
    "stages.newton_euler": ("NewtonEuler", "newton_euler"),
    "stages.projection": ("EquationsOfMotion", "projection"),
    "stages.reactions": ("JointReactions", "Reactions", "reactions"),
    "symbolic": ("SymMatrix",),
    "wrenches": ("JointWrench", "joint_wrenches"),
}
_MODULE_OF = {name: module for module, names in _WHERE.items() for name in names}


def __getattr__(name: str) -> Any:
    """A public name imported from its submodule on first use (PEP 562), then kept here; a
    subpackage or module by its name (``jourdain.models`` after ``import jourdain``, as when
    this module imported them all)."""
    module = _MODULE_OF.get(name)
    if module is None:
        if name.startswith("_") or find_spec(f"{__name__}.{name}") is None:
            raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
        return import_module(f"{__name__}.{name}")  # the import system sets it here
    value = getattr(import_module(f"{__name__}.{module}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_MODULE_OF})


#: The public API, by topic (tests/test_architecture.py checks that each name is documented).
__all__ = [
    # the model: the system, its bodies, joints and force elements (jourdain.model)
    "System", "Body", "WORLD", "symbols", "t",
    "box", "cylinder", "disc", "point_mass", "rod", "planar_inertia",
    "Joint", "Rot", "Trans", "Revolute", "Prismatic", "Cylindrical", "Universal", "Spherical",
    "Planar", "Free", "Fixed", "General",
    "Gravity", "Force", "Torque", "SpringDamper", "GeneralizedForce", "RotationalSpringDamper",
    "Bushing", "JointFriction", "rate", "acceleration", "elongation", "elongation_d", "deflection",
    "deflection_d",
    "ClosingJoint", "RollingDisc", "KnifeEdge", "VelocityConstraint", "ElasticBody",
    "Quantity", "position", "velocity", "point_acceleration", "angular_velocity",
    "relative_position", "relative_velocity", "distance", "distance_rate",
    # functions for expressions in models (SymEngine's)
    "sin", "cos", "tan", "atan2", "exp", "log", "sqrt", "pi",
    # the stages of the method (jourdain.stages)
    "kinematics", "Kinematics", "BodyKinematics",
    "constraints", "Constraints", "ConstraintRow",
    "newton_euler", "NewtonEuler",
    "projection", "EquationsOfMotion", "SymMatrix",
    "reactions", "Reactions", "JointReactions", "evaluate_reactions", "joint_reactions",
    "JointWrench", "joint_wrenches",
    "linearization", "Linearization", "linearization_general", "GeneralLinearization",
    "linearize_numeric", "NumericLinearization", "CompiledLinearization", "NominalCheck",
    "NominalMotionWarning", "TimeVariantError",
    # simulation (jourdain.simulation)
    "simulate", "Results", "Event", "IntegrationError",
    # analysis (jourdain.analysis, jourdain.equilibrium)
    "state_space", "StateSpace", "modes", "Modes", "mode_motion", "stability", "Stability",
    "frequency_response", "FrequencyResponse", "sweep", "Sweep", "stability_boundary",
    "floquet", "Floquet", "cyclic_coordinates", "energy", "Energy",
    "find_equilibrium", "find_equilibria", "Equilibrium", "NoEquilibrium",
    "to_control", "state_feedback",
    # files and views (jourdain.io)
    "load_model", "ModelFile", "ModelFileError", "load_urdf", "view", "View", "MeshVisual",
    # optimal control: the equations of motion as CasADi functions (jourdain.io.casadi), the
    # compiled derivatives of the dynamics per state (jourdain.numeric.derivatives)
    "to_casadi", "CasadiDynamics", "derivatives", "Derivatives",
    # errors (jourdain.errors)
    "JourdainError", "ModelError", "EvaluationError", "SingularMassMatrix", "JourdainWarning",
    "ClosedSystemError", "AssemblyError", "SingularConfiguration",
]
