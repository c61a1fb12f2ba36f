"""The kinematic recursion of :mod:`jourdain.numeric.recursive` in planar vectors, for systems
whose bodies all turn about the inertial z axis and move parallel to the x-y plane.

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
``[[c, −s, 0], [s, c, 0], [0, 0, 1]]`` with literal zeros and one, and every Jacobian column,
rheonomic velocity and acceleration lies in the plane (ω̄, ᾱ, J_R about z; v̄, ā, J_T in x-y),
each a literal zero across it. A system whose expressions only simplify to that is not taken
for planar and gets the spatial engine: never a wrong number, at worst a slower one. Applied
forces across the plane and moments about in-plane axes are carried by the joints (they do no
work on any planar motion) and are left out, as the spatial engine's projection leaves them.

Floor: numeric (it reads the stages' joint motions, as :mod:`jourdain.numeric.recursive` does).
"""

from __future__ import annotations

from importlib import resources
from typing import TYPE_CHECKING

import symengine as se

from ..stages.kinematics import joint_motions
from .ccode import HEADER, argument_names, function_source
from .recursive import _disjoint, c_table, layout

if TYPE_CHECKING:
    from ..model.system import System

#: numbers per body in the local array (see planar_engine.h) and per Jacobian column
PLANE_BODY = 17
PLANE_COLUMN = 3
#: bodies above which the planar engine's work (on the stack) is not used
PLANE_MAX_BODIES = 256


def _zero(x: se.Basic) -> bool:
    return x == 0


def is_planar(system: System) -> bool:
    """Every joint of ``system`` keeps its child in the x-y plane of its parent, turning about
    z, by literal zeros and one in its local expressions (see the module docstring); bodies'
    forces need not be planar (those across the plane are carried by the joints)."""
    if not system.bodies or len(system.bodies) > PLANE_MAX_BODIES:
        return False
    for jm in joint_motions(system):
        A = jm.A
        if not (all(_zero(A[r][2]) and _zero(A[2][r]) for r in (0, 1)) and A[2][2] == 1):
            return False
        if not all(_zero(x) for x in (*jm.omega_bar[:2], *jm.alpha_bar[:2], jm.v_bar[2],
                                      jm.a_bar[2])):
            return False
        if not all(_zero(v[0]) and _zero(v[1]) for v in jm.J_R.values()):
            return False
        if not all(_zero(v[2]) for v in jm.J_T.values()):
            return False
    return True


def planar_units(system: System, accel_template: str) -> tuple[str, str, bool]:
    """The generated per-joint code and the planar engine (two translation units compiled in
    parallel), and whether the articulated-body recursion applies (every coordinate in one
    joint); where it does not, ``accel_template`` (``jd_accel`` by LDLᵀ of ``jd_fn``'s M) is
    appended to the engine. ``jd_fn`` gives ``[M (f×f), k, q]``."""
    lay = layout(system)  # the spatial layout, whose blocks hold the planar numbers
    p, f = len(lay.parent), system.f
    nb = 40  # recursive.BODY_BLOCK: A 9, d 3, ω̄ 3, v̄ 3, ᾱ 3, ā 3, m, com 3, I 6, f 3, l 3
    # A[0][0], A[1][0], d_xy, ω̄_z, v̄_xy, ᾱ_z, ā_xy, m, com_xy, I_zz, f_xy, l_z
    pick = (0, 3, 9, 10, 14, 15, 16, 20, 21, 22, 24, 25, 26, 33, 34, 35, 39)
    exprs = [lay.exprs[nb * i + k] for i in range(p) for k in pick]
    for k in range(len(lay.exprs) - nb * p):
        if k % 6 in (2, 3, 4):  # a column: J_R (3) then J_T (3); keep J_R,z and J_T,xy
            exprs.append(lay.exprs[nb * p + k])
    names = argument_names(system.y, system.yd, system.t, system.parameter_symbols,
                           system.inputs)
    local = function_source("jd_local", exprs, names)
    col_start = [0]
    col_coord: list[int] = []
    for c in lay.columns:
        col_coord.extend(c)
        col_start.append(col_start[-1] + len(c))
    aba = _disjoint(lay.columns)
    head = (f"#define JD_P {p}\n#define JD_F {f}\n#define JD_NC {max(len(col_coord), 1)}\n"
            f"#define JD_NL {len(exprs)}\n#define JD_COLS {p * PLANE_BODY}\n"
            f"#define JD_ABA {1 if aba else 0}\n"
            + c_table("jd_parent", list(lay.parent))
            + c_table("jd_col_start", col_start)
            + c_table("jd_col_coord", col_coord))
    decl = ("void jd_local(const double *y, const double *yd, double t, const double *p,\n"
            "              const double *u, double *out);\n")
    engine = head + ENGINE + ("" if aba else accel_template)
    return HEADER + local, HEADER + decl + engine, aba


#: the C text is ``planar_engine.h`` beside this module
ENGINE = resources.files(__package__ or "jourdain.numeric").joinpath("planar_engine.h").read_text(
    encoding="utf-8")
