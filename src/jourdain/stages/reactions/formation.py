"""Formation of the reaction matrices (``docs/method.md`` §4): Q̄ (6p×q) from the joints'
directions, and ``N̂ = Q̄ᵀM̄⁻¹Q̄``, ``k̂ = Q̄ᵀM̄⁻¹q̄^c``, ``q̂ = Q̄ᵀM̄⁻¹q̄^e`` over the rows of M̄ with
inertia (:func:`reactions`, giving :class:`Reactions`), after the joint-by-joint check of
``J̄ᵀ·Q̄ = 0``; :func:`jourdain.analysis.reactions.check_orthogonality` checks the assembled
matrices.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import symengine as se

from ...errors import JourdainError, ModelError
from ...model.bodies import WORLD
from ...model.joints import Vec3
from ...symbolic import SymMatrix
from ..kinematics import _add, _cross, _mat, _mtv, _mv, _scale
from ..newton_euler import NewtonEuler, joint_transform
from ..planar import planar_moments

if TYPE_CHECKING:
    from ...model.system import System
from .checks import _checked_joints
from .joints import ZERO, JointReactions, joint_directions
from .rows import _body_rows, _singular_rows
from .subtree import _project, _subtree_wrench


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
    planar_moments : tuple of str
        The components of g that are moments across the plane at the joint of a body with a
        planar inertia (:func:`jourdain.model.bodies.planar_inertia`): not physical, they are
        those of a body without products of inertia about its axis, which the model does not
        know (:mod:`jourdain.stages.planar`).
    orthogonality : tuple of (joint name, "symbolic" | "numeric")
        How ``J̄ᵀ·Q̄ = 0`` was verified for each joint's directions (:func:`check_joints`); the
        assembled matrices are checked by
        :func:`jourdain.analysis.reactions.check_orthogonality` before numbers are made;
        numbers: :func:`jourdain.analysis.reactions.evaluate_reactions`.
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
    planar_moments: tuple[str, ...] = ()

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
        from ...symbolic import to_sympy

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
        S = _mat(bk.S)
        R_pc, o_pc = joint_transform(j)
        c_c = body.com
        i = row[body.name]
        parent = None if body.parent == WORLD else system.body(body.parent)
        for w in jr.wrenches:
            F: Vec3 = (w[0], w[1], w[2])
            T: Vec3 = (w[3], w[4], w[5])
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
    N: list[list[list[se.Basic]]] = [[[] for _ in range(q)] for _ in range(q)]
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
        planar_moments=planar_moments(system, tuple(joints), names),
    )
