/* sin and cos of n arguments at once (numeric/ccode.py: every sin/cos of a coordinate, parameter
 * or input of a generated function, all computed at its top in one call).
 *
 * Why not libm: glibc's sin and cos are called one argument at a time (12 sincos pairs: 105 ns
 * of the 215 ns of the 12-link pendulum's M, k, q); this loop has no call and no branch, so the
 * compiler runs it on two arguments at a time (SSE2, x86-64's baseline): 12 pairs in about
 * 60 ns; M, k, q of that pendulum 212 -> 172 ns. (Compiled for AVX2 as well, through
 * target_clones: M, k, q 20 ns faster, but not the solve that follows; not kept.)
 *
 * Method (fdlibm's, in its branch-free form): a = n·π/2 + r with π/2 split into three 33-bit
 * parts and a tail, so that every product n·part is exact for |n| < 2^20 and the sums are
 * error-free (TwoSum), giving r as an unevaluated sum y0 + y1 good to far below an ulp, also
 * next to multiples of π/2; then fdlibm's minimax polynomials on |r| ≤ π/4 (errors below one
 * ulp of the kernel) and the quadrant n mod 4. Measured against 200-bit mpmath over 8·10^4
 * arguments (random in ±4 and ±10^6, tiny, next to k·π/2): at most 0.76 ulp (glibc: 0.52);
 * tests/test_sincos.py holds it to < 1 ulp. |a| > JD_SINCOS_MAX, inf and NaN go to libm. */
#ifndef JD_SINCOS
#define JD_SINCOS
#define JD_SINCOS_MAX 1.0e6 /* |n| < 2^20 */
#if defined(__GNUC__) && !defined(__clang__) && !defined(JD_LEAN)
__attribute__((optimize("O3", "no-trapping-math"), unused)) /* vectorized: -O2 of GCC 12 does not,
   and it keeps float comparisons out of selects unless told they cannot trap. JD_LEAN (a
   function evaluated once per sample of a motion, numeric/compiled.py: lambdify's lean): not
   vectorized, 25 ms less to compile (of 75 for a small function); the same numbers */
#elif defined(__GNUC__)
__attribute__((unused))
#endif
static void jd_sincos_n(const double *x, int n, double *s, double *c) {
    for (int i = 0; i < n; ++i) {
        /* a value outside the range is replaced by 0 here and by libm's result below */
        const double a = fabs(x[i]) <= JD_SINCOS_MAX ? x[i] : 0.0;
        const double fn = (a * 6.36619772367581382433e-01 + 6755399441055744.0)
                          - 6755399441055744.0;  /* nearest integer to a·2/π */
        const double r1 = a - fn * 1.57079632673412561417e+00;  /* exact (Sterbenz) */
        const double w2 = fn * 6.07710050630396597660e-11;
        const double r2 = r1 - w2, b2 = r2 - r1;
        const double e2 = (r1 - (r2 - b2)) - (w2 + b2);
        const double w3 = fn * 2.02226624871116645580e-21;
        const double r3 = r2 - w3, b3 = r3 - r2;
        const double e3 = (r2 - (r3 - b3)) - (w3 + b3);
        const double tail = (e2 + e3) - fn * 8.47842766036889956997e-32;
        const double y0 = r3 + tail, y1 = (r3 - y0) + tail;
        const double z = y0 * y0, w = z * z, v = z * y0;
        const double ps = 8.33333333332248946124e-03
                          + z * (-1.98412698298579493134e-04 + z * 2.75573137070700676789e-06)
                          + z * w * (-2.50507602534068634195e-08 + z * 1.58969099521155010221e-10);
        double sn = y0 - ((z * (0.5 * y1 - v * ps) - y1) + v * 1.66666666666666324348e-01);
        const double pc = z * (4.16666666666666019037e-02 + z * (-1.38888888888741095749e-03
                                                                + z * 2.48015872894767294178e-05))
                          + w * w * (-2.75573143513906633035e-07
                                     + z * (2.08757232129817482790e-09
                                            + z * -1.13596475577881948265e-11));
        const double hz = 0.5 * z, w1 = 1.0 - hz;
        const double cs = w1 + (((1.0 - w1) - hz) + (z * pc - y0 * y1));
        sn = fabs(a) < 7.450580596923828125e-9 ? a : sn;  /* keeps the sign of −0 */
        const int q = (int)fn;
        const double s1 = (q & 1) ? cs : sn, c1 = (q & 1) ? sn : cs;
        s[i] = (q & 2) ? -s1 : s1;
        c[i] = ((q + 1) & 2) ? -c1 : c1;
    }
    for (int i = 0; i < n; ++i)
        if (!(fabs(x[i]) <= JD_SINCOS_MAX)) { s[i] = sin(x[i]); c[i] = cos(x[i]); }
}
#endif
