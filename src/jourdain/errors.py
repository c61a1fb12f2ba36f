"""Exceptions of jourdain. Each names the model element (body, joint, parameter, file line) at fault."""

from __future__ import annotations


class JourdainError(Exception):
    """Base class of all errors raised by jourdain."""


class ModelError(JourdainError, ValueError):
    """The model description is inconsistent: unknown or duplicate names, bad mass data, ..."""


class SingularMassMatrix(JourdainError, ArithmeticError):
    """A mass matrix that must be positive definite is not (at the time and state given)."""


class EvaluationError(JourdainError, ValueError):
    """Numeric evaluation was given bad input: wrong sizes, unknown names, NaN or inf values."""
