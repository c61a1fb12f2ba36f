"""Pinocchio models built from the same numbers as jourdain's sample models (for the benchmarks
and the reference tests)."""

from __future__ import annotations

from dataclasses import dataclass

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


@dataclass(frozen=True)
class TreeIndex:
    """How a Pinocchio twin's joints and coordinates map to jourdain's.

    Attributes
    ----------
    v : int array (f,)
        Pinocchio's q and v index of each jourdain coordinate (every Pinocchio joint here has
        one coordinate, so q and v indices coincide): ``q_pin[v] = y``, ``M = M_pin[ix_(v, v)]``.
    joint : tuple of int
        Per jourdain body (in jourdain's order), the Pinocchio joint id of the last elementary
        joint of its jourdain joint, whose frame is the jourdain body frame: ``data.f[joint[i]]``
        is the wrench the jourdain joint transmits, in the child body frame at the joint point.
    order : tuple of int
        The jourdain bodies in the order Pinocchio's joints were added (depth-first).
    """

    v: np.ndarray
    joint: tuple[int, ...]
    order: tuple[int, ...]

    def to_pinocchio(self, y: np.ndarray) -> np.ndarray:
        """A jourdain vector (y, ẏ, ÿ, τ) in Pinocchio's order."""
        out = np.empty(len(self.v))
        out[self.v] = y
        return out

    def from_pinocchio(self, x: np.ndarray) -> np.ndarray:
        """A Pinocchio vector (or the rows and columns of a matrix) in jourdain's order."""
        x = np.asarray(x)
        return x[np.ix_(self.v, self.v)] if x.ndim == 2 else x[self.v]


def chain_index(data: list[dict]) -> TreeIndex:
    """The :class:`TreeIndex` of :func:`chain_model` (same order as jourdain's)."""
    from jourdain.models import TREE_JOINTS

    counts = [TREE_JOINTS[d["joint"]] for d in data]
    return TreeIndex(np.arange(sum(counts)), tuple(int(k) for k in np.cumsum(counts)),
                     tuple(range(len(data))))


def tree_model(data: list[dict], depth_first: bool = True):
    """Pinocchio model of :func:`jourdain.models.tree_from_data` (random_tree) and the index
    map between the two (:class:`TreeIndex`).

    Joints are added depth-first (each sub-tree's coordinates contiguous): Pinocchio's CRBA
    fills row blocks over ``nvSubtree`` columns and is wrong for another order, while RNEA and
    ABA are not; jourdain's data are breadth-first. Each jourdain joint becomes a chain of
    elementary one-coordinate Pinocchio joints, in the order of the jourdain joint's steps,
    joined by massless bodies without offsets; the first is placed at the joint point in the
    parent's body frame (the jourdain joint frame has the parent's orientation):

    * revolute, prismatic about/along a unit axis ``u``: ``RevoluteUnaligned(u)``,
      ``PrismaticUnaligned(u)`` (an axis along x, y or z gives ``RX``, ``PY``, ...);
    * universal: revolute about ``axes[0]``, then about ``axes[1]`` in the turned frame;
    * spherical: ``RX``/``RY``/``RZ`` in the order of the sequence (each about the axis of the
      frame turned by the previous ones, as jourdain's steps);
    * free: ``PX``, ``PY``, ``PZ`` (the joint frame's axes), then the three rotations.

    Gravity (0, 0, -9.81). ``depth_first=False`` adds the joints in list order instead, for
    the test that shows why not.
    """
    import pinocchio as pin

    from jourdain.models import TREE_JOINTS

    f = sum(TREE_JOINTS[d["joint"]] for d in data)
    children: list[list[int]] = [[] for _ in data]
    roots = []
    for i, d in enumerate(data):
        (roots if d["parent"] < 0 else children[d["parent"]]).append(i)
    # jourdain coordinate offsets, body by body in jourdain's order
    first = np.concatenate([[0], np.cumsum([TREE_JOINTS[d["joint"]] for d in data])])
    model = pin.Model()
    v = np.full(f, -1)
    last = [0] * len(data)
    order: list[int] = []
    stack = list(reversed(roots)) if depth_first else list(reversed(range(len(data))))
    while stack:  # depth-first, children in list order
        i = stack.pop()
        order.append(i)
        d = data[i]
        parent = 0 if d["parent"] < 0 else last[d["parent"]]
        for k, jm in enumerate(_elementary_joints(d)):
            placement = (pin.SE3(np.eye(3), np.asarray(d["position"], dtype=float)) if k == 0
                         else pin.SE3.Identity())
            parent = model.addJoint(parent, jm, placement, f"joint{i}_{k}")
            v[first[i] + k] = model.joints[parent].idx_v
        model.appendBodyToJoint(parent, pin.Inertia(float(d["mass"]), np.asarray(d["com"], float),
                                                    np.asarray(d["inertia"], float)),
                                pin.SE3.Identity())
        last[i] = parent
        if depth_first:
            stack.extend(reversed(children[i]))
    model.gravity.linear = np.array([0.0, 0.0, -9.81])
    assert model.nq == model.nv == f and sorted(v) == list(range(f))
    return model, TreeIndex(v, tuple(last), tuple(order))


def _elementary_joints(d: dict) -> list:
    """One-coordinate Pinocchio joints, in the order of the jourdain joint's steps."""
    import pinocchio as pin

    def revolute(u):
        return _aligned(u, "R") or pin.JointModelRevoluteUnaligned(np.asarray(u, float))

    def prismatic(u):
        return _aligned(u, "P") or pin.JointModelPrismaticUnaligned(np.asarray(u, float))

    kind = d["joint"]
    if kind == "revolute":
        return [revolute(d["axes"][0])]
    if kind == "prismatic":
        return [prismatic(d["axes"][0])]
    if kind == "universal":
        return [revolute(d["axes"][0]), revolute(d["axes"][1])]
    rot = {"x": pin.JointModelRX, "y": pin.JointModelRY, "z": pin.JointModelRZ}
    rotations = [rot[a]() for a in d["sequence"]]
    if kind == "spherical":
        return rotations
    if kind == "free":
        return [pin.JointModelPX(), pin.JointModelPY(), pin.JointModelPZ(), *rotations]
    raise ValueError(f"unknown joint kind {kind!r}")


def _aligned(u, prefix: str):
    """``RX``/``PX``, ... when ``u`` is +x, +y or +z exactly (Pinocchio's aligned joints have
    no negative axes), else None."""
    import pinocchio as pin

    u = np.asarray(u, dtype=float)
    for k, a in enumerate("XYZ"):
        if u[k] == 1.0:
            return getattr(pin, f"JointModel{prefix}{a}")()
    return None
