"""Sample models shared by the tests, the documentation and the benchmarks."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import symengine as se

from .model import (
    Body,
    Force,
    Free,
    General,
    Gravity,
    Prismatic,
    Revolute,
    Rot,
    Spherical,
    Universal,
    point_mass,
    rod,
    symbols,
)
from .pipeline import System


def n_link_pendulum_on_cart(n: int) -> System:
    """n-link pendulum on a cart, the same system as
    ``sympy.physics.mechanics.models.n_link_pendulum_on_cart(n, cart_force=True)``.

    Coordinates ``q0`` (cart position along x) and ``q1 … qn`` (absolute link angles about z,
    measured from the upward y axis); masses ``m0`` (cart) … ``mn`` (point masses at the link
    ends); lengths ``l0 … l(n-1)``; gravity ``g`` along -y; input ``F``, the horizontal force on
    the cart. Links are massless. Absolute angles are joint angles ``q_i - q_(i-1)`` of general
    joints, which the kinematics merges back into ``R_z(q_i)``.
    """
    if n < 1:
        raise ValueError("n must be at least 1")
    q = [se.Symbol(f"q{i}") for i in range(n + 1)]
    m = [se.Symbol(f"m{i}") for i in range(n + 1)]
    l = [se.Symbol(f"l{i}") for i in range(n)]
    g, F = symbols("g F")
    bodies = [Body("cart", "world", Prismatic("slider", q[0], "x"), mass=m[0],
                   inertia=point_mass())]
    for i in range(1, n + 1):
        if i == 1:
            joint = Revolute("hinge1", q[1], "z")
        else:
            joint = General(f"hinge{i}", [Rot("z", q[i] - q[i - 1])], coordinates=[q[i]],
                            position=(0, l[i - 2], 0))
        bodies.append(Body(f"link{i}", "cart" if i == 1 else f"link{i - 1}", joint, mass=m[i],
                           com=(0, l[i - 1], 0), inertia=point_mass()))
    params = {f"m{i}": 1.0 for i in range(n + 1)}
    params.update({f"l{i}": 1.0 for i in range(n)})
    params["g"] = 9.81
    return System(q, bodies, [Gravity((0, -g, 0)), Force("cart_force", "cart", (F, 0, 0))],
                  parameters=params, inputs=[F], name=f"{n}-link pendulum on a cart",
                  units={"g": "m/s^2", **{f"m{i}": "kg" for i in range(n + 1)},
                         **{f"l{i}": "m" for i in range(n)}})


def double_pendulum() -> System:
    """Planar double pendulum of two uniform rods hanging from revolute joints about z.

    ``phi1``: angle of the first rod from the downward vertical; ``phi2``: angle of the second
    rod relative to the first. Rods of mass ``m1, m2`` and length ``l1, l2`` along the body's
    -y axis; gravity ``g`` along -y.
    """
    phi1, phi2 = symbols("phi1 phi2")
    m1, m2, l1, l2, g = symbols("m1 m2 l1 l2 g")
    bodies = [
        Body("rod1", "world", Revolute("hinge1", phi1, "z"), mass=m1, com=(0, -l1 / 2, 0),
             inertia=rod(m1, l1, "y")),
        Body("rod2", "rod1", Revolute("hinge2", phi2, "z", position=(0, -l1, 0)), mass=m2,
             com=(0, -l2 / 2, 0), inertia=rod(m2, l2, "y")),
    ]
    return System([phi1, phi2], bodies, [Gravity((0, -g, 0))],
                  parameters={"m1": 1.0, "m2": 0.5, "l1": 1.0, "l2": 0.7, "g": 9.81},
                  units={"m1": "kg", "m2": "kg", "l1": "m", "l2": "m", "g": "m/s^2",
                         "phi1": "rad", "phi2": "rad"},
                  name="double pendulum")


def heavy_top() -> System:
    """Heavy symmetric top on a fixed point, in Euler angles ``psi`` (precession), ``theta``
    (nutation), ``phi`` (spin) of the z-x-z sequence.

    Centre of mass at distance ``L`` on the symmetry axis (body z); moments of inertia ``A``
    (transverse) and ``C`` (axial) about the centre of mass; gravity ``g`` along -z.
    """
    psi, theta, phi = symbols("psi theta phi")
    m, L, A, C, g = symbols("m L A C g")
    body = Body("top", "world", Spherical("pivot", (psi, theta, phi), "zxz"), mass=m,
                com=(0, 0, L), inertia=(A, A, C))
    return System([psi, theta, phi], [body], [Gravity((0, 0, -g))],
                  parameters={"m": 1.0, "L": 0.1, "A": 0.004, "C": 0.006, "g": 9.81},
                  units={"m": "kg", "L": "m", "A": "kg*m^2", "C": "kg*m^2", "g": "m/s^2"},
                  name="heavy symmetric top")


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
        I = np.round(_random_inertia(rng, 0.02, 0.05, margin=0.005), 6)
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
        inertia = _random_inertia(rng, 0.005, 0.03, margin=0.002)
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
            axes = (_unit_vector(rng),)
        elif kind == "universal":
            u1 = _unit_vector(rng)
            u2 = _unit_vector(rng)
            while np.linalg.norm(np.cross(u1, u2)) < 0.3:  # well apart: a regular joint
                u2 = _unit_vector(rng)
            axes = (u1, u2)
        seq = ""
        if kind in ("spherical", "free"):
            seq = str(sequences[int(rng.integers(0, len(sequences)))])
        bodies.append({
            "parent": parent, "joint": kind, "axes": axes, "sequence": seq,
            "position": rng.uniform(-position, position, 3),
            "mass": float(rng.uniform(*mass)),
            "com": rng.uniform(-com, com, 3),
            "inertia": _random_inertia(rng, *moment),
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


def _unit_vector(rng: np.random.Generator) -> np.ndarray:
    """A random unit 3-vector (uniform on the sphere), normalized to |u|² = 1 within 1e-15."""
    u = rng.normal(size=3)
    return u / np.linalg.norm(u)


def _random_inertia(rng: np.random.Generator, lo: float, hi: float,
                    margin: float | None = None) -> np.ndarray:
    """A full inertia tensor: principal moments in (lo, hi) that satisfy the triangle
    inequality by at least ``margin`` (default ``0.1·lo``), turned by a random rotation."""
    m = 0.1 * lo if margin is None else margin
    a, b = rng.uniform(lo, hi, 2)
    c = rng.uniform(abs(a - b) + m, a + b - m)
    Qm, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    I = Qm @ np.diag([a, b, c]) @ Qm.T
    return 0.5 * (I + I.T)


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
