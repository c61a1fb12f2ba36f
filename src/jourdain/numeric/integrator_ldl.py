"""The solve ``ÿ = M⁻¹(q − k)`` of the integrator's right-hand side, written out for one size.

:func:`ldl_source` gives C for ``jd_solve_mkq`` (the routine that the generated ``jd_accel``
calls, see :mod:`jourdain.numeric`) as straight-line code for a given ``f``: the right-looking
(outer-product) form of the LDLᵀ factorization (Golub & Van Loan, *Matrix Computations*, 4th
ed., §4.1.2), the forward substitution fused into the elimination of each column, and the back
substitution, every entry of ``M`` a named local.

Why right-looking and written out: the left-looking loop (every entry of column ``j`` as a dot
product over the columns before it) is bound by latency, each column waiting for a chain of
``j`` dependent multiply-adds before its pivot and again before its entries; in the
right-looking form the chain from one pivot to the next is one division, one multiplication
and one multiply-add, and the rest of the updates are independent of each other, which the
compiler schedules freely once the loops and their bounds are gone. Beyond about f = 11 the
written-out code is slower than the loop although it executes half the instructions (valgrind,
f = 13: 2 500 against 5 400 per solve; a left-looking form written out is slower still),
probably because that much straight-line code no longer fits beside M, k, q in the instruction
caches. Measured end to end (``benchmarks/simulation.py``'s run of the n-link pendulum on a cart,
10 s at rtol = atol = 5e-8, the same right-hand-side evaluations, best of 30 rounds, both forms in
one process, 2-core AMD EPYC, gcc 12 -O2): n = 2 (f = 3) 0.34 → 0.30 ms, n = 4 (f = 5)
0.63 → 0.50 ms, n = 8 (f = 9) 1.40 → 1.29 ms, n = 10 (f = 11) 1.97 → 1.94 ms, but n = 12
(f = 13) 2.79 → 3.13 ms. Hence :data:`WRITTEN_OUT_MAX_F`; above it the loop of
:mod:`jourdain.numeric` applies.

The order of the operations is fixed by the text, so the results are reproducible; they differ
from the loop's in the last bits (another rounding order: final states of the runs above agree
to 1e-13).
"""

from __future__ import annotations

#: largest f for which the solve is written out (faster up to about f = 11, slower at 13)
WRITTEN_OUT_MAX_F = 10


def ldl_source(f: int) -> str:
    """C of ``static int jd_solve_mkq(M, k, q, ydd, L)`` for ``f`` coordinates (row-major ``M``,
    ``L`` unused work space kept for the loop's signature): 0, 1 (``M`` not positive definite:
    a pivot at or below 1e-13 times the largest diagonal entry) or 2 (NaN or inf). Empty above
    :data:`WRITTEN_OUT_MAX_F` (the loop of :mod:`jourdain.numeric` applies)."""
    if not 1 <= f <= WRITTEN_OUT_MAX_F:
        return ""
    out = ["#ifndef JD_SOLVE_MKQ", "#define JD_SOLVE_MKQ",
           "/* ÿ = M⁻¹(q − k) by right-looking LDLᵀ, written out for f = " + str(f) + " */",
           "static int jd_solve_mkq(const double *M, const double *k, const double *q, "
           "double *ydd, double *L) {",
           "    (void)L;",
           "    double dmax = 0.0;"]
    # a{i}_{j}, i >= j: the lower triangle of M, read from the upper one (M_ij = M_ji: the
    # generated jd_fn_upper leaves the lower one unwritten), overwritten by d_j·l_ij during
    # the elimination
    for i in range(f):
        out.append("    double " + ", ".join(f"a{i}_{j} = M[{j * f + i}]" for j in range(i + 1))
                   + ";")
    for i in range(f):  # written as a comparison: fmax is a library call at -O2
        out.append(f"    {{ double t_ = fabs(a{i}_{i}); dmax = t_ > dmax ? t_ : dmax; }}")
    out.append("    double " + ", ".join(f"b{i} = q[{i}] - k[{i}]" for i in range(f)) + ";")
    out.append("    const double tiny = 1e-13 * dmax;")
    for j in range(f):
        out.append(f"    if (!(a{j}_{j} > tiny)) return isfinite(a{j}_{j}) ? 1 : 2;")
        out.append(f"    const double r{j} = 1.0 / a{j}_{j};")
        for m in range(j + 1, f):
            out.append(f"    const double l{m}_{j} = a{m}_{j} * r{j};")
        for m in range(j + 1, f):
            out.append("    " + " ".join(f"a{i}_{m} -= a{i}_{j} * l{m}_{j};"
                                         for i in range(m, f)))
        for i in range(j + 1, f):  # forward substitution L z = b, column j
            out.append(f"    b{i} -= l{i}_{j} * b{j};")
    for i in range(f - 1, -1, -1):  # back substitution D Lᵀ ÿ = z
        # the terms of the unknowns found last come last: x_i waits one multiply-add for
        # x_{i+1}, not the whole sum
        terms = "".join(f" - l{m}_{i} * x{m}" for m in range(f - 1, i, -1))
        out.append(f"    const double x{i} = b{i} * r{i}{terms};")
        out.append(f"    ydd[{i}] = x{i};")
    out.append("    return " + " && ".join(f"isfinite(x{i})" for i in range(f)) + " ? 0 : 2;")
    out += ["}", "#endif", ""]
    return "\n".join(out)
