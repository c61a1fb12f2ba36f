"""The kinematic recursion of :mod:`jourdain.numeric.recursive` in planar vectors, for systems
whose bodies all turn about one axis of the inertial frame and move parallel to the plane
normal to it (z first: the x-y plane; else the y-z or z-x plane, its axes taken in cyclic
order, so that the engine's "x", "y", "z" stay a right-handed frame).

Such a system's twists have three components (ω_z, u_x, u_y) and its spatial inertias four
numbers (J, m·c_x, m·c_y, m) about the origin: the components across the plane are carried by
the joints and enter neither M, k, q nor ÿ (a planar Jacobian column has none, so J̄ᵀ drops
them exactly; the gyroscopic moment ω × I·ω of a rotation about z lies in the plane). The
engine (``planar_engine.h``) is therefore the spatial one with 3- instead of 6-vectors and
3×3 instead of 6×6 articulated inertias: the 32-link planar pendulum's ÿ by articulated bodies
costs a quarter of the spatial recursion's (``benchmarks/paths.py``). Its numbers agree with
the spatial engine's to rounding; they are not bit-identical to it (other sums).

Planar is decided structurally on the joints' local expressions
(:func:`jourdain.stages.kinematics.joint_motions`): every relative rotation ``A`` has the form
``[[c, −s, 0], [s, c, 0], [0, 0, 1]]`` (for the x-y plane) with literal zeros and one, and every
Jacobian column, rheonomic velocity and acceleration lies in the plane (ω̄, ᾱ, J_R about the
normal; v̄, ā, J_T in the plane), each a literal zero across it. A system whose expressions only simplify to that is not taken
for planar and gets the spatial engine: never a wrong number, at worst a slower one. Applied
forces across the plane and moments about in-plane axes are carried by the joints (they do no
work on any planar motion) and are left out, as the spatial engine's projection leaves them.

Floor: numeric (it reads the stages' joint motions, as :mod:`jourdain.numeric.recursive` does).
"""

from __future__ import annotations

from functools import lru_cache
from importlib import resources
from typing import TYPE_CHECKING

import symengine as se

from ..stages.kinematics import JointMotion, joint_motions
from .ccode import HEADER, argument_names, batch_source, function_source
from .recursive import _disjoint, c_table, column_tables, layout

if TYPE_CHECKING:
    from ..model.system import System

#: numbers per body in the local array (see planar_engine.h) and per Jacobian column
PLANE_BODY = 17
PLANE_COLUMN = 3
#: bodies above which the planar engine is not used (a bound on its generated tables)
PLANE_MAX_BODIES = 1024


def _zero(x: se.Basic) -> bool:
    return x == 0


#: per normal axis k, the in-plane axes (a, b) with (a, b, k) right-handed: the plane's "x" and
#: "y" of the engine (a cyclic permutation of the axes keeps rotations rotations)
PLANES = {2: (0, 1), 0: (1, 2), 1: (2, 0)}


@lru_cache(maxsize=32)
def plane_normal(system: System) -> int | None:
    """The axis (0, 1, 2 for x, y, z) about which every joint of ``system`` turns its child and
    across which none moves it, by literal zeros and one in the joints' local expressions
    (see the module docstring), or None; z is tried first. Bodies' forces need not be planar
    (those across the plane are carried by the joints). Memoized per system: the cost model
    and the planar engine's source both ask."""
    if not system.bodies or len(system.bodies) > PLANE_MAX_BODIES:
        return None
    motions = joint_motions(system)
    for k, (a, b) in PLANES.items():
        if all(_keeps_plane(jm, k, a, b) for jm in motions):
            return k
    return None


