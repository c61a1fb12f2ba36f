"""Reaction forces (METHOD.md §4): Q̄ from the joints, N̂·g = k̂ − q̂.

Every joint transmits a *wrench* (force and torque) in the directions it constrains. The wrench
is written in the child body's frame (the frame at the end of the joint) and acts at that frame's
origin, the joint point on the child side; the child body receives it with a plus sign, the
parent with a minus sign, each with the lever arm from the joint point to its centre of mass:

* translational rows (inertial frame): ``±S_c·F``
* rotational rows, child (child body frame, about its centre of mass): ``T − c_c × F``
* rotational rows, parent (parent body frame, about its centre of mass):
  ``−(R_pc·T + (o_pc − c_p) × R_pc·F)``, ``R_pc`` the rotation child → parent and ``o_pc`` the
  child frame's origin in the parent frame.

So ``Q̄`` (6p×q) has one column per constrained direction, ``g`` (q) are the magnitudes of the
reaction forces and torques, named ``<joint>.F_x``, ``<joint>.T_y``, ... after the joint and the
direction in the child frame. Multiplying ``M̄·J̄·ÿ + q̄^c = q̄^e + Q̄·g`` by ``Q̄ᵀM̄⁻¹`` removes
ÿ (orthogonality ``J̄ᵀQ̄ = 0``)::

    N̂·g = k̂ − q̂,   N̂ = Q̄ᵀM̄⁻¹Q̄,  k̂ = Q̄ᵀM̄⁻¹q̄^c,  q̂ = Q̄ᵀM̄⁻¹q̄^e.

Singular inertia
----------------
Rows of M̄ that are zero (the rotational rows of a point mass, the axial row of a thin rod, all
six rows of a massless body) have no inverse. They are *not* dropped: they state that the
wrench on a body without inertia balances (``0 = q̄^e_s − q̄^c_s + Q̄_s·g``, the statics of a
massless link), which determines, e.g., that a massless rod with a point mass transmits only an
axial force. With ``r`` the regular and ``s`` the singular rows, ``N̂, k̂, q̂`` are formed from the
regular rows, and the reactions solve the bordered system ::

    [ N̂    Q̄_sᵀ ] [ g ]   [ k̂ − q̂         ]
    [ Q̄_s  0    ] [ λ ] = [ q̄^c_s − q̄^e_s ],   λ = J̄_s·ÿ

(multiply the regular rows by ``Q̄_rᵀM̄_r⁻¹`` and use ``Q̄_rᵀJ̄_r = −Q̄_sᵀJ̄_s``). It is exact:
the limit of the regular method for inertia ε → 0. Components of ``g`` that this system leaves
open (redundant constrained directions, a statically indeterminate joint) are reported as
undetermined (NaN, and listed by name), never as numbers.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING, Any

import numpy as np
import symengine as se

from ..errors import EvaluationError, JourdainError, ModelError
from ..model.bodies import WORLD
from ..model.expressions import values_at
from ..model.joints import IDENTITY, Joint, Mat3, Rot, Vec3, rotation_matrix
from ..symbolic import SymMatrix
from .kinematics import Z3, _add, _cross, _dot, _mm, _mtv, _mv, _scale, kinematics
from .newton_euler import NewtonEuler, joint_transform, newton_euler
from .projection import projection  # the model has no stage methods (issue 16)

if TYPE_CHECKING:
    from ..model.system import System

ZERO = se.Integer(0)
ONE = se.Integer(1)
Wrench = tuple[se.Basic, se.Basic, se.Basic, se.Basic, se.Basic, se.Basic]

_UNIT = {
    "F_x": (1, 0, 0, 0, 0, 0), "F_y": (0, 1, 0, 0, 0, 0), "F_z": (0, 0, 1, 0, 0, 0),
    "T_x": (0, 0, 0, 1, 0, 0), "T_y": (0, 0, 0, 0, 1, 0), "T_z": (0, 0, 0, 0, 0, 1),
}


def _unit(name: str) -> Wrench:
    return tuple(se.Integer(c) for c in _UNIT[name])  # type: ignore[return-value]


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
            return [(a, tuple(se.Integer(int(a == b)) for b in "xyz")) for a in others]  # type: ignore[misc]
    k = int(np.argmin(np.abs(uv)))
    e = np.zeros(3)
    e[k] = 1.0
    e1 = np.cross(uv, e)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(uv, e1)
    return [("1", tuple(se.Float(float(x)) for x in e1)),  # type: ignore[misc]
            ("2", tuple(se.Float(float(x)) for x in e2))]


def _wrench(F: Vec3 = Z3, T: Vec3 = Z3) -> Wrench:
    return (*F, *T)  # type: ignore[return-value]


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
                v = _add(v, _mv(Rb, dv))  # type: ignore[arg-type]
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
        u = steps[0].axis
        return ([(n, _unit(n)) for n in ("F_x", "F_y", "F_z")]
                + [(f"T_{a}", _wrench(T=e)) for a, e in _perpendicular(u, joint, "rotation")])
    if kind == "prismatic":
        u = steps[0].axis
        return ([(f"F_{a}", _wrench(F=e)) for a, e in _perpendicular(u, joint, "translation")]
                + [(n, _unit(n)) for n in ("T_x", "T_y", "T_z")])
    if kind == "cylindrical":
        u = steps[0].axis
        perp = _perpendicular(u, joint, "cylinder")
        return ([(f"F_{a}", _wrench(F=e)) for a, e in perp]
                + [(f"T_{a}", _wrench(T=e)) for a, e in perp])
    if kind == "planar":
        n = steps[2].axis
        ax = "xyz"[[abs(int(c)) for c in n].index(1)]
        return [(f"F_{ax}", _unit(f"F_{ax}"))] + [
            (f"T_{a}", _unit(f"T_{a}")) for a in "xyz" if a != ax]
    if kind == "universal":
        (w1, w2) = (w for _, w in relative_twist(joint, joint.coordinates))
        n = _cross(w1, w2)
        u1, u2 = steps[0].axis, steps[1].axis
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
        from ..model.expressions import as_vector

        w = as_vector(vec, where, n=6)
        if all(c == 0 for c in w):
            raise ModelError(f"{where}: the wrench direction {name!r} is zero")
        out.append((name, w))  # type: ignore[arg-type]
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
            extra.append((f"W_{k}", tuple(se.Float(float(x)) if x else ZERO for x in v)))  # type: ignore[misc]
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
    return out + extra  # type: ignore[return-value]


# --- numeric evaluation of expression graphs ----------------------------------------------------
_NUMPY = {"sin": np.sin, "cos": np.cos, "tan": np.tan, "exp": np.exp, "log": np.log,
          "Abs": np.abs, "asin": np.arcsin, "acos": np.arccos, "atan": np.arctan,
          "sinh": np.sinh, "cosh": np.cosh, "tanh": np.tanh, "sign": np.sign}


def _key1(e: se.Basic) -> tuple:
    args = e.args
    if not args:
        return (type(e).__name__, hash(e), str(e))
    return (type(e).__name__, hash(e), tuple(sorted(hash(a) for a in args)))


def _node_key(e: se.Basic) -> tuple:
    """Structural fingerprint of a node over three levels, the bucket key of
    :func:`graph_values`. SymEngine's hash of a sum ignores the coefficients of its terms
    (x + y and 2x + 2y share it), its children's hashes do not."""
    args = e.args
    if not args:
        return (type(e).__name__, hash(e), str(e))
    return (type(e).__name__, hash(e), tuple(sorted(_key1(a) for a in args)))


