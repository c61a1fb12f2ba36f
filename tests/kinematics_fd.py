"""Finite-difference reference for the kinematics: velocities and accelerations from r(y, t) and
S(y, t) alone, independent of the recursive formulas of jourdain.stages.kinematics."""

from __future__ import annotations

import numpy as np

from jourdain.numeric import lambdify, parameter_vector
from jourdain.symbolic import SymMatrix


def compile_kinematics(system):
    kin = system.kinematics()
    mats = {}
    for b in kin.bodies:
        for name in ("r", "S", "J_T", "J_R", "v_bar", "omega_bar", "a_bar", "alpha_bar", "omega"):
            mats[f"{b.name}.{name}"] = getattr(b, name)
    fn = lambdify(system, mats)
    p = parameter_vector(system, None)
    nu = len(system.inputs)
    return kin, (lambda y, yd, t: fn(y, yd, t, p, np.zeros(nu)))


def positions(fn, y, t, body):
    out = fn(y, np.zeros_like(y), t)
    return out[f"{body}.r"].ravel(), out[f"{body}.S"]


def fd_velocity(fn, y, yd, t, body, h=1e-6):
    """v (inertial) and ω (body frame) by central differences along the motion y + yd*τ."""
    r1, S1 = positions(fn, y + h * yd, t + h, body)
    r0, S0 = positions(fn, y - h * yd, t - h, body)
    _, S = positions(fn, y, t, body)
    v = (r1 - r0) / (2 * h)
    W = S.T @ (S1 - S0) / (2 * h)  # ω̃ in the body frame
    return v, np.array([W[2, 1], W[0, 2], W[1, 0]])


def fd_acceleration(fn, y, yd, ydd, t, body, h=1e-4):
    """a (inertial) and α (body frame) by central differences of the velocities."""

    def vel(tau):
        yy = y + yd * tau + 0.5 * ydd * tau**2
        yyd = yd + ydd * tau
        out = fn(yy, yyd, t + tau)
        v = out[f"{body}.J_T"] @ yyd + out[f"{body}.v_bar"].ravel()
        w = out[f"{body}.J_R"] @ yyd + out[f"{body}.omega_bar"].ravel()
        return v, w

    v1, w1 = vel(h)
    v0, w0 = vel(-h)
    return (v1 - v0) / (2 * h), (w1 - w0) / (2 * h)


__all__ = ["SymMatrix", "compile_kinematics", "fd_acceleration", "fd_velocity", "positions"]
