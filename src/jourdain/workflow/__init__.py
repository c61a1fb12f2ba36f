"""The workflow shared by the command line and the report (docs/method.md, all stages).

It sits above the stages, the numbers, the simulation and the analyses, and below the two
front ends (:mod:`jourdain.cli`, :mod:`jourdain.io.report`), which import it and never each
other:

- :mod:`~jourdain.workflow.capability`: which stages this build offers (:func:`has_capability`,
  :class:`NotAvailable`);
- :mod:`~jourdain.workflow.overview`: a loaded model summarized (:func:`summary`);
- :mod:`~jourdain.workflow.evaluation`: every matrix of the method at one state
  (:func:`evaluate_all`), the symbolic matrices (:func:`eom_matrices`) and their JSON form
  (:data:`EVAL_FORMAT`, :func:`eval_document`, :func:`json_array`);
- :mod:`~jourdain.workflow.checks`: the initial state's checks (:func:`check_initial_state`).
"""

from .capability import NotAvailable, has_capability, require
from .checks import SINGULAR_RTOL, check_initial_state, mass_matrix_problem
from .evaluation import (
    EVAL_FORMAT,
    eom_matrices,
    eval_document,
    evaluate_all,
    json_array,
    linearization_at,
    reactions_at,
)
from .overview import cyclic, summary

__all__ = [
    "NotAvailable", "has_capability", "require", "SINGULAR_RTOL", "check_initial_state",
    "mass_matrix_problem", "EVAL_FORMAT", "eom_matrices", "eval_document", "evaluate_all",
    "json_array", "linearization_at", "reactions_at", "cyclic", "summary",
]
