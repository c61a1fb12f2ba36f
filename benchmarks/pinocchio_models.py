"""Pinocchio models built from the same numbers as jourdain's sample models (for the benchmarks
and the reference tests)."""

from __future__ import annotations

import numpy as np


def chain_model(data: list[dict]):
    """Pinocchio model of :func:`jourdain.models.chain_from_data` (spatial_chain, robot_arm):
    each jourdain joint becomes one Pinocchio revolute joint per elementary rotation (universal:
    2, spherical Cardan xyz: 3), placed at the previous body's offset; gravity (0, 0, -9.81)."""
    import pinocchio as pin

    axis = {"x": pin.JointModelRX, "y": pin.JointModelRY, "z": pin.JointModelRZ}
    model = pin.Model()
    parent = 0
    offset = np.zeros(3)
    for i, d in enumerate(data):
        seq = {"revolute": list(d["axes"][:1]), "universal": list(d["axes"]),
               "spherical": ["x", "y", "z"]}[d["joint"]]
        for k, a in enumerate(seq):
            placement = pin.SE3(np.eye(3), offset) if k == 0 else pin.SE3.Identity()
            parent = model.addJoint(parent, axis[a](), placement, f"joint{i}_{k}")
        model.appendBodyToJoint(parent, pin.Inertia(float(d["mass"]), np.asarray(d["com"]),
                                                    np.asarray(d["inertia"])), pin.SE3.Identity())
        offset = np.asarray(d["offset"], dtype=float)
    model.gravity.linear = np.array([0.0, 0.0, -9.81])
    return model
