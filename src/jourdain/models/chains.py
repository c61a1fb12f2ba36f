"""Serial chains built from numeric data: random spatial chains and a 7-joint robot arm
(:func:`chain_from_data` turns the data of one body per dict into a System)."""

from __future__ import annotations

import numpy as np
import symengine as se

from ..model import (
    Body,
    Gravity,
    Revolute,
    Spherical,
    Universal,
)
from ..pipeline import System


def spatial_chain_data(n: int, seed: int = 0) -> list[dict]:
    """Numeric data of :func:`spatial_chain` (one dict per body), for building peer models.

    Keys: ``joint`` ("revolute", "universal", "spherical"), ``axes`` (axis names), ``mass``,
    ``com`` (3,), ``inertia`` (3×3, about the centre of mass, body frame), ``offset`` (3,): the
    next joint's position in this body's frame.
    """
    rng = np.random.default_rng(seed)
    kinds = ("revolute", "universal", "spherical")
    rev_axes = ("z", "x", "y")
    out = []
    for i in range(n):
        kind = kinds[i % 3]
        axes: tuple[str, ...]
        if kind == "revolute":
            axes = (rev_axes[(i // 3) % 3],)
        elif kind == "universal":
            axes = ("x", "y") if (i // 3) % 2 == 0 else ("z", "x")
        else:
            axes = ("x", "y", "z")
        # full, non-diagonal inertia: principal moments (triangle inequality) turned by a rotation
        I = np.round(random_inertia(rng, 0.02, 0.05, margin=0.005), 6)
        out.append({
            "joint": kind, "axes": axes, "mass": round(float(rng.uniform(0.5, 2.0)), 4),
            "com": np.round(rng.uniform(-0.1, 0.1, 3) + np.array([0.0, 0.0, 0.15]), 4),
            "inertia": I,
            "offset": np.round(rng.uniform(-0.1, 0.1, 3) + np.array([0.0, 0.0, 0.3]), 4),
        })
    return out


def spatial_chain(n: int, seed: int = 0) -> System:
    """A spatial chain of ``n`` rigid bodies with full (non-diagonal) inertia tensors, joined by
    revolute, universal and spherical (Cardan xyz) joints in turn, under gravity ``g`` along -z.

    Body ``i`` has mass ``m{i}``, centre of mass ``(cx{i}, cy{i}, cz{i})``, inertia entries
    ``I{i}xx, I{i}xy, …`` and the next joint at ``(dx{i}, dy{i}, dz{i})`` in its frame; all are
    parameters whose default values come from :func:`spatial_chain_data` (so a peer tool can be
    built from the same numbers). Coordinates ``q0, q1, …`` in joint order.
    """
    return chain_from_data(spatial_chain_data(n, seed), name=f"spatial chain of {n} bodies")


#: the 7-joint arm of :func:`robot_arm`: joint axes, joint offsets (m) and link masses (kg) of a
#: common research arm
ARM_AXES = ("z", "y", "z", "y", "z", "y", "z")
ARM_OFFSETS = ((0, 0, 0.333), (0, 0, 0.0), (0, 0, 0.316), (0.0825, 0, 0), (-0.0825, 0, 0.384),
               (0, 0, 0), (0.088, 0, 0.107))
ARM_MASSES = (4.97, 0.65, 3.23, 3.59, 1.23, 1.67, 0.74)


def robot_arm_data(seed: int = 7) -> list[dict]:
    """Numeric data of :func:`robot_arm`, in the form of :func:`spatial_chain_data`: link
    lengths and masses of a common 7-joint research arm, full inertia tensors drawn at random."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(7):
        inertia = random_inertia(rng, 0.005, 0.03, margin=0.002)
        out.append({"joint": "revolute", "axes": (ARM_AXES[i],), "mass": ARM_MASSES[i],
                    "com": np.round(rng.uniform(-0.05, 0.05, 3), 4),
                    "inertia": inertia,
                    "offset": np.array(ARM_OFFSETS[i], dtype=float)})
    return out


def robot_arm(seed: int = 7) -> System:
    """A 7-joint revolute arm (axes z-y-z-y-z-y-z) under gravity, built by
    :func:`chain_from_data` from :func:`robot_arm_data`."""
    return chain_from_data(robot_arm_data(seed), name="7-joint arm")


def chain_from_data(data: list[dict], name: str = "chain") -> System:
    """A serial chain from numeric data in the form of :func:`spatial_chain_data` (one dict per
    body: ``joint``, ``axes``, ``mass``, ``com``, ``inertia``, ``offset``), with every number a
    named parameter (``m{i}``, ``cx{i}``, ``I{i}xy``, ``dx{i}``, ...; gravity ``g`` along -z)."""
    coords: list[se.Symbol] = []
    bodies = []
    params: dict[str, float] = {"g": 9.81}
    comp = "xyz"
    for i, d in enumerate(data):
        nq = {"revolute": 1, "universal": 2, "spherical": 3}[d["joint"]]
        qs = [se.Symbol(f"q{len(coords) + k}") for k in range(nq)]
        coords.extend(qs)
        pos = (0, 0, 0) if i == 0 else tuple(se.Symbol(f"d{c}{i - 1}") for c in comp)
        jname = f"joint{i}"
        if d["joint"] == "revolute":
            joint = Revolute(jname, qs[0], d["axes"][0], position=pos)
        elif d["joint"] == "universal":
            joint = Universal(jname, qs, d["axes"], position=pos)
        else:
            joint = Spherical(jname, qs, "xyz", position=pos)
        m = se.Symbol(f"m{i}")
        com = tuple(se.Symbol(f"c{c}{i}") for c in comp)
        I = [[se.Symbol(f"I{i}{comp[min(a, b)]}{comp[max(a, b)]}") for b in range(3)]
             for a in range(3)]
        bodies.append(Body(f"body{i}", "world" if i == 0 else f"body{i - 1}", joint, mass=m,
                           com=com, inertia=I))
        params[f"m{i}"] = float(d["mass"])
        for a in range(3):
            params[f"c{comp[a]}{i}"] = float(d["com"][a])
            params[f"d{comp[a]}{i}"] = float(d["offset"][a])
            for b in range(a, 3):
                params[f"I{i}{comp[a]}{comp[b]}"] = float(d["inertia"][a, b])
    g = se.Symbol("g")
    return System(coords, bodies, [Gravity((0, 0, -g))], parameters=params, name=name)


def unit_vector(rng: np.random.Generator) -> np.ndarray:
    """A random unit 3-vector (uniform on the sphere), normalized to |u|² = 1 within 1e-15."""
    u = rng.normal(size=3)
    return u / np.linalg.norm(u)


def random_inertia(rng: np.random.Generator, lo: float, hi: float,
                    margin: float | None = None) -> np.ndarray:
    """A full inertia tensor: principal moments in (lo, hi) that satisfy the triangle
    inequality by at least ``margin`` (default ``0.1·lo``), turned by a random rotation."""
    m = 0.1 * lo if margin is None else margin
    a, b = rng.uniform(lo, hi, 2)
    c = rng.uniform(abs(a - b) + m, a + b - m)
    Qm, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    I = Qm @ np.diag([a, b, c]) @ Qm.T
    return 0.5 * (I + I.T)