def graph_values(exprs: Sequence[se.Basic], values: Mapping[se.Basic, Any]) -> list[Any]:
    """Numeric values of ``exprs`` for the symbol values ``values`` (NumPy arrays broadcast), each
    distinct node of the shared expression graph evaluated once.

    Nodes are looked up by :func:`_node_key` and confirmed with ``==``, which SymEngine answers
    at once for the same shared node; a fingerprint alone is not exact (two different nodes of
    a large graph can share it, which gave wrong numbers here). ``==`` walks whole trees on
    distinct but equal nodes, so this is meant for the short expressions of single joints; the
    matrices of whole systems are evaluated by the compiled code of :mod:`jourdain.numeric`.
    """
    given = {k: np.asarray(v, dtype=float) for k, v in values.items()}

    def atom(a: se.Basic) -> Any:
        if isinstance(a, se.Symbol):
            if a in given:
                return given[a]
            raise EvaluationError(f"no value for symbol {a}")
        return float(a)

    memo: dict[tuple, list[tuple[se.Basic, Any]]] = {}

    def lookup(e: se.Basic, k: tuple) -> tuple[bool, Any]:
        for node, v in memo.get(k, ()):
            if node == e:
                return True, v
        return False, None

    out: list[Any] = []
    for root in exprs:
        if not root.args:
            out.append(atom(root))
            continue
        rk = _node_key(root)
        stack: list[tuple[se.Basic, tuple, list | None]] = [(root, rk, None)]
        while stack:
            node, k, kids = stack.pop()
            if kids is None:
                if lookup(node, k)[0]:
                    continue
                args = node.args
                kids = [_node_key(a) if a.args else None for a in args]
                stack.append((node, k, kids))
                stack.extend((a, ka, None) for a, ka in zip(args, kids, strict=True)
                             if ka is not None)
                continue
            if lookup(node, k)[0]:
                continue
            a_vals = [lookup(a, ka)[1] if ka is not None else atom(a)
                      for a, ka in zip(node.args, kids, strict=True)]
            memo.setdefault(k, []).append((node, _apply(node, a_vals)))
        out.append(lookup(root, rk)[1])
    return out


def _apply(node: se.Basic, args: list[Any]) -> Any:
    name = type(node).__name__
    if name == "Add":
        r = args[0]
        for x in args[1:]:
            r = r + x
        return r
    if name == "Mul":
        r = args[0]
        for x in args[1:]:
            r = r * x
        return r
    if name == "Pow":
        return np.power(args[0], args[1])
    if name in _NUMPY:
        return _NUMPY[name](*args)
    if name == "atan2":
        return np.arctan2(*args)
    return np.vectorize(lambda *xs: float(node.func(*(se.Float(x) for x in xs))))(*args)


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
    out = graph_values(exprs, vals)
    return np.array([np.broadcast_to(np.asarray(v, float), (samples,)) for v in out])


