"""Frequency response of a linearized system to harmonic excitation.

For a harmonic excitation ``h = ĥ·e^{iΩt}`` (or inputs ``Δu = û·e^{iΩt}``) the steady-state
response is ``η = η̂·e^{iΩt}`` with

    η̂ = H(Ω)·ĥ,   H(Ω) = (Q − Ω²·M̃ + iΩ·P)⁻¹          (dynamic compliance)
    η̂ = H(Ω)·B·û                                       (inputs)

so a real excitation ``ĥ·cos(Ωt)`` gives ``η = |η̂|·cos(Ωt + arg η̂)``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import EvaluationError
from .state_space import AnyLinearization, StateSpace, state_space


@dataclass(frozen=True)
class FrequencyResponse:
    """Steady-state response amplitudes over a range of excitation frequencies.

    Attributes
    ----------
    omega : (n,) array
        Excitation angular frequencies in rad/s.
    response : (n, f, m) complex array
        ``η̂`` per unit amplitude of each of the m excitations.
    coordinate_names : tuple of str
        The f outputs (coordinates).
    excitation_names : tuple of str
        The m excitations: input names, coordinate names for ``h``, or ``"e0", "e1", …``.
    """

    omega: np.ndarray
    response: np.ndarray
    coordinate_names: tuple[str, ...]
    excitation_names: tuple[str, ...]

    @property
    def magnitude(self) -> np.ndarray:
        """``|η̂|``, shape (n, f, m)."""
        return np.abs(self.response)

    @property
    def phase(self) -> np.ndarray:
        """Phase ``arg η̂`` in radians, unwrapped along the frequency axis, shape (n, f, m)."""
        return np.unwrap(np.angle(self.response), axis=0)

    def of(self, coordinate: str, excitation: str) -> np.ndarray:
        """The complex response of one coordinate to one excitation, shape (n,)."""
        try:
            i = self.coordinate_names.index(coordinate)
            j = self.excitation_names.index(excitation)
        except ValueError:
            raise EvaluationError(
                f"unknown coordinate {coordinate!r} or excitation {excitation!r}; coordinates "
                f"{list(self.coordinate_names)}, excitations {list(self.excitation_names)}"
            ) from None
        return self.response[:, i, j]


def frequency_response(system: StateSpace | AnyLinearization,
                       omega: Sequence[float] | np.ndarray, excitation: Any = "inputs",
                       t: float | None = None,
                       parameters: Mapping[str, float] | None = None) -> FrequencyResponse:
    """Magnitude and phase of ``η`` for harmonic excitation over the frequencies ``omega``.

    Parameters
    ----------
    system : StateSpace or Linearization or CompiledLinearization
    omega : sequence of float
        Excitation angular frequencies (rad/s), finite and non-negative.
    excitation : "inputs", "h", or an (f, m) array
        ``"inputs"``: the system's inputs through B; ``"h"``: a unit generalized force on each
        coordinate (the dynamic compliance matrix); an array: the columns are force patterns ĥ.
    """
    ss = system if isinstance(system, StateSpace) else state_space(system, t, parameters)
    w = np.asarray(omega, dtype=float).reshape(-1)
    if w.size == 0 or not np.all(np.isfinite(w)) or np.any(w < 0):
        raise EvaluationError("omega must be a non-empty sequence of finite, non-negative "
                              "frequencies in rad/s")
    f = ss.f
    if isinstance(excitation, str) and excitation == "inputs":
        if not ss.input_names:
            raise EvaluationError('the system has no inputs; use excitation="h" or an (f, m) '
                                  "array of force patterns")
        F = ss.B_u
        names = ss.input_names
    elif isinstance(excitation, str) and excitation == "h":
        F = np.eye(f)
        names = ss.coordinate_names
    elif isinstance(excitation, str):
        raise EvaluationError(f'excitation must be "inputs", "h" or an array, got {excitation!r}')
    else:
        F = np.asarray(excitation, dtype=float)
        if F.ndim == 1:
            F = F.reshape(-1, 1)
        if F.shape[0] != f or not np.all(np.isfinite(F)):
            raise EvaluationError(f"excitation array must have {f} finite rows (one per "
                                  f"coordinate), got shape {F.shape}")
        names = tuple(f"e{j}" for j in range(F.shape[1]))
    out = np.empty((w.size, f, F.shape[1]), dtype=complex)
    for k, wk in enumerate(w):
        Z = ss.Q - wk**2 * ss.M_tilde + 1j * wk * ss.P
        try:
            out[k] = np.linalg.solve(Z, F)
        except np.linalg.LinAlgError:
            raise EvaluationError(
                f"the dynamic stiffness Q - Ω²M̃ + iΩP is singular at Ω = {wk} rad/s "
                "(resonance of an undamped mode or a rigid-body mode at Ω = 0)"
            ) from None
    return FrequencyResponse(omega=w, response=out, coordinate_names=ss.coordinate_names,
                             excitation_names=tuple(names))
