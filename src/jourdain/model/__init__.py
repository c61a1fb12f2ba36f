"""The model description: what the user describes, immutable once built."""

from .bodies import (
    WORLD,
    Body,
    PlanarInertia,
    box,
    cylinder,
    disc,
    planar_inertia,
    point_mass,
    rod,
)
from .expressions import symbols, t
from .forces import (
    Bushing,
    Force,
    GeneralizedForce,
    Gravity,
    RotationalSpringDamper,
    SpringDamper,
    Torque,
    acceleration,
    deflection,
    deflection_d,
    elongation,
    elongation_d,
    rate,
)
from .friction import JointFriction
from .joints import (
    Cylindrical,
    Fixed,
    Free,
    General,
    Joint,
    Planar,
    Prismatic,
    Revolute,
    Rot,
    Spherical,
    Trans,
    Universal,
)
from .quantities import (
    Quantity,
    angular_velocity,
    distance,
    distance_rate,
    point_acceleration,
    position,
    relative_position,
    relative_velocity,
    velocity,
)
from .system import System

__all__ = [
    "WORLD", "Body", "box", "cylinder", "disc", "point_mass", "rod", "symbols", "t",
    "PlanarInertia", "planar_inertia",
    "Force", "GeneralizedForce", "Gravity", "RotationalSpringDamper", "SpringDamper", "Torque",
    "acceleration", "elongation", "elongation_d", "rate", "Bushing", "deflection", "deflection_d",
    "Quantity", "angular_velocity", "distance", "distance_rate", "point_acceleration", "position",
    "relative_position", "relative_velocity", "velocity", "JointFriction",
    "Cylindrical", "Fixed", "Free", "General", "Joint", "Planar", "Prismatic", "Revolute", "Rot",
    "Spherical", "Trans", "Universal", "System",
]