# --- the stage ----------------------------------------------------------------------------------
@dataclass(frozen=True, repr=False)
class Reactions:
    """Result of :func:`reactions` (METHOD.md §4).

    Attributes
    ----------
    Q_bar : SymMatrix (6p×q)
        Distribution matrix of the reaction forces; translational rows inertial, rotational rows
        in each body's frame about its centre of mass; column k belongs to ``g_names[k]``.
    N_hat : SymMatrix (q×q)
        ``Q̄_rᵀ M̄_r⁻¹ Q̄_r`` over the regular rows r of M̄ (all rows when every body has mass and
        a regular inertia tensor; then symmetric positive definite).
    k_hat, q_hat : SymMatrix (q×1)
        ``Q̄_rᵀ M̄_r⁻¹ q̄^c_r`` and ``Q̄_rᵀ M̄_r⁻¹ q̄^e_r``.
    g_names : tuple of str
        ``<joint>.<direction>``, e.g. ``hinge1.F_x``: force/torque components in the child body
        frame at the joint point.
    joints : tuple of JointReactions
    singular_rows : tuple of int
        Rows of the 6p-vectors where M̄ is zero (no inertia); see the module docstring.
    orthogonality : tuple of (joint name, "symbolic" | "numeric")
        How ``J̄ᵀ·Q̄ = 0`` was verified for each joint's directions (:func:`check_joints`); the
        assembled matrices are checked by :func:`check_orthogonality` before numbers are made.
    newton_euler : NewtonEuler
        The stage this came from.
    """

    newton_euler: NewtonEuler
    Q_bar: SymMatrix
    N_hat: SymMatrix
    k_hat: SymMatrix
    q_hat: SymMatrix
    g_names: tuple[str, ...]
    joints: tuple[JointReactions, ...]
    singular_rows: tuple[int, ...]
    orthogonality: tuple[tuple[str, str], ...] = ()

    @property
    def system(self) -> System:
        return self.newton_euler.system

    def __repr__(self) -> str:
        n6, q = self.Q_bar.shape
        names = ", ".join(self.g_names[:6]) + (", ..." if q > 6 else "")
        return (f"Reactions({self.system.name!r}: Q_bar {n6}x{q}, g = [{names}], "
                f"{len(self.singular_rows)} rows without inertia)")

    def joint(self, name: str) -> JointReactions:
        """The constrained directions of the joint called ``name``."""
        for jr in self.joints:
            if jr.joint.name == name:
                return jr
        raise ModelError(f'unknown joint "{name}"; joints are: '
                         f'{", ".join(j.joint.name for j in self.joints)}')

    def g(self, max_unknowns: int = 16, simplify: bool = True) -> Any:
        """``g`` in closed form, a :class:`sympy.Matrix` (q×1) in y, ẏ, t, parameters, inputs.

        Solves ``N̂·g = k̂ − q̂`` (with the rows of bodies without inertia, see the module
        docstring) with SymPy; meant for small systems (at most ``max_unknowns`` unknowns).
        Components that the model leaves undetermined raise :class:`JourdainError`.
        """
        import sympy

        q = len(self.g_names)
        s = len(self.singular_rows)
        if q + s > max_unknowns:
            raise JourdainError(
                f"closed-form g has {q + s} unknowns (more than max_unknowns={max_unknowns}); "
                "evaluate it numerically with evaluate() or joint_reactions()"
            )
        ne = self.newton_euler
        memo: dict = {}
        from ..symbolic import to_sympy

        N = sympy.Matrix(q + s, q + s, lambda i, j: 0)
        rhs = sympy.zeros(q + s, 1)
        for i in range(q):
            for j in range(q):
                N[i, j] = to_sympy(self.N_hat[i, j], memo)
            rhs[i] = to_sympy(self.k_hat[i] - self.q_hat[i], memo)
        for a, row in enumerate(self.singular_rows):
            for j in range(q):
                e = to_sympy(self.Q_bar[row, j], memo)
                N[q + a, j] = e
                N[j, q + a] = e
            rhs[q + a] = to_sympy(ne.q_c[row] - ne.q_e[row], memo)
        unknowns = sympy.symbols(f"_g0:{q + s}")
        sol = sympy.linsolve((N, rhs), unknowns)
        if not sol:
            raise JourdainError("the reaction equations have no solution (inconsistent loads on "
                                "bodies without inertia)")
        (vals,) = list(sol)
        out = []
        for k in range(q):
            v = vals[k]
            if v.free_symbols & set(unknowns):
                raise JourdainError(f'reaction component "{self.g_names[k]}" is undetermined')
            out.append(sympy.simplify(v) if simplify else v)
        return sympy.Matrix(out)

    def joint_g(self, name: str) -> SymMatrix:
        """Reaction components of one joint without forming all of ``g``.

        The wrench that the joint transmits equals the Newton–Euler residual of the sub-tree it
        carries, ``Σ (m_i a_i − f_i^e, I_i α_i + ω̃_i I_i ω_i − l_i^e)``, moved to the joint
        point and the child frame; projected on the joint's (orthonormal) directions. The result
        is in y, ẏ, ÿ (symbols ``<name>_dd``), t, parameters and inputs: insert ÿ from the
        equations of motion, or from a measured or simulated motion.
        """
        jr = self.joint(name)
        W = _subtree_wrench(self.newton_euler, jr.child)
        return SymMatrix.column(_project(jr, W))

    def evaluate(self, y: Any, yd: Any, t: float = 0.0,
                 parameters: Mapping[str, float] | None = None,
                 inputs: Mapping[str, float] | Sequence[float] | None = None
                 ) -> dict[str, Any]:
        """Numbers at one state; see :func:`evaluate_reactions`."""
        return evaluate_reactions(self.system, y, yd, t, parameters, inputs)


def _body_rows(system: System) -> dict[str, int]:
    return {b.name: i for i, b in enumerate(system.bodies)}


def _singular_rows(system: System) -> tuple[tuple[int, ...], dict[str, tuple[list[int], Any]]]:
    """Rows where M̄ vanishes and, per body, its regular rotational axes with the inverse of the
    inertia tensor restricted to them."""
    p = len(system.bodies)
    values = dict(system.parameters)

    singular: list[int] = []
    inv: dict[str, tuple[list[int], Any]] = {}
    for i, b in enumerate(system.bodies):
        if b.mass == 0:
            singular.extend(range(3 * i, 3 * i + 3))
        elif abs(values_at([b.mass], values)[0]) == 0.0:
            raise ModelError(f'body "{b.name}": its mass is zero at the default parameters but '
                             "not identically zero; write mass=0 for a massless body")
        I = b.inertia
        regular = [a for a in range(3)
                   if not all(I[a][c] == 0 and I[c][a] == 0 for c in range(3))]
        singular.extend(3 * p + 3 * i + a for a in range(3) if a not in regular)
        if regular:
            sub = [[I[a][c] for c in regular] for a in regular]
            Ir = np.array(values_at([x for r in sub for x in r], values)).reshape(len(sub), -1)
            # |det| <= 1e-12·s^n, s = max|I|, tested as det(I/s): s^n overflows for inertias
            # above 1e102 (a mass of 1e300), and a floor of 1 on s made the small, regular
            # inertias of real robot links (1e-6 kg m², det 1e-18) count as singular
            s = float(np.abs(Ir).max()) or 1.0
            if abs(np.linalg.det(Ir / s)) <= 1e-12:
                raise ModelError(
                    f'body "{b.name}": its inertia tensor is singular, but not along body axes '
                    "(no row and column of zeros); give the inertia in a frame whose axes are "
                    "its principal axes"
                )
            inv[b.name] = (regular, _inverse(sub))
        else:
            inv[b.name] = ([], None)
    return tuple(sorted(singular)), inv


def _inverse(A: list[list[se.Basic]]) -> list[list[se.Basic]]:
    n = len(A)
    if n == 1:
        return [[1 / A[0][0]]]
    if n == 2:
        d = A[0][0] * A[1][1] - A[0][1] * A[1][0]
        return [[A[1][1] / d, -A[0][1] / d], [-A[1][0] / d, A[0][0] / d]]
    # 3x3 via the adjugate (constant parameters only: the expressions stay short)
    c = [[A[(i + 1) % 3][(j + 1) % 3] * A[(i + 2) % 3][(j + 2) % 3]
          - A[(i + 1) % 3][(j + 2) % 3] * A[(i + 2) % 3][(j + 1) % 3] for j in range(3)]
         for i in range(3)]
    d = A[0][0] * c[0][0] + A[0][1] * c[0][1] + A[0][2] * c[0][2]
    return [[c[j][i] / d for j in range(3)] for i in range(3)]


@lru_cache(maxsize=32)
def joint_directions(system: System) -> tuple[JointReactions, ...]:
    """The constrained directions of every joint, in body order, with the names and columns of
    their components of g (no Q̄ yet: that needs the kinematics)."""
    params = system.parameter_values
    joints: list[JointReactions] = []
    start = 0
    for body in system.bodies:
        dirs = constrained_directions(body.joint, system.coordinates, params)
        joints.append(JointReactions(
            body.joint, body.name, body.parent,
            tuple(f"{body.joint.name}.{suffix}" for suffix, _ in dirs),
            tuple(w for _, w in dirs), tuple(range(start, start + len(dirs)))))
        start += len(dirs)
    return tuple(joints)


