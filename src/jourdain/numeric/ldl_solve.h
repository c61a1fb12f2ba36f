
#ifndef JD_SOLVE_MKQ
#define JD_SOLVE_MKQ
/* ÿ = M⁻¹(q − k) by LDLᵀ of the projected M, read from its diagonal and upper triangle
   (the generated jd_fn_upper leaves the lower one unwritten); 0, 1 (M not positive
   definite) or 2 (NaN) */
#if defined(__GNUC__) && !defined(__clang__)
/* GCC: its short inner loops unrolled (-O2 does not): 15 % less time per solve at f = 13, the
   operations and their order unchanged (no reassociation), so the results are too */
__attribute__((optimize("unroll-loops")))
#endif
/* JD_SOLVE_N_PARAM: empty for the generated code (JD_F a constant); the interpreter
   (interpreter.h) defines it as a size parameter and JD_F as that parameter */
#ifndef JD_SOLVE_N_PARAM
#define JD_SOLVE_N_PARAM
#endif
static int jd_solve_mkq(JD_SOLVE_N_PARAM const double *M, const double *k, const double *q,
                        double *ydd, double *L /* f×f work */) {
    double D[JD_F], Dinv[JD_F], E[JD_F], dmax = 0.0;
    for (int i = 0; i < JD_F; ++i) { ydd[i] = q[i] - k[i]; dmax = fmax(dmax, fabs(M[i * JD_F + i])); }
    for (int j = 0; j < JD_F; ++j) {
        double d = M[j * JD_F + j];
        for (int m = 0; m < j; ++m) { E[m] = L[j * JD_F + m] * D[m]; d -= L[j * JD_F + m] * E[m]; }
        if (!(d > 1e-13 * dmax)) return isfinite(d) ? 1 : 2;
        D[j] = d; Dinv[j] = 1.0 / d;
        for (int i = j + 1; i < JD_F; ++i) {
            double s = M[j * JD_F + i];  /* the upper triangle: M_ji = M_ij */
            for (int m = 0; m < j; ++m) s -= L[i * JD_F + m] * E[m];
            L[i * JD_F + j] = s * Dinv[j];
        }
    }
    for (int i = 0; i < JD_F; ++i) {
        double s = ydd[i];
        for (int m = 0; m < i; ++m) s -= L[i * JD_F + m] * ydd[m];
        ydd[i] = s;
    }
    for (int i = JD_F - 1; i >= 0; --i) {
        double s = ydd[i] * Dinv[i];
        /* H1: unknowns found last come last, so ydd[i] waits one multiply-add for ydd[i+1]
           (not the whole sum): 3-5 % less time per right-hand side at f = 13 */
        for (int m = JD_F - 1; m > i; --m) s -= L[m * JD_F + i] * ydd[m];
        ydd[i] = s;
    }
    for (int i = 0; i < JD_F; ++i) if (!isfinite(ydd[i])) return 2;
    return 0;
}
#endif
