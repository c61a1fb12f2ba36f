"""Compiled evaluation that follows the kinematic recursion body by body (METHOD.md §1–§3).

The symbolic stages give every entry of M = J̄ᵀM̄J̄ as an expression; for a chain of p bodies
with f coordinates those expressions hold O(f³) operations, and compiling them took minutes at
f = 63. Here the same products are formed numerically in the order of the tree, in generated C
whose size grows with the number of bodies, not with f²:

1. **Per joint, symbolic and short** (:func:`jourdain.stages.kinematics.joint_motions`): the relative
   rotation ``A`` and position ``d`` of the child frame, the relative Jacobian columns
   ``J_T``, ``J_R``, and the rheonomic and ÿ-free relative velocities and accelerations; per
   body its mass data and the resultant applied force ``f`` (inertial) and torque ``l`` (body
   frame) of :func:`jourdain.stages.newton_euler.applied_forces`. These are compiled as one function
   of (y, ẏ, t, p, u) with the graph CSE of :mod:`jourdain.numeric.ccode`.
2. **Forward pass** (generic C, parents first): S_i = S_λ·A_i, the origin r_O,i = r_O,λ + S_λ·d_i,
   ω_i, v_i, and the local accelerations ᾱ_i, ā_i (METHOD.md §1) composed from the parent's;
   every Jacobian column of the joint as a spatial twist at the inertial origin,
   ``V = (w, u)`` with ``w = S_i·J_R,j`` and ``u = S_λ·J_T,j + r_O,i × w`` — a column keeps this
   form unchanged in every body below the joint, which is what makes the sums below short.
3. **Composite bodies** (backward pass): the spatial inertia of each body about the inertial
   origin (inertial components) and the wrenches of q̄^c and q̄^e of each body about the origin
   are summed over each sub-tree (plain sums: all in one frame about one point).
4. **Projection**: with I^c_b the composite inertia of the sub-tree of body b,

       M_jk = Σ_b Σ_(a ancestor-or-self of b) V_a,jᵀ · I^c_b · V_b,k   (and its transpose)
       k_j  = Σ_a V_a,jᵀ · (Σ_(i below a) q̄^c_i as a wrench),   q_j likewise with q̄^e_i,

   which is J̄ᵀM̄J̄, J̄ᵀq̄^c and J̄ᵀq̄^e with the body sums gathered first (associativity only).
   A coordinate that enters several joints (absolute angles of a chain) has a column in each;
   the double sum over joint pairs covers it exactly.

The cost per state is O(Σ_b columns·depth), like Pinocchio's CRBA, and the generated source is a
few hundred bytes per body plus a fixed engine. The symbolic equations stay what
:func:`jourdain.stages.projection.projection` gives, for display and export; tests compare both, and
both with Pinocchio.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from typing import TYPE_CHECKING

import symengine as se

from ..model.forces import Gravity
from ..stages.kinematics import joint_motions, kinematics
from ..stages.newton_euler import applied_forces
from .ccode import HEADER, argument_names, batch_source, function_source

if TYPE_CHECKING:
    from ..model.system import System

#: numbers per body in the local array: A 9, d 3, ω̄ 3, v̄ 3, ᾱ 3, ā 3, m 1, com 3, I 6, f 3, l 3
BODY_BLOCK = 40
#: numbers per Jacobian column: J_R 3 (child frame), J_T 3 (parent frame)
COLUMN_BLOCK = 6


@dataclass(frozen=True)
class RecursiveLayout:
    """Tables of the generated code: ``parent[i]`` (-1: world), the columns of each body's joint
    ``columns[i]`` (coordinate indices), and the local expressions in array order."""

    parent: tuple[int, ...]
    columns: tuple[tuple[int, ...], ...]
    exprs: tuple[se.Basic, ...]
    #: number of constrained directions of each joint (their wrenches follow the columns)
    directions: tuple[int, ...] = ()


@lru_cache(maxsize=32)
def layout(system: System, directions: tuple | None = None) -> RecursiveLayout:
    """The local expressions of every joint and body, in the order of the C arrays;
    ``directions``: per body the unit wrenches of its joint's constrained directions
    (:func:`jourdain.stages.reactions.joint_directions`), for Q̄."""
    motions = joint_motions(system)
    index = {b.name: i for i, b in enumerate(system.bodies)}
    # the symbolic kinematics of every body is needed only for loads that depend on it
    forces = None
    gravities = [fe for fe in system.forces if isinstance(fe, Gravity)]
    if len(gravities) < len(system.forces):
        forces = [(bf.f, bf.l) for bf in applied_forces(kinematics(system))]
    elif gravities:
        g = [se.Add(*(fe.vector[a] for fe in gravities)) for a in range(3)]
        forces = [(tuple(b.mass * x for x in g), (se.Integer(0),) * 3) for b in system.bodies]
    zero = se.Integer(0)
    exprs: list[se.Basic] = []
    cols: list[tuple[int, ...]] = []
    col_exprs: list[se.Basic] = []
    for i, (body, jm) in enumerate(zip(system.bodies, motions, strict=True)):
        exprs.extend(x for row in jm.A for x in row)
        exprs.extend((*jm.d, *jm.omega_bar, *jm.v_bar, *jm.alpha_bar, *jm.a_bar))
        I = body.inertia
        exprs.extend((body.mass, *body.com, I[0][0], I[0][1], I[0][2], I[1][1], I[1][2],
                      I[2][2]))
        if forces is None:
            exprs.extend((zero,) * 6)
        else:
            exprs.extend((*forces[i][0], *forces[i][1]))
        js = tuple(sorted(set(jm.J_T) | set(jm.J_R)))
        z3 = (zero, zero, zero)
        for j in js:
            col_exprs.extend((*jm.J_R.get(j, z3), *jm.J_T.get(j, z3)))
        cols.append(js)
    parent = tuple(-1 if b.parent == "world" else index[b.parent] for b in system.bodies)
    dir_exprs = [x for ws in (directions or ()) for w in ws for x in w]
    return RecursiveLayout(parent, tuple(cols), tuple(exprs + col_exprs + dir_exprs),
                           tuple(len(ws) for ws in directions) if directions else ())


def _disjoint(columns: tuple[tuple[int, ...], ...]) -> bool:
    """Every coordinate belongs to one joint (the articulated-body recursion applies)."""
    flat = [j for c in columns for j in c]
    return len(flat) == len(set(flat))


def column_tables(columns: tuple[tuple[int, ...], ...]) -> tuple[list[int], list[int]]:
    """The engines' column tables: where each body's columns start (one more entry than
    bodies), and each column's coordinate."""
    start = [0]
    coord: list[int] = []
    for c in columns:
        coord.extend(c)
        start.append(start[-1] + len(c))
    return start, coord


