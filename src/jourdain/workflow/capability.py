"""Which later stages this build of jourdain offers (reactions, linearization, simulation).

The command line and the report ask here before they use a stage, so that a stage that is
missing becomes a message (``jourdain eval``) or a note in the report instead of a traceback.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from ..pipeline import System


class NotAvailable(Exception):
    """A capability (reactions, linearization, simulation) is not part of this build yet."""


def has_capability(method: str) -> bool:
    """Whether :class:`jourdain.pipeline.System` (what model files build) offers ``method``
    (reactions, linearize, simulate)."""
    return hasattr(System, method)


def require(system: Any, method: str, what: str) -> Callable[..., Any]:
    """``system.<method>``; :class:`NotAvailable` naming ``what`` when this build lacks it."""
    fn = getattr(system, method, None)
    frictions = getattr(system, "frictions", ())
    if method == "linearize" and frictions:
        raise NotAvailable(f"{what} is not available for joint friction "
                           f"({', '.join(f.name for f in frictions)}): it depends on the "
                           "reaction forces")
    if fn is None:
        raise NotAvailable(f"{what} is not available yet in this version of jourdain "
                           f"(System.{method} is missing)")
    return fn