@lru_cache(maxsize=32)
def _checked_joints(system: System) -> dict[str, str]:
    """:func:`check_joints` of :func:`joint_directions` (ModelError for a direction that does
    work), once per system."""
    return check_joints(system, joint_directions(system))


def reactions(ne: NewtonEuler) -> Reactions:
    """Q̄ from the joints and N̂, k̂, q̂ (METHOD.md §4); checks ``J̄ᵀQ̄ = 0``.

    Parameters
    ----------
    ne : NewtonEuler
        The Newton–Euler equations of the system.

    Returns
    -------
    Reactions
        ``Q_bar`` (6p×q), ``N_hat`` (q×q), ``k_hat``, ``q_hat`` (q×1), ``g_names``.

    Raises
    ------
    ModelError
        When a joint's constrained directions violate the orthogonality relation ``J̄ᵀQ̄ = 0``
        (checked numerically at random states), naming the joint and the direction.
    """
    kin = ne.kinematics
    system = kin.system
    bodies = system.bodies
    p = len(bodies)
    row = _body_rows(system)
    joints = joint_directions(system)
    names = [n for jr in joints for n in jr.names]
    # columns of Q̄, sparse: per column {row: expression}
    cols: list[dict[int, se.Basic]] = []
    # per column, its force on each body in that body's own frame (for N̂: SᵀS = E is then
    # never left for the simplifier to find)
    local: list[dict[int, Vec3]] = []
    for body, bk, jr in zip(bodies, kin.bodies, joints, strict=True):
        j = body.joint
        S = bk.S.rows
        R_pc, o_pc = joint_transform(j)
        c_c = body.com
        i = row[body.name]
        parent = None if body.parent == WORLD else system.body(body.parent)
        for w in jr.wrenches:
            F, T = w[:3], w[3:]
            col: dict[int, se.Basic] = {}
            SF = _mv(S, F)
            rot_c = _add(T, _scale(_cross(c_c, F), -1))  # lever arm: from the COM to O
            for a in range(3):
                col[3 * i + a] = SF[a]
                col[3 * p + 3 * i + a] = rot_c[a]
            if parent is not None:
                k = row[parent.name]
                RF, RT = _mv(R_pc, F), _mv(R_pc, T)
                arm = (o_pc[0] - parent.com[0], o_pc[1] - parent.com[1], o_pc[2] - parent.com[2])
                rot_p = _add(RT, _cross(arm, RF))
                for a in range(3):
                    col[3 * k + a] = -SF[a]
                    col[3 * p + 3 * k + a] = -rot_p[a]
            cols.append({r: e for r, e in col.items() if e != 0})
            local.append({i: F} if parent is None else {i: F, row[parent.name]: _scale(RF, -1)})
    q = len(cols)
    n6 = 6 * p
    Q_rows = [[ZERO] * q for _ in range(n6)]
    for c, col in enumerate(cols):
        for r, e in col.items():
            Q_rows[r][c] = e
    Q_bar = SymMatrix.from_rows(Q_rows)
    verified = _checked_joints(system)
    singular, inv = _singular_rows(system)
    # N̂, k̂, q̂ body by body over the regular rows (M̄ block diagonal)
    N = [[[] for _ in range(q)] for _ in range(q)]
    kh: list[list[se.Basic]] = [[] for _ in range(q)]
    qh: list[list[se.Basic]] = [[] for _ in range(q)]
    qc, qe = ne.q_c, ne.q_e
    for i, body in enumerate(bodies):
        blocks = []
        if body.mass != 0:
            mi = 1 / body.mass
            blocks.append((list(range(3 * i, 3 * i + 3)), [[mi if a == b else ZERO
                                                            for b in range(3)] for a in range(3)]))
        regular, Iinv = inv[body.name]
        if regular:
            blocks.append(([3 * p + 3 * i + a for a in regular], Iinv))
        for rows_, Minv in blocks:
            if rows_[0] < 3 * p:  # translational: forces and loads in the body's frame
                S_i = kin.bodies[i].S.rows
                touching = [c for c in range(q) if i in local[c]
                            and any(x != 0 for x in local[c][i])]
                vecs = {c: list(local[c][i]) for c in touching}
                cvec = list(_mtv(S_i, tuple(qc[r] for r in rows_)))  # type: ignore[arg-type]
                evec = list(_mtv(S_i, tuple(qe[r] for r in rows_)))  # type: ignore[arg-type]
            else:
                touching = [c for c in range(q) if any(r in cols[c] for r in rows_)]
                vecs = {c: [cols[c].get(r, ZERO) for r in rows_] for c in touching}
                cvec = [qc[r] for r in rows_]
                evec = [qe[r] for r in rows_]
            mv = {c: [se.Add(*(Minv[a][b] * vecs[c][b] for b in range(len(rows_))))
                      for a in range(len(rows_))] for c in touching}
            for ia, ca in enumerate(touching):
                for cb in touching[ia:]:
                    N[ca][cb].append(se.Add(*(x * y for x, y in zip(mv[ca], vecs[cb], strict=True))))
                if any(x != 0 for x in cvec):
                    kh[ca].append(se.Add(*(x * y for x, y in zip(mv[ca], cvec, strict=True))))
                if any(x != 0 for x in evec):
                    qh[ca].append(se.Add(*(x * y for x, y in zip(mv[ca], evec, strict=True))))
    return Reactions(
        newton_euler=ne, Q_bar=Q_bar, N_hat=SymMatrix.symmetric_from_terms(N),
        k_hat=SymMatrix.column([se.Add(*t) if t else ZERO for t in kh]),
        q_hat=SymMatrix.column([se.Add(*t) if t else ZERO for t in qh]),
        g_names=tuple(names), joints=tuple(joints), singular_rows=singular,
        orthogonality=tuple(verified.items()),
    )


def _step_coordinates(joint: Joint, coordinates: Sequence[se.Symbol]) -> list[se.Symbol]:
    """The coordinates that the joint's elementary steps depend on."""
    free: set = set()
    for st in joint.steps:
        exprs = [st.angle] if isinstance(st, Rot) else list(st.vector)
        for e in exprs:
            free |= e.free_symbols
    return [c for c in coordinates if c in free]


