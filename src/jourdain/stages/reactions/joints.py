"""The per-joint view of the reactions (``docs/method.md`` §4): the directions each joint
constrains, as unit wrenches in the child body's frame at the joint point.

Produces :class:`JointReactions` (a joint's constrained directions, the names ``<joint>.F_x``, ...
of its components of g and their columns of Q̄) and :func:`joint_directions` (all joints of a
system, in body order). Directions come from the joint's declaration (``constrained``) or are
derived from its elementary steps (:func:`constrained_directions`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING, Any

import numpy as np
import symengine as se

from ...errors import ModelError
from ...graph import evaluate_arrays
from ...model.joints import IDENTITY, Joint, Mat3, Rot, Vec3, rotation_matrix
from ..kinematics import Z3, _add, _cross, _dot, _mm, _mtv, _mv, _scale, step_axis

if TYPE_CHECKING:
    from ...model.system import System


ZERO = se.Integer(0)
ONE = se.Integer(1)
Wrench = tuple[se.Basic, se.Basic, se.Basic, se.Basic, se.Basic, se.Basic]

_UNIT = {
    "F_x": (1, 0, 0, 0, 0, 0), "F_y": (0, 1, 0, 0, 0, 0), "F_z": (0, 0, 1, 0, 0, 0),
    "T_x": (0, 0, 0, 1, 0, 0), "T_y": (0, 0, 0, 0, 1, 0), "T_z": (0, 0, 0, 0, 0, 1),
}


def _unit(name: str) -> Wrench:
    return tuple(se.Integer(c) for c in _UNIT[name])


# --- constrained directions of one joint ---------------------------------------------------------
@dataclass(frozen=True)
class JointReactions:
    """The constrained directions of one joint.

    ``names`` are the components of ``g`` (``hinge1.F_x`` ...), ``wrenches`` the unit wrenches
    ``(F_x, F_y, F_z, T_x, T_y, T_z)`` in the child body frame at its origin (they may depend on
    the joint's coordinates, as the torque of a universal joint does), ``columns`` their indices
    in ``g`` and in the columns of ``Q̄``.
    """

    joint: Joint
    child: str
    parent: str
    names: tuple[str, ...]
    wrenches: tuple[Wrench, ...]
    columns: tuple[int, ...]


def _perpendicular(u: Vec3, joint: Joint, what: str) -> list[tuple[str, Vec3]]:
    """Two unit vectors perpendicular to the unit axis ``u`` (named after the coordinate axes
    when ``u`` is one of them)."""
    if any(c.free_symbols for c in u):
        raise ModelError(
            f'joint "{joint.name}": the reactions need a numeric {what} axis, got {u}; use a '
            "General joint with constrained=[...] for a symbolic axis"
        )
    uv = np.array([float(c) for c in u])
    for k, ax in enumerate("xyz"):
        if abs(abs(uv[k]) - 1.0) < 1e-15:
            others = [a for a in "xyz" if a != ax]
            return [(a, tuple(se.Integer(int(a == b)) for b in "xyz")) for a in others]
    k = int(np.argmin(np.abs(uv)))
    e = np.zeros(3)
    e[k] = 1.0
    e1 = np.cross(uv, e)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(uv, e1)
    return [("1", tuple(se.Float(float(x)) for x in e1)),
            ("2", tuple(se.Float(float(x)) for x in e2))]


def _wrench(F: Vec3 = Z3, T: Vec3 = Z3) -> Wrench:
    return (*F, *T)


def relative_twist(joint: Joint, coordinates: Sequence[se.Symbol]) -> list[tuple[Vec3, Vec3]]:
    """Columns ``(v, ω)`` of the joint's relative twist Jacobian, one per coordinate in
    ``coordinates``: the velocity of the child frame's origin and the angular velocity of the
    child relative to the parent, per unit rate of the coordinate, in the child body frame."""
    R: Mat3 = IDENTITY
    p: Vec3 = Z3
    rots: list[tuple[Vec3, Vec3, se.Basic]] = []  # (axis in joint frame, origin, angle)
    trans: list[tuple[Mat3, Vec3]] = []  # (frame before the step, vector)
    for s in joint.steps:
        if isinstance(s, Rot):
            rots.append((_mv(R, s.axis), p, s.angle))
            R = _mm(R, rotation_matrix(s.axis, s.angle))
        else:
            trans.append((R, s.vector))
            p = _add(p, _mv(R, s.vector))
    out = []
    for y in coordinates:
        w: Vec3 = Z3
        v: Vec3 = Z3
        for axis, origin, angle in rots:
            d = se.diff(angle, y)
            if d != 0:
                w = _add(w, _scale(axis, d))
                v = _add(v, _scale(_cross(axis, (p[0] - origin[0], p[1] - origin[1],
                                                 p[2] - origin[2])), d))
        for Rb, vec in trans:
            dv = tuple(se.diff(c, y) for c in vec)
            if any(c != 0 for c in dv):
                v = _add(v, _mv(Rb, dv))
        out.append((_mtv(R, v), _mtv(R, w)))
    return out


def constrained_directions(joint: Joint, coordinates: Sequence[se.Symbol] = (),
                           parameters: Mapping[str, float] | None = None
                           ) -> list[tuple[str, Wrench]]:
    """The constrained directions of ``joint``: ``[(suffix, unit wrench), ...]``.

    Wrenches ``(F_x, F_y, F_z, T_x, T_y, T_z)`` are in the child body frame at its origin.
    Standard joints: revolute 3 forces + 2 torques, prismatic 2 forces + 3 torques, cylindrical
    2 + 2, universal 3 forces + the torque ``T_n`` about the normal to both rotation axes,
    spherical 3 forces, planar the normal force and 2 torques, free none, fixed all six. A
    general joint takes the user's ``constrained`` list or derives the directions from its
    elementary steps (``coordinates``: the system's coordinates, ``parameters``: default values
    for the numeric rank test).
    """
    kind = joint.kind
    steps = joint.steps
    if joint.constrained is not None:
        return _user_directions(joint)
    if kind == "fixed":
        return [(n, _unit(n)) for n in _UNIT]
    if kind == "free":
        return []
    if kind == "spherical":
        return [(n, _unit(n)) for n in ("F_x", "F_y", "F_z")]
    if kind == "revolute":
        u = step_axis(steps[0])
        return ([(n, _unit(n)) for n in ("F_x", "F_y", "F_z")]
                + [(f"T_{a}", _wrench(T=e)) for a, e in _perpendicular(u, joint, "rotation")])
    if kind == "prismatic":
        u = step_axis(steps[0])
        return ([(f"F_{a}", _wrench(F=e)) for a, e in _perpendicular(u, joint, "translation")]
                + [(n, _unit(n)) for n in ("T_x", "T_y", "T_z")])
    if kind == "cylindrical":
        u = step_axis(steps[0])
        perp = _perpendicular(u, joint, "cylinder")
        return ([(f"F_{a}", _wrench(F=e)) for a, e in perp]
                + [(f"T_{a}", _wrench(T=e)) for a, e in perp])
    if kind == "planar":
        n = step_axis(steps[2])
        ax = "xyz"[[abs(int(c)) for c in n].index(1)]
        return [(f"F_{ax}", _unit(f"F_{ax}"))] + [
            (f"T_{a}", _unit(f"T_{a}")) for a in "xyz" if a != ax]
    if kind == "universal":
        (w1, w2) = (w for _, w in relative_twist(joint, joint.coordinates))
        n = _cross(w1, w2)
        u1, u2 = step_axis(steps[0]), step_axis(steps[1])
        norm = se.sqrt(_dot(_cross(u1, u2), _cross(u1, u2)))  # constant: |A2ᵀu1 × u2| = |u1 × u2|
        if not any(c.free_symbols for c in (*u1, *u2)):
            norm = se.Float(float(norm)) if float(norm) != 1.0 else ONE
        return ([(nm, _unit(nm)) for nm in ("F_x", "F_y", "F_z")]
                + [("T_n", _wrench(T=_scale(n, 1 / norm)))])
    return _derived_directions(joint, coordinates, parameters or {})


def _user_directions(joint: Joint) -> list[tuple[str, Wrench]]:
    out: list[tuple[str, Wrench]] = []
    for k, item in enumerate(joint.constrained or ()):
        where = f'joint "{joint.name}" constrained[{k}]'
        if isinstance(item, str):
            if item not in _UNIT:
                raise ModelError(f"{where}: {item!r} is not one of {', '.join(_UNIT)}; give "
                                 "(name, (F_x, F_y, F_z, T_x, T_y, T_z)) for other directions")
            out.append((item, _unit(item)))
            continue
        if not (isinstance(item, tuple | list) and len(item) == 2 and isinstance(item[0], str)):
            raise ModelError(f"{where}: expected a name like 'F_x' or a pair "
                             f"(name, (F_x, F_y, F_z, T_x, T_y, T_z)), got {item!r}")
        name, vec = item
        if not name.isidentifier():
            raise ModelError(f"{where}: name {name!r} must be an identifier")
        from ...model.expressions import as_vector

        w = as_vector(vec, where, n=6)
        if all(c == 0 for c in w):
            raise ModelError(f"{where}: the wrench direction {name!r} is zero")
        out.append((name, w))
    names = [n for n, _ in out]
    dup = {n for n in names if names.count(n) > 1}
    if dup:
        raise ModelError(f'joint "{joint.name}": constrained direction(s) {sorted(dup)} given twice')
    return out


def _derived_directions(joint: Joint, coordinates: Sequence[se.Symbol],
                        parameters: Mapping[str, float]) -> list[tuple[str, Wrench]]:
    """Constrained directions of a general joint: a basis of the wrenches that do no work in
    any motion its elementary steps allow (the complement of the relative twist), chosen among
    the unit wrenches along the child frame's axes and the torques normal to two rotation axes.
    """
    ys = [c for c in coordinates
          if any(c in (s.angle.free_symbols if isinstance(s, Rot) else
                       set().union(*(x.free_symbols for x in s.vector))) for s in joint.steps)]
    twists = relative_twist(joint, ys)
    cols: list[se.Basic] = [x for v, w in twists for x in (*v, *w)]
    candidates: list[tuple[str, Wrench]] = [(n, _unit(n)) for n in _UNIT]
    axes = [w for _, w in twists]
    normals = 0
    for i in range(len(axes)):
        for j in range(i + 1, len(axes)):
            n = _cross(axes[i], axes[j])
            if any(c != 0 for c in n):
                normals += 1
                candidates.append((f"T_n{normals}" if normals > 1 else "T_n", _wrench(T=n)))
    rng = np.random.default_rng(20240601)
    # three states where the steps have real values (a square root of a coordinate has none
    # for negative ones): drawn among more, the others dropped
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        values = _sample_values(cols + [c for _, w in candidates for c in w], coordinates,
                                parameters, rng, 24)
    values = values[:, np.isfinite(values).all(axis=0)][:, :3]
    samples = values.shape[1]
    if samples == 0:
        raise ModelError(
            f'joint "{joint.name}": its steps have no finite real value at any of 24 random '
            "states, so its constrained directions cannot be derived; give them with "
            "General(..., constrained=[...])")
    J = values[:len(cols)].reshape(len(ys), 6, samples) if ys else np.zeros((0, 6, samples))
    Wc = values[len(cols):].reshape(len(candidates), 6, samples)
    rank = max((np.linalg.matrix_rank(J[:, :, s].T, tol=1e-9) for s in range(samples)), default=0)
    need = 6 - rank
    chosen: list[int] = []
    for c in range(len(candidates)):
        if len(chosen) == need:
            break
        w = Wc[c]
        scale = max(1.0, float(np.abs(w).max()))
        if J.shape[0] and np.abs(np.einsum("jas,as->js", J, w)).max() > 1e-9 * scale * max(
                1.0, float(np.abs(J).max())):
            continue
        trial = Wc[chosen + [c]]
        if all(np.linalg.matrix_rank(trial[:, :, s], tol=1e-9) == len(chosen) + 1
               for s in range(samples)):
            chosen.append(c)
    extra: list[tuple[str, Wrench]] = []
    if len(chosen) < need and J.shape[0] and np.ptp(J, axis=2).max() < 1e-12:
        # constant relative twist (a screw, a slanted slider): complete the basis with the
        # orthonormal complement of the twist and the directions chosen so far
        A = np.concatenate([J[:, :, 0], Wc[chosen, :, 0]]) if chosen else J[:, :, 0]
        _, sv, Vt = np.linalg.svd(A)
        rank_A = int((sv > 1e-9 * max(1.0, sv[0])).sum())
        for k, v in enumerate(Vt[rank_A:rank_A + need - len(chosen)], start=1):
            v = np.where(np.abs(v) < 1e-15, 0.0, v)
            extra.append((f"W_{k}", tuple(se.Float(float(x)) if x else ZERO for x in v)))
    if len(chosen) + len(extra) < need:
        raise ModelError(
            f'joint "{joint.name}": cannot derive its {need} constrained directions from its '
            f"steps (found {[candidates[c][0] for c in chosen]}); give them with "
            "General(..., constrained=['F_x', ..., ('T_a', (0, 0, 0, tx, ty, tz))])"
        )
    out = []
    for c in chosen:
        name, w = candidates[c]
        if name.startswith("T_n"):
            norm = np.linalg.norm(Wc[c][3:], axis=0)
            if np.ptp(norm) < 1e-12 * norm.max():  # constant length: normalize symbolically
                w = tuple(x / se.Float(float(norm[0])) if float(norm[0]) != 1.0 else x for x in w)
        out.append((name, w))
    return out + extra
def _sample_values(exprs: list[se.Basic], coordinates: Sequence[se.Symbol],
                   parameters: Mapping[str, float], rng: np.random.Generator,
                   samples: int) -> np.ndarray:
    """Values of ``exprs`` at ``samples`` random coordinates and times, parameters at their
    defaults (perturbed by up to 10 %), as an array (len(exprs), samples)."""
    vals: dict[se.Basic, Any] = {c: rng.uniform(-math.pi, math.pi, samples) for c in coordinates}
    vals[se.Symbol("t")] = rng.uniform(0.0, 2.0, samples)
    for k, v in parameters.items():
        vals[se.Symbol(k)] = v * rng.uniform(0.9, 1.1, samples)
    for e in exprs:  # symbols nobody declared (a joint checked on its own): random values
        for s in e.free_symbols:
            vals.setdefault(s, rng.uniform(0.5, 1.5, samples))
    out = evaluate_arrays(exprs, vals)
    return np.array([np.broadcast_to(np.asarray(v, float), (samples,)) for v in out])


@lru_cache(maxsize=32)
def joint_directions(system: System, only: tuple[str, ...] | None = None
                     ) -> tuple[JointReactions, ...]:
    """The constrained directions of every joint (or of the joints named in ``only``), in body
    order, with the names and columns of their components of g (no Q̄ yet: that needs the
    kinematics)."""
    params = system.parameter_values
    joints: list[JointReactions] = []
    start = 0
    for body in system.bodies:
        if only is not None and body.joint.name not in only:
            continue
        dirs = constrained_directions(body.joint, system.coordinates, params)
        joints.append(JointReactions(
            body.joint, body.name, body.parent,
            tuple(f"{body.joint.name}.{suffix}" for suffix, _ in dirs),
            tuple(w for _, w in dirs), tuple(range(start, start + len(dirs)))))
        start += len(dirs)
    return tuple(joints)
