"""Model files: a multibody system, its nominal motions and simulation settings in TOML.

The format is described in ``docs/model-format.md``. :func:`load_model` reads a file,
:func:`loads_model` a string. Expressions are read by :mod:`jourdain.io.expressions` (never by
Python); every mistake raises :class:`ModelFileError` naming the file, the line and the key path::

    double.toml:14: body "rod2" → joint → axis: expected one of x, y, z or a 3-vector, got "w"

The package reads by topic: :mod:`.schema` (allowed keys, limits), :mod:`.errors` (locating
and wording mistakes), :mod:`.document` (the result), :mod:`.values` (typed access),
:mod:`.bodies`, :mod:`.forces` and :mod:`.loader` (building the model, section by section).
"""

from .document import ModelFile, NominalMotion, SimulationSettings
from .errors import ModelFileError, describe_path
from .loader import load_model, loads_model
from .schema import MAX_FILE_BYTES

__all__ = ["MAX_FILE_BYTES", "ModelFile", "ModelFileError", "NominalMotion", "describe_path",
           "SimulationSettings", "load_model", "loads_model"]
