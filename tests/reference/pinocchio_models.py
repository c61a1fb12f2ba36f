"""Pinocchio models built from the same numbers as jourdain's sample models."""

from __future__ import annotations

import numpy as np

pin = __import__("pytest").importorskip("pinocchio")

_AXIS = {"x": pin.JointModelRX, "y": pin.JointModelRY, "z": pin.JointModelRZ}


def spatial_chain_model(data: list[dict]):
    """Pinocchio model of jourdain.models.spatial_chain: each jourdain joint becomes one
    Pinocchio revolute joint per elementary rotation (universal: 2, spherical Cardan xyz: 3)."""
    model = pin.Model()
    parent = 0
    offset = np.zeros(3)
    for i, d in enumerate(data):
        seq = {"revolute": list(d["axes"][:1]), "universal": list(d["axes"]),
               "spherical": ["x", "y", "z"]}[d["joint"]]
        for k, a in enumerate(seq):
            placement = pin.SE3(np.eye(3), offset) if k == 0 else pin.SE3.Identity()
            parent = model.addJoint(parent, _AXIS[a](), placement, f"joint{i}_{k}")
        model.appendBodyToJoint(parent, pin.Inertia(d["mass"], np.asarray(d["com"]),
                                                    np.asarray(d["inertia"])), pin.SE3.Identity())
        offset = np.asarray(d["offset"], dtype=float)
    model.gravity.linear = np.array([0.0, 0.0, -9.81])
    return model
