"""Bodies with a planar inertia (:func:`jourdain.model.bodies.planar_inertia`): only the moment
about the normal of their plane is given, (0, 0, I_zz), as planar tools describe a body.

No 3-D body has such a tensor (the triangle inequality), but the motion of a body whose angular
velocity stays about its axis n needs no more: with ω = ω_n·n and n a principal axis, Euler's
equation ``I·ω̇ + ω × (I·ω)`` is ``I_nn·ω̇_n·n`` whatever the other moments. So the tensor is
accepted where the kinematics keep ω about n at every state (:func:`check_planar`, called by the
Newton–Euler stage: the rows of J_R and ω̄ across n vanish identically), and refused with the
body named otherwise. The reaction moments across the plane at the body's joint are those of a
body without products of inertia about n, which the model does not know: they are flagged
(:func:`planar_moments`, ``Reactions.planar_moments``).

Floor: the stages.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import JourdainError, ModelError
from ..graph import evaluate_float

if TYPE_CHECKING:
    from ..model.system import System
    from .kinematics import Kinematics

#: a component of ω across the axis counts as zero below this fraction of |ω| + 1 at a trial
#: state (terms that cancel, such as sin·cos − cos·sin, leave a few eps)
PLANAR_RTOL = 1e-9


def check_planar(kin: Kinematics) -> None:
    """Refuse a body with a planar inertia whose angular velocity can leave its axis: the
    rows of ``J_R`` and ``ω̄`` (body frame) across the axis must vanish, structurally or at
    three random states, times and inputs (the parameters at their values)."""
    system = kin.system
    for body, bk in zip(system.bodies, kin.bodies, strict=True):
        axis = getattr(body, "planar", None)
        if axis is None:
            continue
        a = "xyz".index(axis)
        across = [i for i in range(3) if i != a]
        exprs = [e for i in across for e in (*bk.J_R.rows[i], bk.omega_bar.rows[i][0])]
        exprs = [e for e in exprs if not (e.is_Number and e == 0)]
        if not exprs:
            continue
        full = [e for i in range(3) for e in (*bk.J_R.rows[i], bk.omega_bar.rows[i][0])]
        worst = _largest(system, exprs, full)
        if worst is None or worst > PLANAR_RTOL:
            what = ("cannot be checked at random states" if worst is None else
                    f"has components across {body.planar} (relative size {worst:.2g})")
            raise ModelError(
                f'body "{body.name}": its planar inertia (the moment about {body.planar} '
                f"alone) holds only for a body whose angular velocity stays about its "
                f"{body.planar} axis, and its angular velocity {what}; give its full inertia "
                "tensor")


def _largest(system: System, exprs: list, full: list) -> float | None:
    """The largest |e| of ``exprs`` relative to 1 + the largest of ``full`` over three random
    states (None where no state gives numbers)."""
    rng = np.random.default_rng(38)
    values = dict(system.parameter_values)
    worst = None
    for _ in range(3):
        for syms, lo, hi in ((system.y, -math.pi, math.pi), (system.yd, -2.0, 2.0),
                             (system.inputs, -1.0, 1.0)):
            values.update({str(s): float(rng.uniform(lo, hi)) for s in syms})
        values["t"] = float(rng.uniform(0.0, 2.0))
        try:
            nums = evaluate_float([*exprs, *full], values)
        except JourdainError:
            continue
        part, scale = nums[:len(exprs)], nums[len(exprs):]
        rel = max(abs(x) for x in part) / (1.0 + max(abs(x) for x in scale))
        worst = rel if worst is None else max(worst, rel)
    return worst


def planar_moments(system: System, joints: Sequence[Any], names: list[str]
                   ) -> tuple[str, ...]:
    """The reaction components (of ``names``, in the order of the joints' wrenches) that are
    pure moments across the plane of a body with a planar inertia, at that body's joint."""
    out = []
    k = 0
    for body, jr in zip(system.bodies, joints, strict=True):
        axis = getattr(body, "planar", None)
        for w in jr.wrenches:
            if axis is not None:
                a = "xyz".index(axis)
                pure_moment = all(x == 0 for x in w[:3]) and any(x != 0 for x in w[3:])
                if pure_moment and w[3 + a] == 0:
                    out.append(names[k])
            k += 1
    return tuple(out)


__all__ = ["PLANAR_RTOL", "check_planar", "planar_moments"]
