"""Planar sample models: the n-link pendulum in relative joint angles and random planar trees,
every body turning about z in the x-y plane (the systems of
:mod:`jourdain.numeric.planar_recursion`; gravity along −y)."""

from __future__ import annotations

import numpy as np
import symengine as se

from ..model import Body, Gravity, Prismatic, Revolute
from ..pipeline import System

#: the n-link pendulum's links: mass (kg), length (m), inertia about the link axis (kg m²)
LINK_MASS, LINK_LENGTH, LINK_I_AXIAL, GRAVITY = 1.0, 1.0, 1e-3, 9.81


def planar_chain(n: int) -> System:
    """A planar pendulum of ``n`` uniform links joined by hinges about z, in the relative joint
    angles q0 … q(n−1); every number a parameter: ``m{i}``, ``l{i}``, ``J{i}`` (inertia across
    the link, m·l²/12), ``Ja{i}`` (about its axis) and ``g``. The links are 1 kg and 1 m with
    the centre of mass at mid-length (``benchmarks/peers.py`` builds the same chain in MuJoCo
    and Exudyn)."""
    if n < 1:
        raise ValueError(f"planar_chain: n must be at least 1, got {n}")
    qs = [se.Symbol(f"q{i}") for i in range(n)]
    params: dict[str, float] = {"g": GRAVITY}
    bodies = []
    for i in range(n):
        m, L, J, Ja = (se.Symbol(f"{k}{i}") for k in ("m", "l", "J", "Ja"))
        pos = (0, 0, 0) if i == 0 else (se.Symbol(f"l{i - 1}"), 0, 0)
        bodies.append(Body(f"link{i}", "world" if i == 0 else f"link{i - 1}",
                           Revolute(f"joint{i}", qs[i], "z", position=pos), mass=m,
                           com=(L / 2, 0, 0), inertia=(Ja, J, J)))
        params.update({f"m{i}": LINK_MASS, f"l{i}": LINK_LENGTH, f"Ja{i}": LINK_I_AXIAL,
                       f"J{i}": LINK_MASS * LINK_LENGTH ** 2 / 12})
    return System(qs, bodies, [Gravity((0, -se.Symbol("g"), 0))], parameters=params,
                  name=f"planar {n}-link pendulum")


def planar_tree(n_bodies: int, seed: int = 0, prismatic: float = 0.2) -> System:
    """A random branching tree of ``n_bodies`` bodies in the x-y plane: body k hangs from a body
    drawn uniformly among those before it, at a random point of it, by a hinge about z or (with
    probability ``prismatic``) a slider along a random direction of the plane; masses, centres
    of mass and moments drawn at random (numbers, not parameters), gravity 9.81 along −y."""
    if n_bodies < 1:
        raise ValueError(f"planar_tree: n_bodies must be at least 1, got {n_bodies}")
    rng = np.random.default_rng(seed)
    qs = [se.Symbol(f"q{i}") for i in range(n_bodies)]
    bodies = []
    for k in range(n_bodies):
        parent = "world" if k == 0 else f"b{int(rng.integers(0, k))}"
        pos = (0.0, 0.0, 0.0) if k == 0 else (*(float(x) for x in rng.uniform(-0.3, 0.3, 2)), 0.0)
        if k and rng.uniform() < prismatic:
            a = float(rng.uniform(0, 2 * np.pi))
            joint = Prismatic(f"j{k}", qs[k], (np.cos(a), np.sin(a), 0.0), position=pos)
        else:
            joint = Revolute(f"j{k}", qs[k], "z", position=pos)
        m = float(rng.uniform(0.5, 2.0))
        I = [float(x) for x in rng.uniform(0.01, 0.05, 2)]
        bodies.append(Body(f"b{k}", parent, joint, mass=m,
                           com=(*(float(x) for x in rng.uniform(-0.15, 0.15, 2)), 0.0),
                           inertia=(I[0], I[1], I[0] + I[1])))
    return System(qs, bodies, [Gravity((0, -GRAVITY, 0))],
                  name=f"random planar tree of {n_bodies} bodies (seed {seed})")