def c_table(name: str, values: list[int], ctype: str = "int") -> str:
    """A static C array of integers (one 0 where there are none: C has no empty arrays)."""
    body = ", ".join(str(v) for v in values) if values else "0"
    return f"static const {ctype} {name}[{max(len(values), 1)}] = {{{body}}};\n"


def recursive_units(system: System, full: bool = False, directions: tuple | None = None,
                    extra_source: str = "", accel_template: str | None = None
                    ) -> tuple[str, str]:
    """:func:`recursive_source` as two translation units, compiled in parallel: the generated
    per-joint code, and the engine with ``extra_source`` (which may call ``jd_fn``).

    ``accel_template``: the integrator's ``jd_accel`` by LDLᵀ of M, used where the
    articulated-body recursion does not apply; where it does, the engine's own ``jd_accel``
    (O(f) per evaluation) is compiled instead.
    """
    local, engine, aba = _parts(system, full, directions)
    decl = ("void jd_local(const double *y, const double *yd, double t, const double *p,\n"
            "              const double *u, double *out);\n")
    if accel_template is not None:
        if aba:
            engine = "#define JD_ACCEL_ABA 1\n" + engine
        else:
            extra_source = accel_template + extra_source
    return HEADER + local, HEADER + decl + engine + extra_source


def recursive_source(system: System, full: bool = False, directions: tuple | None = None
                     ) -> str:
    """C source of ``jd_fn(y, yd, t, p, u, out)`` with ``out = [M (f×f), k (f), q (f)]``, and
    with ``full`` ``out = [M_bar, J_bar, q_c, q_e, M, k, q]`` (the layout of
    :func:`jourdain.numeric.evaluate`), followed by ``Q_bar`` (6p×q) when ``directions`` (per
    body, the unit wrenches of its joint) are given; plus ``jd_fn_batch``."""
    local, engine, _ = _parts(system, full, directions)
    return local + "\n/* ---- engine ---- */\n" + engine


