"""The model description: what the user describes, immutable once built."""

from .bodies import WORLD, Body, box, cylinder, disc, point_mass, rod
from .expressions import symbols, t
from .forces import (
    Force,
    GeneralizedForce,
    Gravity,
    RotationalSpringDamper,
    SpringDamper,
    Torque,
    acceleration,
    elongation,
    elongation_d,
    rate,
)
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
from .system import System

__all__ = [
    "WORLD", "Body", "box", "cylinder", "disc", "point_mass", "rod", "symbols", "t",
    "Force", "GeneralizedForce", "Gravity", "RotationalSpringDamper", "SpringDamper", "Torque",
    "acceleration", "elongation", "elongation_d", "rate",
    "Cylindrical", "Fixed", "Free", "General", "Joint", "Planar", "Prismatic", "Revolute", "Rot",
    "Spherical", "Trans", "Universal", "System",
]