def _keeps_plane(jm: JointMotion, k: int, a: int, b: int) -> bool:
    A = jm.A
    return (all(_zero(A[i][k]) and _zero(A[k][i]) for i in (a, b)) and A[k][k] == 1
            and all(_zero(x) for x in (jm.omega_bar[a], jm.omega_bar[b], jm.alpha_bar[a],
                                        jm.alpha_bar[b], jm.v_bar[k], jm.a_bar[k]))
            and all(_zero(v[a]) and _zero(v[b]) for v in jm.J_R.values())
            and all(_zero(v[k]) for v in jm.J_T.values()))


def is_planar(system: System) -> bool:
    """Every body of ``system`` moves in planes normal to one coordinate axis of the inertial
    frame, turning about it (:func:`plane_normal`)."""
    return plane_normal(system) is not None


def planar_units(system: System, accel_template: str) -> tuple[str, str, bool]:
    """The generated per-joint code and the planar engine (two translation units compiled in
    parallel), and whether the articulated-body recursion applies (every coordinate in one
    joint); where it does not, ``accel_template`` (``jd_accel`` by LDLᵀ of ``jd_fn``'s M) is
    appended to the engine. ``jd_fn`` gives ``[M (f×f), k, q]``."""
    k = plane_normal(system)
    if k is None:
        raise ValueError(f"{system.name}: not a planar system (jourdain.numeric.planar_recursion)")
    a, b = PLANES[k]
    lay = layout(system)  # the spatial layout, whose blocks hold the planar numbers
    p, f = len(lay.parent), system.f
    nb = 40  # recursive.BODY_BLOCK: A 9, d 3, ω̄ 3, v̄ 3, ᾱ 3, ā 3, m, com 3, I 6, f 3, l 3
    inertia = {0: 28, 1: 31, 2: 33}  # I_xx, I_yy, I_zz in (xx, xy, xz, yy, yz, zz)
    # A[a][a], A[b][a], d_ab, ω̄_k, v̄_ab, ᾱ_k, ā_ab, m, com_ab, I_kk, f_ab, l_k
    pick = (3 * a + a, 3 * b + a, 9 + a, 9 + b, 12 + k, 15 + a, 15 + b, 18 + k, 21 + a, 21 + b,
            24, 25 + a, 25 + b, inertia[k], 34 + a, 34 + b, 37 + k)
    exprs = [lay.exprs[nb * i + j] for i in range(p) for j in pick]
    n_cols = (len(lay.exprs) - nb * p) // 6  # a column: J_R (3) then J_T (3)
    for col in range(n_cols):
        exprs.extend(lay.exprs[nb * p + 6 * col + j] for j in (k, 3 + a, 3 + b))
    names = argument_names(system.y, system.yd, system.t, system.parameter_symbols,
                           system.inputs)
    local = function_source("jd_local", exprs, names)
    col_start, col_coord = column_tables(lay.columns)
    aba = _disjoint(lay.columns)
    head = (f"#define JD_P {p}\n#define JD_F {f}\n#define JD_NC {max(len(col_coord), 1)}\n"
            f"#define JD_NL {len(exprs)}\n#define JD_COLS {p * PLANE_BODY}\n"
            f"#define JD_ABA {1 if aba else 0}\n"
            # the work on the stack when small (64 kB, as the spatial engine's)
            f"#define JD_PLANE_STACK {1 if 8 * (51 * p + 7 * len(col_coord)) <= 65536 else 0}\n"
            + c_table("jd_parent", list(lay.parent))
            + c_table("jd_col_start", col_start)
            + c_table("jd_col_coord", col_coord))
    decl = ("void jd_local(const double *y, const double *yd, double t, const double *p,\n"
            "              const double *u, double *out);\n")
    engine = (head + ENGINE + batch_source("jd_fn", "(JD_F * JD_F + 2 * JD_F)")
              + ("" if aba else accel_template))
    return HEADER + local, HEADER + decl + engine, aba


#: the C text is ``planar_engine.h`` beside this module
ENGINE = resources.files(__package__ or "jourdain.numeric").joinpath("planar_engine.h").read_text(
    encoding="utf-8")