def check_joints(system: System, joints: Sequence[JointReactions], samples: int = 3,
                 seed: int = 7) -> dict[str, str]:
    """Joint by joint: every constrained direction does no work in the joint's relative motion
    (``wᵀ·ξ = 0``, the orthogonality relation ``J̄ᵀ·Q̄ = 0`` restricted to one joint), the
    directions and the motions of a joint span all six, and the joints' motions are independent
    (their ranks add up to f).

    The orthogonality is shown symbolically where the expanded products ``wᵀ·ξ`` vanish (unit
    directions, the torque normal to two axes); the rest, and the ranks, are checked numerically
    at random states (coordinates in (−π, π), t in (0, 2), parameters within 10 % of their
    defaults) on the joint's own short expressions. Raises :class:`ModelError` naming the joint
    and the direction. Returns, per joint, ``"symbolic"`` or ``"numeric"``: how its
    orthogonality was verified.
    """
    rng = np.random.default_rng(seed)
    params = system.parameter_values
    total = 0
    ranks: list[tuple[JointReactions, int]] = []
    how: dict[str, str] = {}
    for jr in joints:
        ys = _step_coordinates(jr.joint, system.coordinates)
        cols = relative_twist(jr.joint, ys)
        twist = [x for v, w in cols for x in (*v, *w)]
        wr = [x for w in jr.wrenches for x in w]
        how[jr.joint.name] = "symbolic" if all(
            se.expand(_dot(w[:3], v) + _dot(w[3:], om)) == 0
            for w in jr.wrenches for v, om in cols) else "numeric"
        vals = _sample_values(twist + wr, system.coordinates, params, rng, samples)
        X = vals[:len(twist)].reshape(len(ys), 6, samples)
        W = vals[len(twist):].reshape(len(jr.wrenches), 6, samples)
        rank = max((np.linalg.matrix_rank(X[:, :, k], tol=1e-9) for k in range(samples)),
                   default=0) if ys else 0
        ranks.append((jr, rank))
        total += rank
        for k in range(samples):
            power = W[:, :, k] @ X[:, :, k].T  # (directions, coordinates)
            scale = max(1.0, float(np.abs(X[:, :, k]).max(initial=0.0)))
            for d in range(len(jr.wrenches)):
                bad = np.nonzero(np.abs(power[d]) > 1e-9 * scale *
                                 max(1.0, float(np.abs(W[d, :, k]).max())))[0]
                if bad.size:
                    raise ModelError(
                        f'joint "{jr.joint.name}" (body "{jr.child}"): its constrained direction '
                        f'"{jr.names[d]}" does work in the joint\'s motion with coordinate '
                        f"{ys[int(bad[0])]} (relative power {abs(power[d, bad[0]]):.2e} per unit "
                        "rate); the orthogonality relation J̄ᵀ·Q̄ = 0 fails"
                    )
            both = np.concatenate([X[:, :, k], W[:, :, k]]) if ys else W[:, :, k]
            if both.shape[0] < 6 or np.linalg.matrix_rank(both, tol=1e-9) < 6:
                raise ModelError(
                    f'joint "{jr.joint.name}" (body "{jr.child}"): its {len(jr.names)} '
                    f"constrained directions and its {rank} directions of motion do not span "
                    "all six; a reaction would be missing from Q̄ (give the missing directions "
                    "in constrained=[...])"
                )
    if total > system.f:
        # a joint that moves with coordinates it does not drive (gears, a screw turned by
        # another joint's angle) couples two joints: that coupling force is no joint's reaction
        odd = [f'"{jr.joint.name}" (moves in {r} directions, drives '
               f"{len(jr.joint.coordinates)} coordinate(s))" for jr, r in ranks
               if jr.joint.kind == "general" and r != len(jr.joint.coordinates)]
        raise ModelError(
            f"the joints move in {total} independent directions but the system has f = "
            f"{system.f} coordinates: some joints are coupled (a joint moved by another joint's "
            "coordinate), and the coupling force is no single joint's reaction; "
            + (f"check joint(s) {', '.join(odd)}" if odd else "check the joints' coordinates")
        )
    return how


def check_orthogonality(r: Reactions, samples: int = 3, seed: int = 7, fn: Any = None) -> float:
    """The orthogonality relation ``J̄ᵀ·Q̄ = 0`` of the assembled symbolic matrices of ``r``,
    checked with J̄ and Q̄ compiled (``fn``: a compiled function giving ``J_bar`` and ``Q_bar``,
    compiled here from ``r`` when not given) at random states (coordinates in (−π, π), t in
    (0, 2), parameters within 10 % of their defaults), and that ``[J̄, Q̄]`` is square and
    regular (no reaction missing). :meth:`jourdain.System.evaluate` checks its own numeric Q̄
    the same way before it gives reaction forces.

    Returns the largest relative residual ``|J̄ᵀQ̄| / (|J̄|ᵀ|Q̄|)`` over the columns; raises
    :class:`ModelError` naming the joint and the direction of a column that does work.
    """
    system = r.system
    if fn is None:
        from ..numeric import lambdify

        fn = lambdify(system, {"J_bar": r.newton_euler.J_bar, "Q_bar": r.Q_bar})
    return _check_assembled(system, r.joints, fn, samples, seed)


