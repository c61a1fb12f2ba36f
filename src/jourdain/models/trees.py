"""Random trees of revolute, prismatic, universal, spherical and free joints with full inertia
tensors (:func:`random_tree_data` draws the numbers, :func:`tree_from_data` builds the System)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import symengine as se

from ..model import (
    Body,
    Free,
    Gravity,
    Prismatic,
    Revolute,
    Spherical,
    Universal,
)
from ..pipeline import System
from .chains import random_inertia, unit_vector

#: joint kinds of :func:`random_tree_data` and their number of coordinates
TREE_JOINTS = {"revolute": 1, "prismatic": 1, "universal": 2, "spherical": 3, "free": 6}
#: default relative frequencies of the joint kinds below the root (``free`` is placed, not drawn)
TREE_WEIGHTS = {"revolute": 0.3, "prismatic": 0.15, "universal": 0.25, "spherical": 0.3}
#: Cardan (Tait–Bryan) sequences: regular at y = 0 (proper Euler sequences such as "zxz" are
#: not, their middle angle 0 is a singular configuration)
CARDAN = ("xyz", "xzy", "yxz", "yzx", "zxy", "zyx")


def random_tree_data(
    n_bodies: int,
    seed: int = 0,
    joints: Sequence[str] = ("revolute", "prismatic", "universal", "spherical", "free"),
    *,
    weights: Mapping[str, float] | None = None,
    free_at: Sequence[int] = (0,),
    sequences: Sequence[str] = CARDAN,
    order: str = "breadth-first",
    mass: tuple[float, float] = (0.5, 2.0),
    moment: tuple[float, float] = (0.01, 0.05),
    com: float = 0.15,
    position: float = 0.3,
) -> list[dict]:
    """Numeric data of :func:`random_tree`: a branching tree of rigid bodies drawn at random.

    Body ``k`` (in creation order) hangs from a body drawn uniformly among the bodies created
    before it; the first hangs from the world. The list is in ``order``: ``"breadth-first"``
    (level by level, children in creation order) or ``"creation"``; both put every parent
    before its children, neither is depth-first in general (a peer tool that needs depth-first
    joint order, as Pinocchio's CRBA does, must reorder).

    Parameters
    ----------
    n_bodies : number of bodies (≥ 1)
    seed : seed of the ``numpy.random.Generator`` that draws everything
    joints : joint kinds to use, among ``revolute``, ``prismatic``, ``universal``,
        ``spherical`` and ``free``
    weights : relative frequencies of the kinds other than ``free`` (default
        :data:`TREE_WEIGHTS`)
    free_at : creation indices of the bodies with a free joint (when ``free`` is in
        ``joints``); the default makes the root a floating base
    sequences : rotation sequences drawn for spherical and free joints (any of
        :class:`jourdain.model.Spherical`'s; default the Cardan sequences)
    order : ``"breadth-first"`` or ``"creation"``
    mass, moment : ranges of the masses (kg) and principal moments of inertia (kg m²)
    com, position : half-widths of the boxes the centres of mass and joint points are drawn in
        (m)

    Returns
    -------
    list of dict, one per body, parents first, with keys ``parent`` (index in the list, -1 for
    the world), ``joint`` (kind), ``axes`` (tuple of unit 3-vectors: one for revolute and
    prismatic, two for universal, none otherwise), ``sequence`` (rotation sequence of spherical
    and free joints, else ""), ``position`` (3,): the joint point in the parent's body frame,
    ``mass``, ``com`` (3,) and ``inertia`` (3×3, about the centre of mass) in the body frame.
    """
    if n_bodies < 1:
        raise ValueError("n_bodies must be at least 1")
    unknown = set(joints) - set(TREE_JOINTS)
    if unknown:
        raise ValueError(f"unknown joint kind(s) {sorted(unknown)}; kinds are {list(TREE_JOINTS)}")
    if order not in ("breadth-first", "creation"):
        raise ValueError(f'order must be "breadth-first" or "creation", got {order!r}')
    w = dict(TREE_WEIGHTS if weights is None else weights)
    drawn = [k for k in joints if k != "free" and w.get(k, 0.0) > 0.0]
    if not drawn and not ("free" in joints and set(range(n_bodies)) <= set(free_at)):
        raise ValueError("no joint kind to draw: give joints other than free, with weights > 0")
    prob = np.array([w[k] for k in drawn], dtype=float)
    prob = prob / prob.sum() if drawn else prob
    rng = np.random.default_rng(seed)
    bodies: list[dict] = []
    for k in range(n_bodies):
        parent = -1 if k == 0 else int(rng.integers(0, k))
        if "free" in joints and k in free_at:
            kind = "free"
        else:
            kind = drawn[rng.choice(len(drawn), p=prob)]
        axes: tuple[np.ndarray, ...] = ()
        if kind in ("revolute", "prismatic"):
            axes = (unit_vector(rng),)
        elif kind == "universal":
            u1 = unit_vector(rng)
            u2 = unit_vector(rng)
            while np.linalg.norm(np.cross(u1, u2)) < 0.3:  # well apart: a regular joint
                u2 = unit_vector(rng)
            axes = (u1, u2)
        seq = ""
        if kind in ("spherical", "free"):
            seq = str(sequences[int(rng.integers(0, len(sequences)))])
        bodies.append({
            "parent": parent, "joint": kind, "axes": axes, "sequence": seq,
            "position": rng.uniform(-position, position, 3),
            "mass": float(rng.uniform(*mass)),
            "com": rng.uniform(-com, com, 3),
            "inertia": random_inertia(rng, *moment),
        })
    if order == "creation":
        return bodies
    # breadth-first: level by level, children in creation order
    children: list[list[int]] = [[] for _ in range(n_bodies)]
    for k, b in enumerate(bodies[1:], start=1):
        children[b["parent"]].append(k)
    bfs = [0]
    for k in bfs:
        bfs.extend(children[k])
    new = {old: i for i, old in enumerate(bfs)}
    new[-1] = -1
    return [{**bodies[old], "parent": new[bodies[old]["parent"]]} for old in bfs]


def random_tree(
    n_bodies: int,
    seed: int = 0,
    joints: Sequence[str] = ("revolute", "prismatic", "universal", "spherical", "free"),
    **options: Any,
) -> System:
    """A random branching tree of ``n_bodies`` rigid bodies with mixed joints, built by
    :func:`tree_from_data` from :func:`random_tree_data` (same arguments; ``options`` are its
    keyword-only ones). With the default joint mix (a free root, then revolute, prismatic,
    universal and spherical joints about random axes) f is about 1.85·n_bodies + 4."""
    data = random_tree_data(n_bodies, seed, joints, **options)
    return tree_from_data(data, name=f"random tree of {n_bodies} bodies (seed {seed})")


def tree_from_data(data: Sequence[Mapping[str, Any]], name: str = "tree") -> System:
    """A tree of rigid bodies from numeric data in the form of :func:`random_tree_data`.

    Body ``i`` is ``body{i}``, its joint ``joint{i}`` at ``(px{i}, py{i}, pz{i})`` in the
    parent's body frame; mass ``m{i}``, centre of mass ``(cx{i}, cy{i}, cz{i})`` and inertia
    entries ``I{i}xx, I{i}xy, …`` in its body frame; gravity ``g`` along -z. All of these are
    parameters with the data's values as defaults. The joint axes stay numbers: the reaction
    forces need numeric axes (:func:`jourdain.stages.reactions.constrained_directions`). Coordinates
    ``q0, q1, …`` body by body in list order, in each joint's own order:

    * revolute, prismatic: the angle about, the distance along ``axes[0]``;
    * universal: the angle about ``axes[0]``, then about ``axes[1]`` of the turned frame;
    * spherical: three angles of ``sequence`` (each about an axis of the frame turned so far);
    * free: translations along x, y, z of the joint frame, then three angles of ``sequence``.
    """
    coords: list[se.Symbol] = []
    bodies = []
    params: dict[str, float] = {"g": 9.81}
    comp = "xyz"
    names = [f"body{i}" for i in range(len(data))]
    for i, d in enumerate(data):
        kind = d["joint"]
        if kind not in TREE_JOINTS:
            raise ValueError(f"body {i}: unknown joint kind {kind!r}; "
                             f"kinds are {list(TREE_JOINTS)}")
        parent = int(d["parent"])
        if not -1 <= parent < i:
            raise ValueError(f"body {i}: parent {parent} must be -1 (world) or an earlier body")
        qs = [se.Symbol(f"q{len(coords) + k}") for k in range(TREE_JOINTS[kind])]
        coords.extend(qs)
        pos = tuple(se.Symbol(f"p{c}{i}") for c in comp)
        jname = f"joint{i}"
        axes = [tuple(float(x) for x in a) for a in d.get("axes", ())]
        if kind == "revolute":
            joint = Revolute(jname, qs[0], axes[0], position=pos)
        elif kind == "prismatic":
            joint = Prismatic(jname, qs[0], axes[0], position=pos)
        elif kind == "universal":
            joint = Universal(jname, qs, axes, position=pos)
        elif kind == "spherical":
            joint = Spherical(jname, qs, d["sequence"], position=pos)
        else:
            joint = Free(jname, qs, d["sequence"], position=pos)
        m = se.Symbol(f"m{i}")
        com = tuple(se.Symbol(f"c{c}{i}") for c in comp)
        I = [[se.Symbol(f"I{i}{comp[min(a, b)]}{comp[max(a, b)]}") for b in range(3)]
             for a in range(3)]
        bodies.append(Body(names[i], "world" if parent < 0 else names[parent], joint, mass=m,
                           com=com, inertia=I))
        params[f"m{i}"] = float(d["mass"])
        params.update({f"c{c}{i}": float(v) for c, v in zip(comp, d["com"], strict=True)})
        params.update({f"p{c}{i}": float(v) for c, v in zip(comp, d["position"], strict=True)})
        inertia = np.asarray(d["inertia"], dtype=float)
        params.update({f"I{i}{comp[a]}{comp[b]}": float(inertia[a, b])
                       for a in range(3) for b in range(a, 3)})
    g = se.Symbol("g")
    return System(coords, bodies, [Gravity((0, 0, -g))], parameters=params, name=name)
