"""Sample models shared by the tests, the documentation and the benchmarks: textbook systems
(:mod:`.classic`), serial chains from data (:mod:`.chains`), random trees (:mod:`.trees`),
closed mechanisms (:mod:`.loops`: four-bar, slider-crank, the IFToMM N four-bar), planar
chains and trees (:mod:`.planar`).
Each builds a :class:`jourdain.System`."""

from .chains import (
    ARM_AXES,
    ARM_MASSES,
    ARM_OFFSETS,
    chain_from_data,
    robot_arm,
    robot_arm_data,
    spatial_chain,
    spatial_chain_data,
)
from .classic import double_pendulum, heavy_top, n_link_pendulum_on_cart
from .loops import four_bar, n_four_bar, slider_crank
from .planar import planar_chain, planar_tree
from .trees import (
    CARDAN,
    TREE_JOINTS,
    TREE_WEIGHTS,
    random_tree,
    random_tree_data,
    tree_from_data,
)

__all__ = [
    "n_link_pendulum_on_cart", "double_pendulum", "heavy_top",
    "spatial_chain", "spatial_chain_data", "robot_arm", "robot_arm_data", "chain_from_data",
    "ARM_AXES", "ARM_OFFSETS", "ARM_MASSES",
    "random_tree", "random_tree_data", "tree_from_data", "TREE_JOINTS", "TREE_WEIGHTS", "CARDAN",
    "four_bar", "slider_crank", "n_four_bar", "planar_chain", "planar_tree",
]