def _parts(system: System, full: bool, directions: tuple | None) -> tuple[str, str, bool]:
    """The generated per-joint code, the engine with its tables, and whether the
    articulated-body recursion applies (every coordinate belongs to one joint)."""
    lay = layout(system, directions)
    p = len(lay.parent)
    f = system.f
    names = argument_names(system.y, system.yd, system.t, system.parameter_symbols,
                           system.inputs)
    local = function_source("jd_local", list(lay.exprs), names)
    col_start, col_coord = column_tables(lay.columns)
    n_q = sum(lay.directions)
    aba = _disjoint(lay.columns)
    dir_start = [0]
    for nd in lay.directions:
        dir_start.append(dir_start[-1] + nd)
    size = ((36 * p * p + 6 * p * f + 12 * p if full else 0) + f * f + 2 * f
            + (6 * p * n_q if lay.directions else 0))
    head = (f"#define JD_P {p}\n#define JD_F {f}\n#define JD_NC {max(len(col_coord), 1)}\n"
            f"#define JD_NL {len(lay.exprs)}\n#define JD_BODY {BODY_BLOCK}\n"
            f"#define JD_COLS {p * BODY_BLOCK}\n"
            f"#define JD_DIRS {p * BODY_BLOCK + COLUMN_BLOCK * len(col_coord)}\n"
            f"#define JD_SIZE {size}\n#define JD_FULL {1 if full else 0}\n"
            f"#define JD_Q {n_q}\n#define JD_QBAR {1 if lay.directions else 0}\n"
            f"#define JD_ABA {1 if aba else 0}\n"
            # the work of the recursion on the stack when small (no malloc per evaluation)
            f"#define JD_WORK_STACK {1 if 8 * (58 * p + 6 * len(col_coord)) <= 65536 else 0}\n"
            + c_table("jd_parent", list(lay.parent))
            + c_table("jd_col_start", col_start)
            + c_table("jd_col_coord", col_coord)
            + c_table("jd_dir_start", dir_start if lay.directions else [0]))
    engine = ENGINE.replace("/* LDL_SOLVE */\n", LDL_SOLVE) + batch_source("jd_fn", "JD_SIZE")
    return local, head + engine, aba


#: ÿ = M⁻¹(q − k) by LDLᵀ for f = JD_F (the integrator's jd_accel of the symbolic code and the
#: recursion where the articulated-body recursion does not apply)
#: (the C text is ``ldl_solve.h`` beside this module)
LDL_SOLVE = resources.files(__package__ or "jourdain.numeric").joinpath("ldl_solve.h").read_text(
    encoding="utf-8")

# The engine: generic in the tables above. Spatial vectors about the inertial origin in inertial
# components: twists (w, u) with u the velocity of the body point at the origin, wrenches
# (moment about the origin, force); the power of a wrench on a twist is w·m + u·F.
# The C text is ``recursive_engine.h`` beside this module.
ENGINE = resources.files(__package__ or "jourdain.numeric").joinpath("recursive_engine.h").read_text(
    encoding="utf-8")