def _check_assembled(system: System, joints: Sequence[JointReactions], fn: Any,
                     samples: int = 3, seed: int = 7) -> float:
    rng = np.random.default_rng(seed)
    pv = np.array(list(system.parameter_values.values()), dtype=float)
    worst = 0.0
    checked = 0
    for _ in range(8 * samples):  # states where the model has real values (sqrt(y) needs y ≥ 0)
        if checked == samples:
            break
        y = rng.uniform(-math.pi, math.pi, system.f)
        out = fn(y, np.zeros(system.f), float(rng.uniform(0, 2)), pv * rng.uniform(0.9, 1.1, pv.size),
                 np.zeros(len(system.inputs)))
        J, Q = out["J_bar"], out["Q_bar"]
        if not (np.isfinite(J).all() and np.isfinite(Q).all()):
            continue
        checked += 1
        n6 = J.shape[0]
        JQ = J.T @ Q
        # relative to ‖J̄_i‖·‖Q̄_k‖ (Cauchy–Schwarz), not to |J̄|ᵀ|Q̄|: a joint frame turned by
        # a float rotation leaves rounding noise (1e-17) in entries of J̄ that are zero, and
        # a torque column meeting only that noise read as relative residual 1
        scale = np.outer(np.linalg.norm(J, axis=0), np.linalg.norm(Q, axis=0)) + 1e-300
        rel = (np.abs(JQ) / scale).max(axis=0)
        worst = max(worst, float(rel.max())) if rel.size else worst
        bad = np.nonzero(rel > 1e-9)[0]
        if bad.size:
            c = int(bad[0])
            jr = next(j for j in joints if c in j.columns)
            raise ModelError(
                f'joint "{jr.joint.name}" (body "{jr.child}"): its constrained direction '
                f'"{jr.names[jr.columns.index(c)]}" does work in an admissible motion (relative '
                f"residual {rel[c]:.2e}); the orthogonality relation J̄ᵀ·Q̄ = 0 fails"
            )
        # redundant directions (more columns) leave components of g undetermined, which the
        # solve reports; missing ones (rank < 6p) would make every g wrong
        sv = np.linalg.svd(np.concatenate([J, Q], axis=1), compute_uv=False)
        rank = int((sv > 1e-9 * sv[0]).sum())
        if rank < n6:
            raise ModelError(
                f"[J̄, Q̄] has rank {rank} < 6p = {n6}: the constrained directions of the "
                "joints and the motions do not span all directions; a reaction is missing"
            )
    if checked == 0:
        raise ModelError("J̄ and Q̄ have no finite values at any of the random states tried: the "
                         "orthogonality J̄ᵀ·Q̄ = 0 cannot be checked, so no reaction forces are "
                         "given")
    return worst


# --- reactions of one joint from its sub-tree --------------------------------------------------
def _subtree(system: System, root: str) -> list[str]:
    below = {root}
    for b in system.bodies:  # tree order: parents come first
        if b.parent in below:
            below.add(b.name)
    return [b.name for b in system.bodies if b.name in below]


def _subtree_parts(ne: NewtonEuler, child: str) -> tuple[Wrench, list[Wrench]]:
    """Residual wrench of the sub-tree below (and including) ``child``, at the child frame's
    origin, in the child frame, split as ``W0 + Σ_j W_j·ÿ_j`` (it is linear in ÿ): ``W0`` from
    the local accelerations, the gyroscopic and the applied forces, ``W_j`` from the Jacobian
    columns of coordinate j."""
    kin = ne.kinematics
    system = kin.system
    f = len(kin.y)
    forces = {bf.name: bf for bf in ne.forces}
    bc = kin[child]
    Sc = bc.S.rows
    rO = _v(bc.r_O)
    W0: list[se.Basic] = [ZERO] * 6
    Wy: list[list[se.Basic]] = [[ZERO] * 6 for _ in range(f)]

    def add(acc: list[se.Basic], name: str, F: Vec3, tau: Vec3, arm: Vec3) -> None:
        # move a force (inertial, at the COM) and a torque (body frame) to the child frame
        Fc = _mtv(Sc, F)
        tau_c = tau if name == child else _mtv(Sc, _mv(kin[name].S.rows, tau))  # type: ignore[arg-type]
        T = _add(tau_c, _cross(arm, Fc))
        for a in range(3):
            acc[a] = acc[a] + Fc[a]
            acc[3 + a] = acc[3 + a] + T[a]

    for name in _subtree(system, child):
        body = system.body(name)
        bk = kin[name]
        bf = forces[name]
        r = _v(bk.r)
        arm = _mtv(Sc, (r[0] - rO[0], r[1] - rO[1], r[2] - rO[2]))
        m = body.mass
        a_bar = _v(bk.a_bar)
        F = (m * a_bar[0] - bf.f[0], m * a_bar[1] - bf.f[1], m * a_bar[2] - bf.f[2])
        tau: Vec3 = (-bf.l[0], -bf.l[1], -bf.l[2])
        I = body.inertia
        if body.has_inertia:
            w = _v(bk.omega)
            tau = _add(tau, _add(_mv(I, _v(bk.alpha_bar)), _cross(w, _mv(I, w))))
        add(W0, name, F, tau, arm)
        for j in set(bk.cols_T) | set(bk.cols_R):
            Fj = _scale(bk.cols_T.get(j, Z3), m)
            tj = _mv(I, bk.cols_R[j]) if body.has_inertia and j in bk.cols_R else Z3
            add(Wy[j], name, Fj, tj, arm)
    return tuple(W0), [tuple(w) for w in Wy]  # type: ignore[return-value]


def _subtree_wrench(ne: NewtonEuler, child: str) -> Wrench:
    """Residual wrench of the sub-tree below ``child`` (see :func:`_subtree_parts`) with ÿ as
    the symbols ``<coordinate>_dd``."""
    W0, Wy = _subtree_parts(ne, child)
    ydd = ne.kinematics.ydd
    return tuple(se.Add(W0[a], *(Wy[j][a] * ydd[j] for j in range(len(Wy))))  # type: ignore[return-value]
                 for a in range(6))


def _v(m: SymMatrix) -> Vec3:
    return (m.rows[0][0], m.rows[1][0], m.rows[2][0])


def _project(jr: JointReactions, W: Wrench) -> list[se.Basic]:
    """Components of the wrench W in the joint's constrained directions (orthonormal ones)."""
    n = len(jr.wrenches)
    if n:
        rng = np.random.default_rng(3)
        E = _sample_values([x for w in jr.wrenches for x in w], (), {}, rng, 3).reshape(n, 6, 3)
        gram = np.einsum("kas,mas->kms", E, E)
        if np.abs(gram - np.eye(n)[:, :, None]).max() > 1e-12:
            raise JourdainError(
                f'joint "{jr.joint.name}": its constrained directions are not orthonormal; '
                "use joint_reactions() or evaluate_reactions() instead"
            )
    out = []
    for w in jr.wrenches:
        out.append(_dot(w[:3], W[:3]) + _dot(w[3:], W[3:]))
    return out


# --- numbers -------------------------------------------------------------------------------------
@dataclass(frozen=True)
class ReactionLayout:
    """What the numeric reactions need besides the compiled matrices: the joints with their
    constrained directions, the names of g, the rows of M̄ without inertia, and per body the
    columns of Q̄ that touch it (its joint's and its children's joints' directions)."""

    joints: tuple[JointReactions, ...]
    g_names: tuple[str, ...]
    singular_rows: tuple[int, ...]
    touching: tuple[tuple[int, ...], ...]


