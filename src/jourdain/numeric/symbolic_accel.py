"""The C source of the symbolic path's ``M, k, q`` with the integrator's ``jd_accel`` by LDLᵀ
(:func:`symbolic_source`), and that ``jd_accel`` for the recursions where the articulated-body
recursion does not apply (:func:`accel_source`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from .ccode import HEADER, argument_names, function_source
from .integrator_ldl import ldl_source  # the solve written out per f (H1)
from .recursive import LDL_SOLVE

if TYPE_CHECKING:
    from ..model.system import System
    from ..stages.projection import EquationsOfMotion

#: largest f for which the integrator's jd_accel is compiled (its work arrays live on the stack)
ACCEL_MAX_F = 128


def symbolic_source(system: System, eom: EquationsOfMotion
                    ) -> tuple[tuple[str, ...], tuple[tuple[int, int], ...], str]:
    """The names, shapes and C source of :func:`jourdain.numeric.compiled.symbolic_mkq`."""
    f = system.f
    cnames = argument_names(system.y, system.yd, system.t, system.parameter_symbols,
                            system.inputs)
    exprs = [*eom.M.entries(), *eom.k.entries(), *eom.q.entries()]
    body = function_source("jd_fn", exprs, cnames, whole=True, symmetric=f)
    source = HEADER + body + "#define JD_FN_M jd_fn_upper\n" + accel_source(f)
    return ("M", "k", "q"), ((f, f), (f, 1), (f, 1)), source


def accel_source(f: int) -> str:
    """The integrator's ``jd_accel`` by LDLᵀ of M for ``f`` coordinates ("" above ACCEL_MAX_F:
    its work arrays live on the stack)."""
    # ldl_source: the solve written out for small f (integrator_ldl), else LDL_SOLVE's loop
    return (ldl_source(f) + ACCEL_TEMPLATE.replace("JD_F_VALUE", str(f))
            if f <= ACCEL_MAX_F else "")


# ÿ = M⁻¹(q − k) with the size known to the compiler, which unrolls the small loops and
# inlines jd_fn; returns 0, 1 (M not positive definite) or 2 (NaN or inf)
ACCEL_TEMPLATE = r"""
#ifndef JD_F
#define JD_F JD_F_VALUE
#endif
#ifndef JD_FN_M
#define JD_FN_M jd_fn
#endif
""" + LDL_SOLVE + r"""
int jd_accel(const double *y, const double *yd, double t, const double *p, const double *u,
             double *ydd, double *power) {
    double buf[JD_F * JD_F + 2 * JD_F], L[JD_F * JD_F];
    JD_FN_M(y, yd, t, p, u, buf);  /* M's upper triangle (and diagonal), k, q */
    const double *M = buf, *k = buf + JD_F * JD_F, *q = k + JD_F;
    double w = 0.0;
    for (int i = 0; i < JD_F; ++i) w += yd[i] * q[i];
    *power = w;
    return jd_solve_mkq(M, k, q, ydd, L);
}
"""
