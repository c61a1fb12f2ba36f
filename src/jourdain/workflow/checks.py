"""The checks of ``jourdain check`` beyond the model file's own: the equations of motion at
the model's initial state are finite, and M is positive definite there."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import JourdainError
from ..graph import evaluate_float
from ..model.expressions import values_at

#: M counts as singular where its smallest eigenvalue is below this fraction of its largest
#: (the relative pivot limit of the integrator's Cholesky factorization)
SINGULAR_RTOL = 1e-13


def check_initial_state(model: Any) -> None:
    """The equations of motion at the model's initial state (its [simulation] y0, yd0 and
    inputs at t = 0, else zeros) must be finite numbers: a NaN there (a spring of zero length,
    a square root of a negative number) is a model error naming its source. M must be positive
    definite there: a coordinate that moves no mass or inertia (every body it moves is massless)
    or a singular configuration leaves ÿ undetermined, and nothing can be simulated."""
    system, sim = model.system, model.simulation
    y0 = list(sim.y0) or [0.0] * system.f
    yd0 = list(sim.yd0) or [0.0] * system.f
    given = dict(sim.inputs)
    values = {**system.parameter_values, "t": 0.0}
    try:
        u = [evaluate_float([given[n]], values)[0] if n in given else 0.0
             for n in system.input_names]
        out = system.evaluate(y0, yd0, 0.0, inputs=u or None)
    except JourdainError as exc:
        raise model.error(f"at the initial state: {exc}") from None
    problem = mass_matrix_problem(system, np.asarray(out["M"], float), values,
                                  out.get("independent"))
    if problem:
        state = ", ".join(f"{c}={v:g}" for c, v in zip(system.coordinate_names, y0, strict=True))
        raise model.error(f"at the initial state ({state}): {problem}")


def mass_matrix_problem(system: Any, M: np.ndarray, values: dict[str, float],
                        coordinates: Any = None) -> str | None:
    """Why M is not positive definite (None when it is): the coordinates that move no mass or
    inertia and the massless bodies they move, else the eigenvalues of a singular
    configuration. ``coordinates``: the names of M's rows where they are not the system's
    coordinates (a closed system's independent ones)."""
    M = 0.5 * M + 0.5 * M.T  # halves first: entries near 1e308 stay finite
    if not np.isfinite(M).all():  # never factorized (LAPACK may not return on inf)
        return ("the mass matrix M is not finite (its entries exceed the floating-point "
                "range): check the magnitudes of the masses, inertias and lengths")
    w = np.linalg.eigvalsh(M) if M.size else np.ones(1)
    top = max(float(w.max()), 0.0)
    if w.min() > SINGULAR_RTOL * top:
        return None
    coords = list(coordinates or system.coordinate_names)
    if len(coords) != M.shape[0]:  # a closed system's M, in coordinates not named
        coords = [f"coordinate {i + 1}" for i in range(M.shape[0])]
    idle = [c for i, c in enumerate(coords) if not M[i, i] > SINGULAR_RTOL * top]
    if idle:
        moved: dict[str, set[str]] = {}  # body -> the coordinates that move it
        for b in system.bodies:
            own = {str(c) for c in b.joint.coordinates}
            moved[b.name] = own | moved.get(b.parent, set())
        bodies = [b for b in system.bodies if moved[b.name] & set(idle)]
        massless = [b.name for b in bodies  # NaN (no value) counts as not massless
                    if not any(values_at([b.mass, *(e for row in b.inertia for e in row)],
                                         values))]
        named = ", ".join(f'body "{n}"' for n in massless)
        one = len(massless) == 1
        who = (f"; {'it moves' if len(idle) == 1 else 'they move'} only {named}, which "
               f"{'has' if one else 'have'} no mass and no inertia"
               if massless and len(massless) == len(bodies) else "")
        fix = ("it" if one else "one of them") if who else "a body they move"
        return (f"the mass matrix M is singular: no mass or inertia moves with "
                f"{', '.join(idle)}{who}; give {fix} a mass or an inertia")
    return (f"the mass matrix M is not positive definite (its eigenvalues range from "
            f"{w.min():.3g} to {top:.3g}): the coordinates are not independent at this state "
            "(a singular configuration of the joints); start from another state")
