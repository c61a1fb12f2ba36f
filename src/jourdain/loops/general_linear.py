"""Linearization of a general system (velocity constraints, METHOD.md §7) about a steady
motion or an equilibrium, in the seed's form ``M̃·η̈ + P·η̇ + Q·η = h`` with D, G, K, N.

The first-order system is ``ẏ_i = (L·z + l)_i``, ``M(y)·ż + k(y, z) = q(y, z)`` in the state
``x = (y_i, z)`` (:mod:`jourdain.loops.general`). Its derivatives at the nominal state are
taken by the complex step, ``∂F/∂x_j = Im F(x + iη·e_j)/η``: the whole evaluation (Newton on
the holonomic rows, the velocity map, the projection) runs in complex arithmetic, so the
derivatives carry no truncation error and no cancellation (exact to rounding, where central
differences lose half the digits). With ``ż_s`` the nominal accelerations (held),

    M̃ = M,  P = ∂(k − q)/∂z,  Q = ∂(M·ż_s + k − q)/∂y,  h = q − k − M·ż_s

in the coordinates η whose rates are speeds (``speeds=[...]`` coordinate names; speeds given by
definition: their quasi-coordinates, where no coordinate acts on the equations). Coordinates
without a speed of their own (the position on the ground, the heading of a bicycle, a wheel
angle) must be cyclic, absent from the equations: they are left out. A speed whose coordinate
is cyclic and which enters no other equation (a wheel's spin rate at steady rolling: the
neighbouring steady motions) is left out with it. Both are listed in ``cyclic``; what remains
is the motion whose stability decides (the benchmark bicycle's lean and steer). Velocity
constraints alone give a ``P`` and a ``Q`` that are not symmetric: damping-like and
circulatory terms without any damper.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import symengine as se

from ..errors import EvaluationError
from ..model import System
from .general import GeneralEvaluator
from .linearization import LoopLinearization, mass_inverse

#: a derivative counts as zero below this fraction of the largest entry (an identity test,
#: as for the cyclic coordinates of trees: jourdain.analysis.cyclic.CYCLIC_RTOL)
ZERO_RTOL = 1e-9
#: the complex step (any tiny number: no difference is formed)
STEP = 1e-60


@dataclass(frozen=True)
class GeneralLinearization(LoopLinearization):
    """:class:`jourdain.loops.linearization.LoopLinearization` of a general system, with the
    ``speeds`` of η, the coordinates left out as ``cyclic``, the full first-order Jacobian
    ``A_x`` in ``x = (y_i, z)`` (``x_names``) and the ``nominal`` it was taken about
    (:meth:`at` linearizes again for other parameter values)."""

    speeds: tuple[str, ...] = ()
    cyclic: tuple[str, ...] = ()
    A_x: np.ndarray | None = None
    x_names: tuple[str, ...] = ()
    nominal: Any = None

    @property
    def cyclic_in_eta(self) -> tuple[str, ...]:
        """The coordinates of η that are cyclic (their columns of Q vanish): Routh's reduction
        of :func:`jourdain.stability` leaves them out (a heading, kept for its rate)."""
        scale = max(float(np.max(np.abs(self.Q), initial=0.0)),
                    float(np.max(np.abs(self.M_tilde), initial=0.0)))
        return tuple(n for i, n in enumerate(self.names)
                     if np.all(np.abs(self.Q[:, i]) <= ZERO_RTOL * scale))

    def at(self, parameters: Mapping[str, float]) -> GeneralLinearization:
        """The linearization about the same nominal (its expressions of the parameters
        evaluated anew) for other parameter values."""
        return linearize_general(self.system, self.nominal,
                                 {**dict(self.parameters or {}), **dict(parameters)})


def _value(v: Any, values: Mapping[str, float], key: str) -> float:
    """A nominal value: a number, or a SymEngine expression of the parameters (model files
    give text, parsed by their safe parser before it comes here)."""
    if isinstance(v, se.Basic):
        free = {str(s) for s in v.free_symbols}
        unknown = sorted(free - set(values))
        if unknown:
            raise EvaluationError(f"nominal {key} = {v}: unknown name(s) {', '.join(unknown)}; "
                                  "a steady motion's values may use the parameters")
        v = v.subs({se.Symbol(k): values[k] for k in free})
    try:
        out = float(v)
    except (TypeError, ValueError, RuntimeError):
        raise EvaluationError(f"nominal {key}: expected a number or an expression of the "
                              f"parameters, got {v!r}") from None
    return out


def _nominal_state(system: System, nominal: Any, values: Mapping[str, float]
                   ) -> tuple[np.ndarray, np.ndarray, dict[str, float]]:
    names = system.coordinate_names
    f = system.f
    y, yd = np.zeros(f), np.zeros(f)
    acc: dict[str, float] = {}
    if not isinstance(nominal, Mapping):
        y = np.asarray(nominal, dtype=float).reshape(-1)
        if y.size != f:
            raise EvaluationError(f"nominal: {f} coordinates expected ({', '.join(names)})")
        return y, yd, acc
    for k, v in nominal.items():
        key = str(k)
        val = _value(v, values, key)
        if key in names:
            y[names.index(key)] = val
        elif key.endswith("_dd"):
            acc[key[:-1]] = val  # by speed name
        elif key.endswith("_d") and key[:-2] in names:
            yd[names.index(key[:-2])] = val
        else:
            raise EvaluationError(f'nominal: unknown coordinate "{key}"; coordinates are '
                                  f"{', '.join(names)}")
    return y, yd, acc


def linearize_general(system: System, nominal: Any,
                      parameters: Mapping[str, float] | None = None, t: float = 0.0
                      ) -> GeneralLinearization:
    """Linearize the general ``system`` about the state ``nominal`` (``{coordinate: value,
    "<coordinate>_d": rate}``, numbers or expressions of the parameters; the dependent
    coordinates and rates follow from the rows): see the module docstring."""
    values = {**system.parameter_values, **dict(parameters or {})}
    y0, yd0, acc = _nominal_state(system, nominal, values)
    ev = GeneralEvaluator(system, y0, t, values)
    x0 = ev.initial(y0, yd0, t)
    s0 = ev.accelerations(x0, t)
    ch = ev.choice
    zd_s = np.array([acc.get(n, 0.0) for n in ch.speeds])
    evc = GeneralEvaluator(system, s0["y"], t, values, complex_=True, choice=ch)
    yref = s0["y"].astype(complex)
    ni, g = len(ch.independent), len(ch.speeds)
    nx = ni + g

    def parts(x: np.ndarray) -> np.ndarray:
        evc.y_guess = yref.copy()
        s = evc.state(x, t)
        r = s["k"] - s["q"] + s["M"] @ zd_s
        return np.concatenate([s["yd"][list(ch.independent)], r])

    J = np.zeros((ni + g, nx))
    for j in range(nx):
        xc = x0.astype(complex)
        xc[j] += 1j * STEP
        J[:, j] = np.imag(parts(xc)) / STEP
    Jy, Jr = J[:ni], J[ni:]
    M = np.real(s0["M"])
    h = np.real(s0["q"] - s0["k"]) - M @ zd_s
    names = system.coordinate_names
    x_names = (*(names[j] for j in ch.independent), *ch.speeds)
    if ch.speed_coordinates is None:
        return _in_quasi_coordinates(system, ch, M, Jy, Jr, h, s0, values, t, x_names,
                                     nominal)
    pos = {j: i for i, j in enumerate(ch.independent)}
    found = [pos.get(j) for j in ch.speed_coordinates]
    if any(m is None for m in found):
        bad = [names[j] for j, m in zip(ch.speed_coordinates, found, strict=True) if m is None]
        raise EvaluationError(f"{system.name}: the speeds' coordinates {', '.join(bad)} are "
                              "dependent; choose them independent (independent=[...])")
    matched: list[int] = [int(m) for m in found if m is not None]
    scale = max(float(np.max(np.abs(Jr), initial=0.0)), float(np.max(np.abs(M))))
    tol = ZERO_RTOL * scale
    zero_col = [bool(np.all(np.abs(Jr[:, i]) <= tol)) for i in range(ni)]
    unmatched = [i for i in range(ni) if i not in matched]
    for i in unmatched:
        if not zero_col[i] or np.any(np.abs(Jy[matched, i]) > ZERO_RTOL):
            raise EvaluationError(
                f"{system.name}: the coordinate {names[ch.independent[i]]} has no speed of "
                "its own and is not cyclic here (the equations depend on it): the motion has "
                "no second-order form in these speeds")
    cyc = [names[ch.independent[i]] for i in unmatched]
    keep = []
    for k, i in enumerate(matched):
        others = [m for m in range(g) if m != k]
        decoupled = (zero_col[i] and np.all(np.abs(Jr[others, ni + k]) <= tol)
                     and np.all(np.abs(M[others, k]) <= ZERO_RTOL * float(np.max(np.abs(M)))))
        if decoupled and g > 1:
            cyc.append(names[ch.independent[i]])
        else:
            keep.append(k)
    kz = [ni + k for k in keep]
    ky = [matched[k] for k in keep]
    ik = np.array(keep, dtype=int)
    Mt = M[np.ix_(ik, ik)]
    P = Jr[np.ix_(ik, np.array(kz, dtype=int))]
    Q = Jr[np.ix_(ik, np.array(ky, dtype=int))]
    n = len(keep)
    Mi = mass_inverse(system, Mt)
    Minv_Q, Minv_P = Mi @ Q, Mi @ P
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv_Q, -Minv_P]])
    ev_ = np.linalg.eigvals(A)
    ev_ = ev_[np.lexsort((ev_.imag, ev_.real))]
    eta = tuple(names[ch.speed_coordinates[k]] for k in keep)
    A_x = np.vstack([Jy, -mass_inverse(system, M) @ Jr])
    return GeneralLinearization(
        names=eta, y_s=np.real(s0["y"])[[ch.speed_coordinates[k] for k in keep]],
        z_s=np.real(s0["y"]), M_tilde=Mt, P=P, Q=Q, h=h[keep], D=(P + P.T) / 2,
        G=(P - P.T) / 2, K=(Q + Q.T) / 2, N=(Q - Q.T) / 2, A=A, eigenvalues=ev_,
        system=system, t=t, parameters=dict(values),
        speeds=tuple(ch.speeds[k] for k in keep), cyclic=tuple(cyc), A_x=A_x,
        x_names=x_names, nominal=nominal)


def _in_quasi_coordinates(system: System, ch: Any, M: np.ndarray, Jy: np.ndarray,
                          Jr: np.ndarray, h: np.ndarray, s0: dict, values: dict, t: float,
                          x_names: tuple, nominal: Any) -> GeneralLinearization:
    """Speeds given by definition (not rates of coordinates): where every coordinate is
    cyclic (the equations in z do not depend on them, as for a vehicle on flat ground), the
    linearization is in the quasi-coordinates π of the speeds (π̇ = z): M̃ = M,
    P = ∂(k − q)/∂z, Q = 0, and Routh's verdict is the one on the speeds alone."""
    ni, g = len(ch.independent), len(ch.speeds)
    names = system.coordinate_names
    scale = max(float(np.max(np.abs(Jr), initial=0.0)), float(np.max(np.abs(M))))
    acting = [names[ch.independent[i]] for i in range(ni)
              if np.any(np.abs(Jr[:, i]) > ZERO_RTOL * scale)]
    if acting:
        raise EvaluationError(
            f"{system.name}: the equations in the speeds {', '.join(ch.speeds)} depend on the "
            f"coordinates {', '.join(acting)}, which have no speed of their own: the motion has "
            "no second-order form in these speeds (give speeds=[coordinate names] for them)")
    P = Jr[:, ni:]
    Q = np.zeros((g, g))
    Mi = mass_inverse(system, M)
    A = np.block([[np.zeros((g, g)), np.eye(g)], [np.zeros((g, g)), -Mi @ P]])
    lam = np.linalg.eigvals(A)
    lam = lam[np.lexsort((lam.imag, lam.real))]
    return GeneralLinearization(
        names=tuple(ch.speeds), y_s=np.zeros(g), z_s=np.real(s0["y"]), M_tilde=M, P=P, Q=Q,
        h=h, D=(P + P.T) / 2, G=(P - P.T) / 2, K=Q, N=Q, A=A, eigenvalues=lam, system=system,
        t=t, parameters=dict(values), speeds=tuple(ch.speeds),
        cyclic=tuple(names[j] for j in ch.independent),
        A_x=np.vstack([Jy, -Mi @ Jr]), x_names=x_names, nominal=nominal)


__all__ = ["GeneralLinearization", "linearize_general"]
