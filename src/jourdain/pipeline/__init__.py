"""The pipeline: :class:`jourdain.System`, the model with the method's stages as methods.

:class:`jourdain.model.System` is the description (pure, immutable data; it imports nothing
above the model). :class:`System` here is the same description with the stages run on demand
and kept: ``system.kinematics()`` → ``newton_euler()`` → ``equations_of_motion()`` →
``reactions()``, and ``linearize``, ``evaluate`` and ``simulate`` on top (``docs/method.md``
§2–§7). It sits above the stages, the numbers and the simulation, which take the base class;
everything that builds systems for users (model files, URDF, :mod:`jourdain.models`, closed
loops) builds this one.
"""

from .system import System

__all__ = ["System"]
