"""A loaded model in figures and names: bodies, joints, degrees of freedom and the
constrained directions of each joint (``jourdain check``, the report's model section)."""

from __future__ import annotations

from typing import Any

from ..analysis.cyclic import cyclic_coordinates
from ..errors import JourdainError
from .capability import has_capability


def summary(model: Any) -> dict[str, Any]:
    """Bodies, joints, degrees of freedom and constrained directions of a loaded model.

    The constrained directions of each joint come from the reactions stage (the columns of Q̄)
    when it is available, else from the joint's own freedoms (6 minus them).
    """
    system = model.system
    directions: dict[str, list[str]] = {}
    if has_capability("reactions"):
        try:
            for jr in system.tree.reactions().joints:  # the closing joints: loop_summary
                directions[jr.joint.name] = [n.split(".", 1)[-1] for n in jr.names]
        except JourdainError:
            directions = {}
    joints = []
    constraints = 0
    for b in system.bodies:
        j = b.joint
        if j.name in directions:
            names = directions[j.name]
            count = len(names)
        else:
            freedoms = sum(1 for s in j.steps
                           if {str(x) for x in _step_symbols(s)} & set(system.coordinate_names))
            count = 6 - freedoms
            names = [f"{count} directions"]
        constraints += count
        joints.append({"name": j.name, "type": j.kind, "body": b.name, "parent": b.parent,
                       "coordinates": [str(c) for c in j.coordinates], "constrained": count,
                       "constrained_directions": names if j.name in directions else []})
    return {
        "name": system.name, "file": model.path, "degrees_of_freedom": system.f,
        "coordinates": system.coordinate_names, "bodies": system.body_names,
        "joints": joints, "constraints": constraints,
        "parameters": system.parameter_values, "inputs": system.input_names,
        "forces": [{"name": f.name, "type": type(f).__name__}
                   for f in (*system.forces, *getattr(system, "frictions", ()))],
        "quantities": [{"name": q.name, "type": q.kind, "symbols": list(q.symbol_names),
                        "definition": q.describe()} for q in system.quantities],
        "nominal_motions": [n.name for n in model.nominal],
        "cyclic_coordinates": [] if system.is_closed else list(cyclic(system)),
    }


def cyclic(system: Any) -> tuple[str, ...]:
    """The cyclic coordinates (in no equation, only their rates), where the equations of
    motion can be formed; none where they cannot."""
    try:
        return tuple(cyclic_coordinates(system))
    except JourdainError:
        return ()


def _step_symbols(step: Any) -> set[Any]:
    """The symbols in one elementary step of a joint (a rotation's angle, a shift's vector)."""
    exprs = [step.angle] if hasattr(step, "angle") else list(step.vector)
    out: set[Any] = set()
    for e in exprs:
        out |= e.free_symbols
    return out
