"""The optional dependencies of jourdain (the extras of ``pyproject.toml``) and the error that
names the extra to install when one is missing.

Every import of an optional package goes through :func:`require` (or raises
:func:`missing`), so that a missing package gives one message, the same from Python and from
every command (which exits with status 1, never with a traceback)::

    URDF import needs the extra: pip install 'jourdain[urdf]' (the package lxml is not installed)

Floor: foundations (imports only :mod:`jourdain.errors`).
"""

from __future__ import annotations

import importlib
from types import ModuleType

from .errors import JourdainError

#: the extras and what each is for (``pyproject.toml``'s ``[project.optional-dependencies]``)
EXTRAS: dict[str, str] = {
    "urdf": "URDF import (yourdfpy, lxml)",
    "fmu": "FMU export (the FMI 2.0 headers of FMPy)",
    "control": "python-control (jourdain.analysis.to_control, state_feedback)",
    "study": "parameter studies (xarray, h5netcdf; dask.distributed for clusters)",
    "casadi": "CasADi (jourdain.to_casadi: the equations of motion for optimal control)",
    "docs": "the documentation site (make docs)",
}


class MissingDependency(JourdainError, ImportError):
    """An optional dependency of jourdain is not installed; the message names the extra."""


def message(what: str, extra: str, package: str | None = None) -> str:
    """``<what> needs the extra: pip install 'jourdain[<extra>]'`` (and the missing package)."""
    if extra not in EXTRAS:
        raise ValueError(f"no extra {extra!r}; the extras are {', '.join(EXTRAS)}")
    text = f"{what} needs the extra: pip install 'jourdain[{extra}]'"
    return text + (f" (the package {package} is not installed)" if package else "")


def missing(what: str, extra: str, package: str | None = None) -> MissingDependency:
    """The :class:`MissingDependency` of :func:`message`."""
    return MissingDependency(message(what, extra, package))


def require(module: str, what: str, extra: str) -> ModuleType:
    """``import module``, or a :class:`MissingDependency` naming ``extra`` where it (or a
    package it needs) is not installed."""
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        package = (exc.name or module).split(".")[0]
        raise missing(what, extra, package) from None


__all__ = ["EXTRAS", "MissingDependency", "message", "missing", "require"]
