"""Where a NaN or an infinity comes from: the joint, body or force element at fault.

Compiled code only says that a number is not finite. When it is, the parts of the model are
evaluated one by one at the same state, from their own short expressions (no compilation, each
shared node once: :func:`jourdain.graph.evaluate_float`): every joint's relative
kinematics, every body's mass data, and the loads of every force element alone. A part whose
numbers are not finite, or whose expressions have no real value there (a spring of zero length
divides by its length), is named in the error.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import JourdainError
from ..graph import evaluate_float
from ..stages.kinematics import joint_motions, kinematics
from ..stages.newton_euler import applied_forces

if TYPE_CHECKING:
    from ..model.system import System


def state_values(system: System, y: np.ndarray, yd: np.ndarray, t: float, p: np.ndarray,
                 u: np.ndarray) -> dict[str, float]:
    """The numbers of one state by symbol name (parameters, y, ẏ, inputs and t), as
    :func:`jourdain.graph.evaluate_float` takes them."""
    vals = {str(s): float(v) for s, v in zip(system.parameter_symbols, p, strict=True)}
    vals.update({str(s): float(v) for s, v in zip(system.y, y, strict=True)})
    vals.update({str(s): float(v) for s, v in zip(system.yd, yd, strict=True)})
    vals.update({str(s): float(v) for s, v in zip(system.inputs, u, strict=True)})
    vals[str(system.t)] = float(t)
    return vals


def _fault(exprs: Sequence[Any], values: Mapping[str, float]) -> str | None:
    """None when every expression has a finite value, else why not."""
    try:
        nums = evaluate_float(list(exprs), values)
    except JourdainError as exc:
        return str(exc)
    if all(math.isfinite(x) for x in nums):
        return None
    return "gives NaN" if any(math.isnan(x) for x in nums) else "gives an infinite value"


def nonfinite_sources(system: System, y: np.ndarray, yd: np.ndarray, t: float, p: np.ndarray,
                      u: np.ndarray) -> list[str]:
    """The joints, bodies and force elements whose numbers are not finite at this state, each
    as ``'force "spring" (SpringDamper): 0.0**-0.5: division by zero or overflow'``."""
    values = state_values(system, y, yd, t, p, u)
    out: list[str] = []
    for body, jm in zip(system.bodies, joint_motions(system), strict=True):
        exprs = [x for row in jm.A for x in row]
        exprs += [*jm.d, *jm.v_bar, *jm.omega_bar, *jm.a_bar, *jm.alpha_bar]
        exprs += [x for c in (*jm.J_T.values(), *jm.J_R.values()) for x in c]
        why = _fault(exprs, values)
        if why:
            out.append(f'joint "{body.joint.name}" (body "{body.name}"): {why}')
        why = _fault([body.mass, *body.com, *(x for r in body.inertia for x in r)], values)
        if why:
            out.append(f'body "{body.name}" mass data: {why}')
    if system.forces:
        kin = kinematics(system)
        for fe in system.forces:
            loads = applied_forces(kin, [fe])
            why = _fault([x for bf in loads for x in (*bf.f, *bf.l)], values)
            if why:
                out.append(f'force "{fe.name}" ({type(fe).__name__}): {why}')
    return out


def nonfinite_message(system: System, quantities: Sequence[str], y: np.ndarray, yd: np.ndarray,
                      t: float, p: np.ndarray, u: np.ndarray) -> str:
    """The message of an evaluation whose results ``quantities`` hold NaN or inf."""
    state = ", ".join(f"{n}={v:.6g}" for n, v in zip(system.coordinate_names, y, strict=True))
    rates = ", ".join(f"{n}_d={v:.6g}" for n, v in zip(system.coordinate_names, yd, strict=True))
    msg = (f"{', '.join(quantities)} of {system.name!r} contain NaN or inf at t = {t:.9g}, "
           f"state {state}; rates {rates}")
    try:
        sources = nonfinite_sources(system, y, yd, t, p, u)
    except JourdainError:  # the trace itself failed: say what is known
        sources = []
    if sources:
        return msg + "; caused by " + "; ".join(sources)
    return msg + " (no single joint, body or force element is at fault: check the parameters " \
                 "and inputs)"