@lru_cache(maxsize=32)
def _reactions_function(system: System) -> tuple[ReactionLayout, Any]:
    """The compiled Newton–Euler matrices with Q̄ (:func:`jourdain.numeric.recursive`), after
    the joint-by-joint check and the check of the assembled J̄ᵀ·Q̄ = 0; ModelError when the
    model's reactions cannot be formed."""
    from ..numeric import _eom_function

    joints = joint_directions(system)
    _checked_joints(system)
    fn = _eom_function(system)
    index = _body_rows(system)
    touching: list[list[int]] = [list(jr.columns) for jr in joints]
    for b, jr in zip(system.bodies, joints, strict=True):
        if b.parent != WORLD:
            touching[index[b.parent]].extend(jr.columns)
    lay = ReactionLayout(joints, tuple(n for jr in joints for n in jr.names),
                         _singular_rows(system)[0], tuple(tuple(sorted(t)) for t in touching))
    _check_assembled(system, joints, fn)
    return lay, fn


def check_reactions(system: System) -> None:
    """The checks made before reaction forces are given in numbers: constrained directions
    that can be formed, the joint-by-joint and the assembled orthogonality ``J̄ᵀ·Q̄ = 0``;
    :class:`ModelError` naming the joint otherwise (no symbolic N̂ is formed)."""
    _reactions_function(system)


