"""Exceptions of jourdain. Each names the model element (body, joint, parameter, file line) at fault."""

from __future__ import annotations

import sys
import warnings
from pathlib import Path
from types import FrameType


class JourdainError(Exception):
    """Base class of all errors raised by jourdain."""


class ModelError(JourdainError, ValueError):
    """The model description is inconsistent: unknown or duplicate names, bad mass data, ..."""


class SingularMassMatrix(JourdainError, ArithmeticError):
    """A mass matrix that must be positive definite is not (at the time and state given)."""


class EvaluationError(JourdainError, ValueError):
    """Numeric evaluation was given bad input: wrong sizes, unknown names, NaN or inf values."""


class JourdainWarning(UserWarning):
    """Base class of the warnings of jourdain: a result that is computed but may not mean what
    it seems to (``warnings.simplefilter("error", JourdainWarning)`` turns them into errors)."""


_PACKAGE = str(Path(__file__).resolve().parent)


def warn(message: str, category: type[Warning] = JourdainWarning) -> None:
    """``warnings.warn`` attributed to the first caller outside jourdain (the user's line)."""
    frame: FrameType | None = sys._getframe(1)  # the caller of warn(), which warnings.warn calls stacklevel 2
    level = 2
    while frame is not None and str(Path(frame.f_code.co_filename).resolve()).startswith(_PACKAGE):
        frame = frame.f_back
        level += 1
    warnings.warn(message, category, stacklevel=level)
