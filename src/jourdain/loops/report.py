"""What ``jourdain check`` shows of a loop model (and the report's section "Closed loops",
:mod:`jourdain.io.report.loops`): the closing joints, the rows of Φ, the degrees of freedom by
Grübler's count and by the rank of the constraint Jacobian at the initial configuration, and
the partition. ``jourdain run`` of a closed system writes the one report of trees and closed
systems (:func:`jourdain.io.report.write_report`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ..model import System
from .closed_loop import LoopEvaluator, constraints


def loop_summary(model: Any) -> dict[str, Any]:
    """Closing joints, constraint rows, degrees of freedom (Grübler, rank) and partition."""
    loop: System = model.system
    sim = model.simulation
    ev = LoopEvaluator(loop, sim.y0)
    asm = ev.assemble(sim.y0, sim.yd0)
    rank = ev.rank(asm.z)
    planar = _planar_grubler(loop)
    return {
        "closing_joints": [{"name": c.name, "type": c.type, "body_a": c.body_a,
                            "body_b": c.body_b} for c in loop.closing],
        "constraint_rows": constraints(loop).labels,
        "tree_coordinates": loop.coordinate_names,
        "degrees_of_freedom_grubler_spatial": loop.grubler(),
        "degrees_of_freedom_grubler_planar": planar,
        "degrees_of_freedom_rank": loop.f - rank,
        "rank_Phi_y": rank,
        "independent": list(ev.independent_names),
        "dependent": list(ev.dependent_names),
        "cond_Phi_d": ev.part.cond,
        "assembly_residual": {"Phi": asm.Phi, "Phi_dot": asm.Phi_dot,
                              "newton_iterations": asm.iterations},
        "z0": asm.z.tolist(),
    }


def _planar_grubler(loop: System) -> int | None:
    """Grübler's planar count 3·n − Σ(3 − f_j) when every joint is a revolute about z or a
    prismatic joint in the x-y plane (None otherwise)."""
    from ..model.joints import Rot, Trans

    dofs = []
    for b in loop.tree.bodies:
        j = b.joint
        moving = [s for s in j.steps if isinstance(s, Rot) and s.angle.free_symbols
                  or isinstance(s, Trans) and any(v.free_symbols for v in s.vector)]
        for s in moving:
            if isinstance(s, Rot) and tuple(s.axis) != (0, 0, 1):
                return None
            if isinstance(s, Trans) and s.vector[2] != 0:
                return None
        dofs.append(len(j.coordinates))
    total = 3 * len(loop.tree.bodies) - sum(3 - f for f in dofs)
    for c in loop.closing:
        if c.type not in ("revolute", "prismatic") or (c.axis and tuple(c.axis) != (0, 0, 1)
                                                       and c.type == "revolute"):
            return None
        total -= 2
    return total


def check_lines(s: Mapping[str, Any]) -> list[str]:
    """The lines of ``jourdain check`` for a loop model's :func:`loop_summary` ``s``."""
    lines = [f"  loops: {len(s['closing_joints'])} closing joint(s), "
             f"{len(s['constraint_rows'])} constraint equations Φ = 0 "
             f"({', '.join(s['constraint_rows'])})"]
    for c in s["closing_joints"]:
        lines.append(f"    {c['name']:<14} {c['type']:<12} {c['body_a']} ↔ {c['body_b']}")
    planar = s["degrees_of_freedom_grubler_planar"]
    lines.append(
        f"  degrees of freedom of the mechanism: {s['degrees_of_freedom_rank']} by the rank "
        f"{s['rank_Phi_y']} of Φ_y at the assembled initial configuration; Grübler: "
        f"{s['degrees_of_freedom_grubler_spatial']} (spatial)"
        + (f", {planar} (planar)" if planar is not None else ""))
    lines.append(f"  independent: {', '.join(s['independent'])}; dependent: "
                 f"{', '.join(s['dependent'])} (cond Φ_d = {s['cond_Phi_d']:.3g}); assembly "
                 f"residual |Φ| = {s['assembly_residual']['Phi']:.2e}, |Φ̇| = "
                 f"{s['assembly_residual']['Phi_dot']:.2e}")
    return lines


__all__ = ["check_lines", "loop_summary"]
