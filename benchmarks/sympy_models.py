"""sympy.physics.mechanics versions of jourdain's sample models, built from the same data."""

from __future__ import annotations

import sympy as sp
import sympy.physics.mechanics as me

from jourdain.models import spatial_chain_data


def spatial_chain_sympy(n: int, seed: int = 0) -> tuple[me.System, list, dict]:
    """spatial_chain(n) with sympy's System/joints API (relative joint coordinates).

    Revolute: PinJoint; universal: two PinJoints through a massless intermediate body;
    spherical: SphericalJoint with body-fixed X-Y-Z angles. Symbols carry jourdain's names, so
    the same parameter values apply. Returns the system (equations formed), the coordinates in
    jourdain's order, and the parameter symbols by name.
    """
    data = spatial_chain_data(n, seed)
    ground = me.RigidBody("ground")
    system = me.System.from_newtonian(ground)
    g = sp.Symbol("g")
    comp = "xyz"
    syms: dict[str, sp.Symbol] = {"g": g}
    coords: list = []
    parent = ground
    parent_origin = ground.masscenter  # the parent body frame's origin (its joint point)
    for i, d in enumerate(data):
        m = sp.Symbol(f"m{i}")
        c = [sp.Symbol(f"c{a}{i}") for a in comp]
        I = {(a, b): sp.Symbol(f"I{i}{comp[min(a, b)]}{comp[max(a, b)]}")
             for a in range(3) for b in range(3)}
        syms.update({str(s): s for s in [m, *c, *I.values()]})
        frame = me.ReferenceFrame(f"B{i}")
        body = me.RigidBody(f"body{i}", frame=frame, mass=m)
        body.inertia = (me.inertia(frame, I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[1, 2], I[0, 2]),
                        body.masscenter)
        # joint point on the parent: the parent frame origin moved by the parent's offset
        if i == 0:
            joint_on_parent = parent_origin
        else:
            dvec = [sp.Symbol(f"d{a}{i - 1}") for a in comp]
            syms.update({str(s): s for s in dvec})
            joint_on_parent = parent_origin.locatenew(
                f"J{i}", dvec[0] * parent.frame.x + dvec[1] * parent.frame.y
                + dvec[2] * parent.frame.z)
        child_point = -(c[0] * frame.x + c[1] * frame.y + c[2] * frame.z)
        nq = {"revolute": 1, "universal": 2, "spherical": 3}[d["joint"]]
        qs = me.dynamicsymbols(f"q{len(coords)}:{len(coords) + nq}")
        us = me.dynamicsymbols(f"u{len(coords)}:{len(coords) + nq}")
        coords.extend(qs)
        parent_point = joint_on_parent.pos_from(parent.masscenter)
        if d["joint"] == "revolute":
            ax = d["axes"][0]
            joint = me.PinJoint(f"joint{i}", parent, body, qs[0], us[0],
                                parent_point=parent_point, child_point=child_point,
                                joint_axis=getattr(parent.frame, ax))
            system.add_joints(joint)
        elif d["joint"] == "universal":
            a1, a2 = d["axes"]
            mid = me.RigidBody(f"cross{i}", mass=0)
            mid.inertia = (me.inertia(mid.frame, 0, 0, 0), mid.masscenter)
            j1 = me.PinJoint(f"joint{i}a", parent, mid, qs[0], us[0], parent_point=parent_point,
                             joint_axis=getattr(parent.frame, a1))
            j2 = me.PinJoint(f"joint{i}b", mid, body, qs[1], us[1], child_point=child_point,
                             joint_axis=getattr(mid.frame, a2))
            system.add_joints(j1, j2)
        else:
            joint = me.SphericalJoint(f"joint{i}", parent, body, qs, us,
                                      parent_point=parent_point, child_point=child_point,
                                      rot_type="BODY", rot_order="XYZ")
            system.add_joints(joint)
        parent = body
        parent_origin = body.masscenter.locatenew(
            f"O{i}", -(c[0] * frame.x + c[1] * frame.y + c[2] * frame.z))
    system.apply_uniform_gravity(-g * ground.frame.z)
    system.validate_system()
    system.form_eoms()
    return system, coords, syms
