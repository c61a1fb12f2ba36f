"""jourdain: multibody dynamics by Schiehlen's Newton–Euler projection method.

Describe a :class:`System` of rigid bodies, joints and force elements, then run the stages
:func:`kinematics` → :func:`newton_euler` → :func:`projection` to get M̄, J̄, q̄^c, q̄^e and the
equations of motion M·ÿ + k = q.
"""

from symengine import atan2, cos, exp, log, pi, sin, sqrt, tan

from .analysis import (
    Floquet,
    FrequencyResponse,
    Modes,
    Stability,
    StateSpace,
    Sweep,
    cyclic_coordinates,
    floquet,
    frequency_response,
    modes,
    stability,
    stability_boundary,
    state_feedback,
    state_space,
    sweep,
    to_control,
)
from .analysis.energy import Energy, energy
from .equilibrium import Equilibrium, NoEquilibrium, find_equilibria, find_equilibrium
from .errors import (
    EvaluationError,
    JourdainError,
    JourdainWarning,
    ModelError,
    SingularMassMatrix,
)
from .io import ModelFile, ModelFileError, load_model
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
from .pipeline import System
from .simulation.results import Results
from .simulation.simulate import Event, IntegrationError, simulate
from .stages.kinematics import BodyKinematics, Kinematics, kinematics
from .stages.linearization import (
    CompiledLinearization,
    GeneralLinearization,
    Linearization,
    NominalCheck,
    NominalMotionWarning,
    NumericLinearization,
    TimeVariantError,
    linearization,
    linearization_general,
    linearize_numeric,
)
from .stages.newton_euler import NewtonEuler, newton_euler
from .stages.projection import EquationsOfMotion, projection
from .stages.reactions import (
    JointReactions,
    Reactions,
    evaluate_reactions,
    joint_reactions,
    reactions,
)
from .symbolic import SymMatrix
from .wrenches import JointWrench, joint_wrenches

__version__ = "0.1.0"

__all__ = [
    "atan2", "cos", "exp", "log", "pi", "sin", "sqrt", "tan",
    "EvaluationError", "JourdainError", "JourdainWarning", "ModelError", "SingularMassMatrix",
    "ModelFile", "ModelFileError", "load_model", "load_urdf", "MeshVisual", "View", "view",
    "BodyKinematics", "Kinematics", "kinematics", "NewtonEuler", "newton_euler",
    "EquationsOfMotion", "projection", "SymMatrix",
    "CompiledLinearization", "GeneralLinearization", "Linearization", "NominalCheck",
    "NominalMotionWarning", "NumericLinearization",
    "TimeVariantError", "linearization", "linearization_general", "linearize_numeric",
    "FrequencyResponse", "Modes", "Stability", "StateSpace", "Sweep", "frequency_response",
    "modes", "stability", "stability_boundary", "state_space", "sweep", "state_feedback",
    "to_control",
    "Equilibrium", "NoEquilibrium", "find_equilibria", "find_equilibrium",
    "JointReactions", "Reactions", "evaluate_reactions", "joint_reactions", "reactions",
    "JointWrench", "joint_wrenches", "Floquet", "floquet", "cyclic_coordinates",
    "Results", "Event", "IntegrationError", "simulate", "Energy", "energy",
    "WORLD", "Body", "Cylindrical", "Fixed", "Force", "Free", "General", "GeneralizedForce",
    "Gravity", "Joint", "Planar", "Prismatic", "Revolute", "Rot", "RotationalSpringDamper",
    "Spherical", "SpringDamper", "System", "Torque", "Trans", "Universal", "acceleration", "box",
    "cylinder", "disc", "elongation", "elongation_d", "point_mass", "rate", "rod", "symbols", "t",
    "Bushing", "deflection", "deflection_d", "Quantity", "angular_velocity", "distance",
    "distance_rate", "point_acceleration", "position", "relative_position", "relative_velocity",
    "velocity",
]
