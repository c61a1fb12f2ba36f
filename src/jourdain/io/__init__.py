"""Input and output: model files, jourdain's expression language, exports and reports.

- :func:`load_model` / :func:`loads_model`: read a TOML model file (``docs/model-format.md``)
  into a :class:`ModelFile` holding the :class:`~jourdain.System`, nominal motions and simulation
  settings; mistakes raise :class:`ModelFileError` with file, line and key path.
- :func:`parse_expression`: the restricted expression parser (never ``eval``).
"""

from .expressions import FUNCTIONS, ExpressionError, parse_expression, parse_number
from .modelfile import (
    ModelFile,
    ModelFileError,
    NominalMotion,
    SimulationSettings,
    load_model,
    loads_model,
)

__all__ = [
    "FUNCTIONS", "ExpressionError", "parse_expression", "parse_number", "ModelFile",
    "ModelFileError", "NominalMotion", "SimulationSettings", "load_model", "loads_model",
]
