"""Exceptions of jourdain. Each names the model element (body, joint, parameter, file line) at fault."""

from __future__ import annotations

import re
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


class ClosedSystemError(ModelError):
    """A function of the open tree was given a closed system (one with closing joints), or a
    capability does not handle closing joints yet. It names the system, the closing joints and
    the capability; jourdain never falls back to the open tree (ask for ``system.tree`` by
    name where the open tree is meant)."""

    def __init__(self, system: object, capability: str, hint: str = "") -> None:
        names = ", ".join(c.name for c in getattr(system, "closing", ()))
        contacts = ", ".join(c.name for c in getattr(system, "contacts", ()))
        if contacts:
            what = (f"constrained by the contact(s) {contacts}"
                    + (f" and closed by the closing joint(s) {names}" if names else ""))
        elif names:
            what = f"closed by the closing joint(s) {names}"
        else:
            what = "a general system (generalized velocities other than ẏ)"
        msg = f"{getattr(system, 'name', 'the system')!r} is {what}: {capability}"
        super().__init__(msg + (f"; {hint}" if hint else ""))
        self.capability = capability


def refuse_closed(system: object, capability: str, hint: str = "") -> None:
    """Raise :class:`ClosedSystemError` when ``system`` has closing joints, contacts or
    generalized velocities of its own (anything the open tree would leave out)."""
    if getattr(system, "closing", ()) or getattr(system, "is_general", False):
        raise ClosedSystemError(system, capability, hint)


class SingularConfiguration(JourdainError, ArithmeticError):
    """The dependent coordinates of a closed system cannot be solved: ``Φ_d`` is singular or
    too ill-conditioned at the time and state given (a change of the partition may help where
    the constraint Jacobian ``Φ_y`` itself keeps full rank). Attributes ``t``, ``z``, ``zd``
    (the tree's coordinates and rates there), ``cond``, ``rank`` (of Φ_y), ``suggestion`` (a
    partition that is well-conditioned there, or None)."""

    def __init__(self, message: str, t: float = float("nan"), z: object = None,
                 zd: object = None, cond: float = float("inf"), rank: int | None = None,
                 suggestion: tuple[str, ...] | None = None) -> None:
        super().__init__(message)
        self.t, self.z, self.zd, self.cond, self.rank = t, z, zd, cond, rank
        self.suggestion = suggestion


class AssemblyError(JourdainError, ValueError):
    """Newton's method found no configuration of a closed system on its constraint manifold
    near the one given."""


class JourdainWarning(UserWarning):
    """Base class of the warnings of jourdain: a result that is computed but may not mean what
    it seems to (``warnings.simplefilter("error", JourdainWarning)`` turns them into errors)."""


class StiffnessWarning(JourdainWarning):
    """A simulation whose method does not suit the motion: an explicit method held at its
    stability limit by a fast motion (stiff: an implicit method steps over it), or Radau
    resolving every oscillation of the fastest one (an explicit method takes fewer, cheaper
    steps). ``command_line``: the same advice in the words of ``jourdain simulate``."""

    def __init__(self, message: str, command_line: str = "") -> None:
        super().__init__(message)
        self.command_line = command_line or message


_PACKAGE = str(Path(__file__).resolve().parent)


def warn(message: str | Warning, category: type[Warning] = JourdainWarning) -> None:
    """``warnings.warn`` attributed to the first caller outside jourdain (the user's line)."""
    frame: FrameType | None = sys._getframe(1)  # the caller of warn(), which warnings.warn calls stacklevel 2
    level = 2
    while frame is not None and str(Path(frame.f_code.co_filename).resolve()).startswith(_PACKAGE):
        frame = frame.f_back
        level += 1
    warnings.warn(message, category, stacklevel=level)


def shorten_words(text: str, n: int = 160) -> str:
    """``text`` with every run of more than ``n`` characters without a space (a value pasted
    into a message: 5 000 characters of an invalid string) shortened in the middle, saying
    how long it was."""
    if len(text) <= n:
        return text
    return re.sub(r"\S{" + str(n + 1) + ",}",
                  lambda m: f"{m.group()[:n // 2]}…{m.group()[-n // 4:]} "
                            f"({len(m.group())} characters)", text)
