"""A parsed study: which model, which cases, what to compute per case.

:class:`StudySpec` holds what a study file says (read by :mod:`jourdain.study.reader`, format
in ``docs/studies.md``): the model file's text and hash, the design (grid, list or seeded
random samples) of the varied parameters and initial states, and what to compute per case.
:meth:`StudySpec.cases` forms the cases, reproducibly from the seed.
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import JourdainError

__all__ = ["DESIGNS", "DISTRIBUTIONS", "EVALUATE_OUTPUTS", "MAX_CASES", "MAX_FILE_BYTES",
           "RESERVED", "StudyError", "StudySpec", "Varied"]

#: How the cases are formed from the varied quantities.
DESIGNS = ("grid", "list", "random")
#: Distributions of a random design and their parameters (NumPy's ``Generator`` methods):
#: uniform on [low, high); normal with mean and standard deviation std; lognormal: ln X is
#: normal with mean mu and standard deviation sigma (median e^mu).
DISTRIBUTIONS = {"uniform": ("low", "high"), "normal": ("mean", "std"),
                 "lognormal": ("mu", "sigma")}
#: What ``[compute.evaluate]`` can give per case.
EVALUATE_OUTPUTS = ("M", "k", "q", "ydd")
#: Largest number of cases of one study (a 10⁷-case grid is 80 MB per scalar output).
MAX_CASES = 10_000_000
#: Largest study file read (bytes).
MAX_FILE_BYTES = 1_000_000


#: Names of the results' dimensions and outputs that a varied quantity cannot have.
RESERVED = frozenset({"case", "coordinate", "coordinate_j", "state", "mode", "time",
                      "wrench_component", "error", "final", "verdict", "max_real_part",
                      "eigenvalue_real", "eigenvalue_imag", "omega", "excitation",
                      "frf_magnitude", "frf_phase", "linearized_about", "closure_residual",
                      "closure_rate_residual"})


class StudyError(JourdainError, ValueError):
    """A mistake in a study file or study arguments; ``file`` and ``line`` say where."""

    def __init__(self, message: str, file: str = "<study>", line: int | None = None) -> None:
        super().__init__(message)
        self.file = file
        self.line = line


@dataclass(frozen=True)
class Varied:
    """One varied quantity: a parameter, an initial coordinate or an initial rate.

    ``kind`` is ``"parameter"``, ``"y0"`` or ``"yd0"``; ``values`` the values of a grid axis or
    a list (None for a random design); ``distribution`` and ``arguments`` those of a random
    design."""

    name: str
    kind: str
    values: tuple[float, ...] | None = None
    distribution: str | None = None
    arguments: tuple[float, ...] = ()


@dataclass(frozen=True)
class StudySpec:
    """A parsed study: the model file's text, the design and what to compute per case.

    Attributes
    ----------
    model_path : the model file (as named, resolved against the study file's folder)
    model_text : its contents (shipped to workers, which rebuild the model from it)
    model_hash : SHA-256 of ``model_text`` (every worker checks it)
    design : "grid", "list" or "random"
    varied : the varied quantities, in the file's order (a grid's axes in this order, the last
        varying fastest)
    samples, seed : number of cases and seed of a random design
    compute : what to compute, ``{"evaluate": {...}, "linearize": {...}, ...}`` (checked)
    block : cases per block (the unit of work and of saving)
    name : the study's name
    source : the study file's text (kept in the results)
    """

    model_path: str
    model_text: str
    model_hash: str
    design: str
    varied: tuple[Varied, ...]
    compute: Mapping[str, Mapping[str, Any]]
    samples: int = 0
    seed: int | None = None
    block: int = 512
    name: str = "study"
    source: str = field(default="", repr=False)
    filename: str = "<study>"

    @property
    def shape(self) -> tuple[int, ...]:
        """The grid's shape (one axis per varied quantity), else ``(n_cases,)``."""
        if self.design == "grid":
            return tuple(len(v.values or ()) for v in self.varied)
        if self.design == "list":
            return (len(self.varied[0].values or ()),) if self.varied else (1,)
        return (self.samples,)

    @property
    def n_cases(self) -> int:
        return int(np.prod(self.shape))

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(v.name for v in self.varied)

    @property
    def spec_hash(self) -> str:
        """SHA-256 of what decides the results (the study text and the model's hash): a saved
        partial study is resumed only when this matches."""
        h = hashlib.sha256()
        for part in (self.source, self.model_hash, self.model_path, str(self.block)):
            h.update(part.encode())
            h.update(b"\0")
        return h.hexdigest()

    def cases(self) -> np.ndarray:
        """The values of the varied quantities, ``(n_cases, n_varied)``, in case order (a
        grid in C order; a random design drawn from ``seed``, one quantity after the other in
        the file's order: the same seed gives the same cases on any machine)."""
        n = self.n_cases
        if not self.varied:
            return np.zeros((n, 0))
        if self.design == "grid":
            axes = [np.asarray(v.values, dtype=float) for v in self.varied]
            mesh = np.meshgrid(*axes, indexing="ij")
            return np.stack([m.reshape(-1) for m in mesh], axis=1)
        if self.design == "list":
            return np.stack([np.asarray(v.values, dtype=float) for v in self.varied], axis=1)
        rng = np.random.default_rng(self.seed)
        cols = []
        for v in self.varied:
            a, b = v.arguments
            if v.distribution == "uniform":
                cols.append(rng.uniform(a, b, n))
            elif v.distribution == "normal":
                cols.append(rng.normal(a, b, n))
            else:
                cols.append(rng.lognormal(a, b, n))
        return np.stack(cols, axis=1)
