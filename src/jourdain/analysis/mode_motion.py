"""A vibration mode as a motion: ``y(t) = y_s(t) + Re(A·s·e^{λt})``, for plots and the 3-D view.

The linearization ``M̃·η̈ + P·η̇ + Q·η = 0`` about a nominal motion ``y_s`` has the free
solutions ``η = Re(A·s·e^{λt})`` with ``λ`` an eigenvalue and ``s`` its mode shape (the position
part of the eigenvector of the state matrix, :func:`jourdain.analysis.modes.modes`; its rates are
``λ·s``). :func:`mode_motion` samples one of them on the nominal motion as
:class:`~jourdain.simulation.Results`, so that everything that shows a simulated motion shows the
mode: ``jd.view(jd.mode_motion(lin, 1))`` animates the first mode in the 3-D view (an elastic
body's line bends in its mode shape), ``Results.plot`` draws its coordinates. It is the motion
of the linear equations: for small amplitudes that of the model, and exact for
``M̃·η̈ + P·η̇ + Q·η`` (``tests/test_mode_motion.py`` checks the residual).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ..errors import EvaluationError, refuse_closed
from ..graph import evaluate_float_many
from ..simulation.results import Results
from .modes import modes
from .state_space import state_space

__all__ = ["mode_motion"]


def mode_motion(lin: Any, mode: int = 1, amplitude: float = 0.1, periods: float = 2.0,
                samples: int = 121, t0: float = 0.0,
                parameters: Mapping[str, float] | None = None) -> Results:
    """The oscillating mode number ``mode`` (1: the lowest natural frequency, counting each
    conjugate pair once) of the linearization ``lin`` as a motion over ``periods`` of its damped
    period from ``t0``, in ``samples`` samples: ``Results`` whose ``y``, ``yd``, ``ydd`` are the
    nominal motion plus ``Re(A·s·e^{λ(t − t0)})`` and its derivatives, with ``A = amplitude``
    and the shape ``s`` scaled so that its largest coordinate is 1 (in that coordinate's
    unit), at the ``parameters`` (default: the model's). For a time-dependent (periodic)
    linearization the mode is that of the matrices at ``t0``.

    Raises ClosedSystemError for the linearization of a closed system (its state is not the
    system's coordinates) and EvaluationError for a mode number out of range or arguments that
    are not positive finite numbers.
    """
    system = lin.system
    refuse_closed(system, "mode_motion", "the state of a closed system's linearization is its "
                  "independent coordinates, not the motion of all of them")
    ss = state_space(lin, t0, parameters, allow_time_variant=True)
    for what, v in (("amplitude", amplitude), ("periods", periods)):
        if not (np.isfinite(v) and v > 0):
            raise EvaluationError(f"mode_motion: {what} must be a positive number, got {v!r}")
    if int(samples) != samples or samples < 2:
        raise EvaluationError(f"mode_motion: samples must be an integer ≥ 2, got {samples!r}")
    m = modes(ss)
    osc = m.oscillating()
    if not 1 <= int(mode) <= len(osc):
        raise EvaluationError(f"mode_motion: mode {mode} asked, the linearization has "
                              f"{len(osc)} oscillating modes (1 … {len(osc)})")
    k = int(osc[int(mode) - 1])
    lam, s = complex(m.eigenvalues[k]), m.shapes[:, k]
    t = t0 + np.linspace(0.0, periods * 2 * np.pi / abs(lam.imag), int(samples))
    e = amplitude * np.exp(np.outer(t - t0, [lam]))  # (N, 1)
    eta = (e * s[None, :]).real
    eta_d = (e * lam * s[None, :]).real
    eta_dd = (e * lam**2 * s[None, :]).real
    values = {**system.parameter_values, **dict(parameters or {})}
    nominal = [*lin.y_s.entries(), *lin.yd_s.entries(), *lin.ydd_s.entries(),
               *lin.u_s.entries()]
    nums = evaluate_float_many(nominal, [{**values, "t": float(tv)} for tv in t])
    f, nu = system.f, len(system.input_names)
    y, yd, ydd = (nums[:, i * f:(i + 1) * f] for i in range(3))
    u = nums[:, 3 * f:3 * f + nu]
    return Results(system, t, y + eta, yd + eta_d, ydd + eta_dd, u, np.full(len(t), np.nan),
                   values, method=f"mode {mode}", status="finished",
                   message=(f"mode {mode} of the linearization: λ = {lam:.6g}, "
                            f"f = {abs(lam.imag) / (2 * np.pi):.6g} Hz, amplitude {amplitude:g}"))
