"""The keys a model file may have, by table, and the limits on its size and nesting.
"""

from __future__ import annotations

import re

#: Largest model file read (bytes). Real models are a few kB to a few hundred kB; reading and
#: locating the keys of a file takes about a second per MB, so larger files are refused at once.
MAX_FILE_BYTES = 4_000_000
#: Deepest nesting of arrays and inline tables reported by name when the TOML reader gives up
#: (model files nest three or four levels).
_MAX_NESTING = 32

_TOP = {"model", "coordinates", "parameters", "inputs", "bodies", "forces", "nominal",
        "simulation", "quantities", "closing_joints", "loops", "contacts", "speeds"}
_JOINT_KEYS: dict[str, set[str]] = {
    "revolute": {"coordinate", "axis"},
    "prismatic": {"coordinate", "axis"},
    "cylindrical": {"coordinates", "axis"},
    "universal": {"coordinates", "axes"},
    "spherical": {"coordinates", "sequence"},
    "planar": {"coordinates", "normal"},
    "free": {"coordinates", "sequence"},
    "fixed": set(),
    "general": {"steps", "coordinates", "constrained"},
}
_JOINT_COMMON = {"type", "name", "position", "orientation"}
_FORCE_KEYS: dict[str, set[str]] = {
    "gravity": {"vector"},
    "force": {"body", "vector", "point", "frame", "point_frame"},
    "torque": {"body", "vector", "frame"},
    "spring_damper": {"body_a", "point_a", "body_b", "point_b", "stiffness", "damping",
                      "rest_length", "law"},
    "generalized": {"coordinate", "value"},
    "rotational_spring_damper": {"coordinate", "stiffness", "damping", "rest_angle"},
    "bushing": {"body_a", "point_a", "body_b", "point_b", "frame", "stiffness", "damping",
                "preload", "laws", "axes_a", "axes_b"},
    "joint_friction": {"joint", "coordinate", "mu", "normal", "radius", "v_eps"},
}
#: keys of a [quantities.<name>] table, by its type (one point, or two points)
_QUANTITY_KEYS_ONE = {"body", "point", "frame", "point_frame"}
_QUANTITY_KEYS_TWO = {"body_a", "point_a", "body_b", "point_b", "frame"}
_SHAPES = {"point": set(), "rod": {"length", "axis"}, "disc": {"radius", "axis"},
           "cylinder": {"radius", "length", "axis"}, "box": {"a", "b", "c"}}
_IDENT = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
# line breaks and other control characters (C0, DEL, C1, the Unicode line separators)
_CONTROL = re.compile("[\x00-\x1f\x7f-\x9f\u2028\u2029]")

