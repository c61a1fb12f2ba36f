"""Input and output: model files, jourdain's expression language, exports and reports.

- :func:`load_model` / :func:`loads_model`: read a TOML model file (``docs/model-format.md``)
  into a :class:`ModelFile` holding the :class:`~jourdain.System`, nominal motions and simulation
  settings; mistakes raise :class:`ModelFileError` with file, line and key path.
- :func:`parse_expression`: the restricted expression parser (never ``eval``).
- :func:`matrix_latex`, :func:`matrix_mathml`, :func:`matrix_text`, :func:`matrices_json`:
  exports of symbolic matrices (large ones summarized by size and operation count).
- :func:`write_report`: the self-contained HTML report of ``jourdain run``.

The report (:mod:`.report`, which sits above the workflow it shares with the command line) is
imported on first use of its names (module ``__getattr__``): ``import jourdain.io`` then never
imports the workflow, whatever imports it first (``jourdain`` itself imports its names lazily:
issue 35).
"""

from importlib import import_module
from importlib.util import find_spec
from typing import TYPE_CHECKING, Any

from .export import matrices_json, matrix_latex, matrix_mathml, matrix_text
from .expressions import FUNCTIONS, ExpressionError, parse_expression, parse_number
from .modelfile import (
    ModelFile,
    ModelFileError,
    NominalMotion,
    SimulationSettings,
    load_model,
    loads_model,
)

if TYPE_CHECKING:
    from .report import ReportInfo, write_report

__all__ = [
    "FUNCTIONS", "ExpressionError", "parse_expression", "parse_number", "ModelFile",
    "ModelFileError", "NominalMotion", "SimulationSettings", "load_model", "loads_model",
    "matrices_json", "matrix_latex", "matrix_mathml", "matrix_text", "ReportInfo",
    "write_report",
]



def __getattr__(name: str) -> Any:
    """The report's names, imported from :mod:`.report` on first use; a subpackage or module
    by its name (``jourdain.io.viewer``, which the report used to import with this package)."""
    if name in ("ReportInfo", "write_report"):
        value = getattr(import_module(f"{__name__}.report"), name)
        globals()[name] = value
        return value
    if name.startswith("_") or find_spec(f"{__name__}.{name}") is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return import_module(f"{__name__}.{name}")