def projected_reactions(lay: ReactionLayout, M_bar: np.ndarray, Q_bar: np.ndarray,
                        q_c: np.ndarray, q_e: np.ndarray
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``N̂ = Q̄_rᵀM̄_r⁻¹Q̄_r``, ``k̂ = Q̄_rᵀM̄_r⁻¹q̄^c_r``, ``q̂ = Q̄_rᵀM̄_r⁻¹q̄^e_r`` in numbers over
    the regular rows r of M̄ (METHOD.md §4), for one state or a batch (leading axes).

    M̄ is block diagonal, so the products are formed body by body from the few columns of Q̄
    that touch each body (O(p) small products, never a 6p×6p solve); with the Cholesky factor
    C of each block, ``N̂ += (C⁻¹Q̄_b)ᵀ(C⁻¹Q̄_b)``, so N̂ is exactly symmetric.
    """
    lead = Q_bar.shape[:-2]
    n6, q = Q_bar.shape[-2:]
    p = n6 // 6
    singular = set(lay.singular_rows)
    N = np.zeros((*lead, q, q))
    kh = np.zeros((*lead, q))
    qh = np.zeros((*lead, q))
    for i in range(p):
        cols = list(lay.touching[i])
        if not cols:
            continue
        for base in (3 * i, 3 * p + 3 * i):
            rows = [base + a for a in range(3) if base + a not in singular]
            if not rows:
                continue
            Mb = M_bar[..., rows, :][..., :, rows]
            C = np.linalg.cholesky(Mb)
            B = np.linalg.solve(C, Q_bar[..., rows, :][..., :, cols])
            bc = np.linalg.solve(C, q_c[..., rows, None])[..., 0]
            be = np.linalg.solve(C, q_e[..., rows, None])[..., 0]
            ix = np.ix_(cols, cols)
            N[..., ix[0], ix[1]] += np.swapaxes(B, -1, -2) @ B
            kh[..., cols] += np.einsum("...rc,...r->...c", B, bc)
            qh[..., cols] += np.einsum("...rc,...r->...c", B, be)
    return 0.5 * (N + np.swapaxes(N, -1, -2)), kh, qh


def solve_g(Q_bar: np.ndarray, N_hat: np.ndarray, k_hat: np.ndarray, q_hat: np.ndarray,
            q_c: np.ndarray, q_e: np.ndarray, singular_rows: Sequence[int],
            names: Sequence[str] = ()) -> tuple[np.ndarray, list[str]]:
    """Solve ``N̂·g = k̂ − q̂`` (Cholesky; N̂ symmetric positive definite), or with rows of
    bodies without inertia the bordered system of the module docstring.

    Returns ``g`` (NaN where undetermined) and the names of the undetermined components.
    """
    q = N_hat.shape[0]
    rhs = k_hat - q_hat
    s = list(singular_rows)
    if not s:
        try:
            C = np.linalg.cholesky(N_hat)
            return np.linalg.solve(C.T, np.linalg.solve(C, rhs)), []
        except np.linalg.LinAlgError:
            pass  # not positive definite: redundant directions; the general path says which
    Qs = Q_bar[s, :]
    K = np.block([[N_hat, Qs.T], [Qs, np.zeros((len(s), len(s)))]])
    b = np.concatenate([rhs, q_c[s] - q_e[s]])
    U, sv, Vt = np.linalg.svd(K)
    tol = max(K.shape) * np.finfo(float).eps * (sv[0] if sv.size else 0.0) * 1e3
    rank = int((sv > tol).sum())
    x = Vt[:rank].T @ ((U[:, :rank].T @ b) / sv[:rank])
    resid = np.abs(K @ x - b).max()
    if resid > 1e-8 * max(1.0, np.abs(b).max(), np.abs(K).max() * np.abs(x).max()):
        raise EvaluationError(
            "the reaction equations have no solution at this state: applied or gyroscopic loads "
            "on rows without inertia that no joint can balance (rows "
            f"{[s[i - q] for i in range(q, q + len(s)) if abs((K @ x - b)[i]) > 1e-8]})"
        )
    g = x[:q].copy()
    null = Vt[rank:, :q]
    und = np.nonzero(np.abs(null).max(axis=0) > 1e-8)[0] if null.size else np.array([], int)
    g[und] = np.nan
    return g, [names[i] for i in und] if names else [str(i) for i in und]


def evaluate_reactions(system: System, y: Any, yd: Any, t: float = 0.0,
                       parameters: Mapping[str, float] | None = None,
                       inputs: Mapping[str, float] | Sequence[float] | None = None,
                       eom: Mapping[str, np.ndarray] | None = None) -> dict[str, Any]:
    """Reaction forces at one state ``y, ẏ, t`` (no ÿ needed).

    Returns a dict with ``Q_bar`` (6p×q), ``N_hat`` (q×q), ``k_hat``, ``q_hat``, ``g`` (q,
    NaN where undetermined), ``g_names`` (list of str) and ``g_undetermined`` (list of the names
    of undetermined components; empty for a well-posed model). ``eom``: the output of
    :func:`jourdain.numeric.evaluate` at the same state, if already at hand.
    """
    from ..numeric import evaluate as evaluate_eom

    lay, _ = _reactions_function(system)
    if eom is None or "Q_bar" not in eom:
        eom = evaluate_eom(system, y, yd, t=t, parameters=parameters, inputs=inputs)
    Q = np.asarray(eom["Q_bar"])
    qc, qe = np.asarray(eom["q_c"]).reshape(-1), np.asarray(eom["q_e"]).reshape(-1)
    N, kh, qh = projected_reactions(lay, np.asarray(eom["M_bar"]), Q, qc, qe)
    g, und = solve_g(Q, N, kh, qh, qc, qe, lay.singular_rows, lay.g_names)
    # NaN marks undetermined components only; anything else not finite is an error
    bad = [k for k, v in (("N_hat", N), ("k_hat", kh), ("q_hat", qh)) if not np.isfinite(v).all()]
    determined = [i for i, n in enumerate(lay.g_names) if n not in und]
    if not np.isfinite(g[determined]).all():
        bad.append("g")
    if bad:
        raise EvaluationError(f"{', '.join(bad)} of {system.name!r} contain NaN or inf at this "
                              "state (the reaction equations are not solvable in floating point "
                              "here)")
    return {"Q_bar": Q, "N_hat": N, "k_hat": kh, "q_hat": qh, "g": g,
            "g_names": list(lay.g_names), "g_undetermined": und}


@lru_cache(maxsize=64)
def _joint_function(system: System, joints: tuple[str, ...]) -> tuple[list, Any]:
    """Compiled M, k, q and, per joint, ``Eᵀ·W0``, ``Eᵀ·W_y`` and ``EᵀE`` (E: its constrained
    directions), so that ``EᵀE·g_j = Eᵀ·(W0 + W_y·ÿ)``."""
    from ..numeric import lambdify

    eom = projection(newton_euler(kinematics(system)))
    ne = eom.newton_euler
    by_joint = {b.joint.name: b for b in system.bodies}
    params = system.parameter_values
    mats: dict[str, SymMatrix] = {"M": eom.M, "k": eom.k, "q": eom.q}
    info = []
    for k, name in enumerate(joints):
        body = by_joint[name]
        dirs = constrained_directions(body.joint, system.coordinates, params)
        info.append((name, [sfx for sfx, _ in dirs]))
        if not dirs:
            continue
        W0, Wy = _subtree_parts(ne, body.name)

        def dot(w: Wrench, v: Wrench) -> se.Basic:
            return se.Add(*(x * y for x, y in zip(w, v, strict=True) if x != 0 and y != 0))

        mats[f"G0_{k}"] = SymMatrix.column([dot(w, W0) for _, w in dirs])
        mats[f"Gy_{k}"] = SymMatrix.from_rows([[dot(w, Wj) for Wj in Wy] for _, w in dirs])
        mats[f"EE_{k}"] = SymMatrix.from_rows([[dot(w, v) for _, v in dirs] for _, w in dirs])
    return info, lambdify(system, mats)


def joint_reactions(system: System, joints: str | Sequence[str], y: Any, yd: Any,
                    t: float = 0.0, parameters: Mapping[str, float] | None = None,
                    inputs: Mapping[str, float] | Sequence[float] | None = None
                    ) -> dict[str, float]:
    """Reaction components of the named joints only, without forming ``N̂`` or all of ``g``.

    ÿ comes from the equations of motion; the residual ``M̄·J̄·ÿ + q̄^c − q̄^e`` of the sub-tree
    each joint carries, moved to the joint point and the child frame, is the wrench ``W`` the
    joint transmits, and ``EᵀE·g_j = Eᵀ·W`` gives its components along the joint's constrained
    directions ``E``. Compiled once per system and set of joints (``M, k, q`` and, per joint,
    ``Eᵀ·W`` split into its part without ÿ and its coefficients of ÿ).

    Returns ``{"<joint>.<direction>": value}``; directions that others of the same joint repeat
    share their force and come back as NaN (undetermined).
    """
    from ..numeric import state_vectors

    if isinstance(joints, str):
        joints = [joints]
    by_joint = {b.joint.name: b for b in system.bodies}
    for name in joints:
        if name not in by_joint:
            raise ModelError(f'unknown joint "{name}"; joints are: {", ".join(by_joint)}')
    args = state_vectors(system, y, yd, t, parameters, inputs)
    info, fn = _joint_function(system, tuple(joints))
    out_ = fn(*args)
    try:
        ydd = np.linalg.solve(np.atleast_2d(out_["M"]), (out_["q"] - out_["k"]).reshape(-1))
    except np.linalg.LinAlgError:
        from ..errors import SingularMassMatrix

        raise SingularMassMatrix("the mass matrix M is singular at this state") from None
    out: dict[str, float] = {}
    for k, (name, suffixes) in enumerate(info):
        if not suffixes:
            continue
        rhs = out_[f"G0_{k}"].reshape(-1) + out_[f"Gy_{k}"] @ ydd
        EE = out_[f"EE_{k}"]
        gj, *_ = np.linalg.lstsq(EE, rhs, rcond=None)
        # directions that the others repeat (a rank-deficient Gram matrix) share their force
        _, sv, Vt = np.linalg.svd(EE)
        null = Vt[int((sv > 1e-10 * sv[0]).sum()):]
        if null.size:
            gj[np.abs(null).max(axis=0) > 1e-8] = np.nan
        for sfx, v in zip(suffixes, gj, strict=True):
            out[f"{name}.{sfx}"] = float(v)
    return out


def evaluate_keys(system: System, y: Any, yd: Any, t: float, parameters: Any, inputs: Any,
                  eom: Mapping[str, np.ndarray]) -> dict[str, Any]:
    """The reaction entries of :meth:`System.evaluate`: ``Q_bar, N_hat, k_hat, q_hat, g,
    g_names, g_undetermined`` and ``joint_wrenches`` (``{joint: JointWrench}``: force and
    torque vectors in the joint frame and the inertial frame, :mod:`jourdain.wrenches`).

    A model whose reactions cannot be formed (a joint moved by another joint's coordinate, a
    symbolic joint axis, constrained directions that do work), or a state where they have no
    solution (a load on a body without inertia that nothing balances), still has equations of
    motion: then the only entry is ``reactions_error``, the message that
    :func:`evaluate_reactions` raises, so that no reaction numbers appear for it.
    """
    try:
        _reactions_function(system)
        out = evaluate_reactions(system, y, yd, t, parameters, inputs, eom=eom)
    except JourdainError as exc:
        return {"reactions_error": str(exc)}
    from ..wrenches import joint_wrenches

    out["joint_wrenches"] = joint_wrenches(system, out["g"], y, yd, t, parameters)
    return out


