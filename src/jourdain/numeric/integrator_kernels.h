/* jourdain's integrator library, the kernels: the loops over the state vector of every step
 * (stage sums, error norms, Radau's Newton iteration) and Radau's dense LU factorizations.
 * This file is a translation unit of its own, compiled at -O3 (its loops vectorized), and the
 * declarations in the other unit (the step loops, events, output), which is compiled at -O2
 * (numeric/integrator_c.py: UNITS). All of it as one unit at -O3 took 1.3-1.6 s to compile
 * on a 2-core AMD EPYC, most of it spent vectorizing loops that run once per run or per
 * event; the two units take 0.34 s and 0.30 s, in parallel. The time per run is the same
 * (n-link pendulum on a cart, n = 4 and 12, DOP853, RK45; Radau IIA within 1 %), and so are the
 * numbers, to the bit: no sum is reordered (no -ffast-math).
 *
 * The step loop's share (issue 35: at most 30 % of a right-hand side at n = 4). Measured
 * 2026-11-27 with perf on the 4-link pendulum on a cart (f = 5, n = 11, DOP853, 10 s, 8 894
 * right-hand sides): of the run's samples, the model's jd_accel 45 %, stage_sum 19 % (its sums
 * of four lanes in one register waiting on the latency of their chain of additions, the
 * n mod 4 others on one chain each), rhs() 5 % (most of it its NaN check, one chain of n
 * additions), inputs() 1.6 %, pow 1.5 %. Now: the stage sums in tiles of three groups of four
 * lanes in vectors (below), the state of each stage checked finite by stage_sum as it writes
 * it (rhs_at), constant inputs set once per run (inputs_fix): stage_sum 12 %, rhs 1.5 %,
 * inputs 0; one process alternating the old and the new library (best of 300 runs each):
 * 1.17-1.19 → 1.02-1.05 ms per run, 0.132-0.134 → 0.115-0.118 µs per right-hand side, against
 * jd_accel alone 0.077 µs: the loop 69-74 % → 48-53 % of a right-hand side, the target not
 * met. Tried and left out, no faster within the noise: stage_sum compiled for n = 11 (n known
 * to the compiler), and each stage's sum but its last term summed one stage ahead (while the
 * previous stage's right-hand side runs, the last term added once its K is known). What is
 * left is spread thin: jd_integrate 2 %, pow 1.8 %, memcpy 1.2 %, error_sums8 0.9 %, and
 * jd_accel itself about 6 % slower inside the loop than alone (perf's share). A second pass
 * (benchmarks/setup.py has its figures): jd_accel "alone" was timed on independent states,
 * whose calls the processor overlaps (0.077 µs each); each waiting on the last, as a stage
 * waits on the one before, it takes 0.100 µs, and the loop adds 0.01 µs to that (with a
 * right-hand side of no cost the loop takes 0.029 µs per right-hand side, mostly hidden
 * under jd_accel's latency). Tried and left out, slower: a stage sum's last term (the stage
 * just computed) added in scalars (0.115 → 0.122 µs); no faster within the noise: K_0
 * copied once per step instead of twice (x's and k0's copies are off the critical path). */
#include <math.h>
#include <string.h>
#if defined(__GNUC__)
#define JD_INTERNAL __attribute__((visibility("hidden")))  /* not exported by the library */
#else
#define JD_INTERNAL
#endif

/* a row of a method's table without its zeros: the q coefficients a[t] ≠ 0 of the stages
   j[t], in the order of j (row_of: from the first s entries of a full row) */
typedef struct { int q; int j[16]; double a[16]; } jd_row;
JD_INTERNAL void row_of(int s, const double *a, jd_row *r);
/* out = x + Σ_t (h·a[t])·K_j[t] over the row r (x NULL: 0 + ...); 1: every component of out
   finite, else 0 */
JD_INTERNAL int stage_sum(long n, const jd_row *r, double h, const double *x, const double *K,
                          double *out);
/* 1: every x_i finite, else 0 */
JD_INTERNAL int all_finite(long n, const double *x);
/* sqrt(Σ (v_i / sc_i)² / n) */
JD_INTERNAL double rms_scaled(long n, const double *v, const double *sc);
/* sc_i = atol_i + rtol·max(|x_i|, |x_new_i|) (both finite) */
JD_INTERNAL void error_scales(long n, const double *atol, double rtol, const double *x,
                              const double *x_new, double *sc);
/* DOP853's two error sums: *e5 = Σ (e5v_i / sc_i)², *e3 = Σ (e3v_i / sc_i)² */
JD_INTERNAL void error_sums8(long n, const double *e5v, const double *e3v, const double *sc,
                             double *e5, double *e3);
/* err_i = h·Σ_j e[j]·K_j,i over the s stages (RK45's error estimate) */
JD_INTERNAL void error_rk5(long n, int s, double h, const double *e, const double *K,
                           double *err);
/* out = a + b (out may be a) */
JD_INTERNAL void vector_sum(long n, const double *a, const double *b, double *out);
/* Radau IIA's change of basis of three vectors of n: out_k = Σ_j T[3k + j]·in_j */
JD_INTERNAL void radau_transform(long n, const double *T, const double *in, double *out);
/* the simplified Newton iteration's right-hand sides in the eigenbasis: fr (real) and
   dW[n..3n) (complex, real and imaginary parts) from the stage derivatives F and W */
JD_INTERNAL void radau_residual(long n, const double *TI, const double *F, const double *W,
                                double mr, double mcr, double mci, double *fr, double *dW);
/* Σ over the three vectors of (dW_q,i / sc_i)² */
JD_INTERNAL double radau_sum_squares(long n, const double *dW, const double *sc);
/* the iteration matrices LUr = mr·I − J and LCr + i·LCi = (mcr + i·mci)·I − J */
JD_INTERNAL void radau_matrices(long n, const double *J, double mr, double mcr, double mci,
                                double *LUr, double *LCr, double *LCi);
/* LU with partial pivoting in place (1: singular or not finite), and its solve */
JD_INTERNAL int lu_real(long n, double *A, long *piv);
JD_INTERNAL void lu_solve_real(long n, const double *A, const long *piv, double *b);
/* the same for a complex matrix held as its real and imaginary parts */
JD_INTERNAL int lu_cplx(long n, double *Ar, double *Ai, long *piv);
JD_INTERNAL void lu_solve_cplx(long n, const double *Ar, const double *Ai, const long *piv,
                               double *br, double *bi);

#ifdef JD_KERNELS  /* the definitions: in the kernels' unit only */
void row_of(int s, const double *a, jd_row *r) {
    r->q = 0;
    for (int j = 0; j < s; ++j)
        if (a[j] != 0.0) { r->j[r->q] = j; r->a[r->q] = a[j]; ++r->q; }
}

/* out = x + Σ_t (h·a[t])·K_j[t]: each component's terms added in the order of the stages, so
   the results are bit-identical to out[] read and written once per stage (the zeros of the
   rows are dropped once per run, where the full rows were scanned at each call for
   h·a[j] = 0: the same unless h·a[j] underflows, h < 1e-290). The components go in groups
   of four lanes (the last group at n − 4, overlapping the one before when 4 ∤ n: their common
   components computed twice, alike), three groups to a tile whose twelve sums stay in
   registers over the stages: twelve independent chains of additions, where before a group of
   four waited on its one chain's latency and the tail of n mod 4 components on a chain each
   (the times: at the top of this file). */
#if defined(__GNUC__)  /* four lanes as one vector (GCC's and Clang's vector extension) */
typedef double jd_v4 __attribute__((vector_size(32)));
#define JD_LOAD4(v, p) memcpy(&(v), (p), sizeof(v))  /* unaligned */
#define JD_INLINE static inline __attribute__((always_inline))

/* the groups of four at o0, o1, o2 of one tile (the first G of them); returns Σ out·0 over
   them. Its sums in three named vectors, not an array of three: with the array, GCC 12 kept
   the loops over the groups of the start and the end as loops through the stack (and zeroed
   it with rep stos where x is NULL), 253 instructions per call at n = 11 (callgrind), of
   which 90 the sums themselves; named, the compiler holds them in registers throughout: 180
   per call, the loop's instructions per right-hand side 490 → 405 (cart(4) with a
   right-hand side of no cost, 10 s). Its time there 0.0287 → 0.0282 µs per right-hand side,
   with the model's 0.1132 → 0.1125 µs (a C driver alternating the libraries in one
   process, best of 100 runs, 4 rounds): the loop waits on latencies more than on its
   instructions. The same operations in the same order: the same numbers to the bit. */
JD_INLINE double tile(int G, const jd_row *r, double h, const double *K, long n,
                      const double *x, long o0, long o1, long o2, double *out) {
    jd_v4 a0 = {0.0, 0.0, 0.0, 0.0}, a1 = a0, a2 = a0, kt;
    if (x) {
        JD_LOAD4(a0, x + o0);
        if (G > 1) JD_LOAD4(a1, x + o1);
        if (G > 2) JD_LOAD4(a2, x + o2);
    }
    for (int t = 0; t < r->q; ++t) {
        const double *k = K + r->j[t] * n, w = h * r->a[t];
        jd_v4 wt = {w, w, w, w};
        JD_LOAD4(kt, k + o0); a0 += wt * kt;
        if (G > 1) { JD_LOAD4(kt, k + o1); a1 += wt * kt; }
        if (G > 2) { JD_LOAD4(kt, k + o2); a2 += wt * kt; }
    }
    jd_v4 z = a0 * 0.0;
    memcpy(out + o0, &a0, sizeof a0);
    if (G > 1) { memcpy(out + o1, &a1, sizeof a1); z += a1 * 0.0; }
    if (G > 2) { memcpy(out + o2, &a2, sizeof a2); z += a2 * 0.0; }
    return (z[0] + z[1]) + (z[2] + z[3]);
}

JD_INLINE int stage_body(long n, const jd_row *r, double h, const double *x, const double *K,
                         double *out) {
    double z = 0.0;  /* x·0 is 0 for finite x, NaN for inf or NaN */
    long groups = (n + 3) / 4;
    for (long g = 0; g < groups; g += 3) {
        long o0 = 4 * g < n - 4 ? 4 * g : n - 4, o1 = 4 * g + 4 < n - 4 ? 4 * g + 4 : n - 4,
             o2 = 4 * g + 8 < n - 4 ? 4 * g + 8 : n - 4, left = groups - g;
        z += left >= 3 ? tile(3, r, h, K, n, x, o0, o1, o2, out)
             : left == 2 ? tile(2, r, h, K, n, x, o0, o1, o2, out)
                         : tile(1, r, h, K, n, x, o0, o1, o2, out);
    }
    return z == 0.0;
}

int stage_sum(long n, const jd_row *r, double h, const double *x, const double *K,
              double *out) {
    if (n >= 4) return stage_body(n, r, h, x, K, out);
#else
int stage_sum(long n, const jd_row *r, double h, const double *x, const double *K,
              double *out) {
#endif
    double z = 0.0;  /* component by component (n < 4, or no vector extension) */
    for (long i = 0; i < n; ++i) {
        double s0 = x ? x[i] : 0.0;
        for (int t = 0; t < r->q; ++t) s0 += (h * r->a[t]) * K[r->j[t] * n + i];
        out[i] = s0;
        z += s0 * 0.0;
    }
    return z == 0.0;
}

/* x·0 is 0 for finite x, NaN for inf or NaN: summed in four lanes (one chain of additions
   over the n components before) */
int all_finite(long n, const double *x) {
    double r = 0.0;
    long i = 0;
#if defined(__GNUC__)
    jd_v4 z = {0.0, 0.0, 0.0, 0.0}, v;
    for (; i + 4 <= n; i += 4) { JD_LOAD4(v, x + i); z += v * 0.0; }
    r = (z[0] + z[1]) + (z[2] + z[3]);
#endif
    for (; i < n; ++i) r += x[i] * 0.0;
    return r == 0.0;
}

double rms_scaled(long n, const double *v, const double *sc) {
    double s = 0.0;
    for (long i = 0; i < n; ++i) { double r = v[i] / sc[i]; s += r * r; }
    return sqrt(s / (double)n);
}

void error_scales(long n, const double *atol, double rtol, const double *x,
                  const double *x_new, double *sc) {
    for (long i = 0; i < n; ++i) {  /* a comparison, not fmax's call */
        double a = fabs(x[i]), b = fabs(x_new[i]);
        sc[i] = atol[i] + rtol * (a > b ? a : b);
    }
}

void error_sums8(long n, const double *e5v, const double *e3v, const double *sc, double *e5,
                 double *e3) {
    double s5 = 0.0, s3 = 0.0;
    for (long i = 0; i < n; ++i) {
        double a5 = e5v[i] / sc[i], a3 = e3v[i] / sc[i];
        s5 += a5 * a5; s3 += a3 * a3;
    }
    *e5 = s5; *e3 = s3;
}

void error_rk5(long n, int s, double h, const double *e, const double *K, double *err) {
    for (long i = 0; i < n; ++i) {
        double a = 0.0;
        for (int j = 0; j < s; ++j) a += e[j] * K[j * n + i];
        err[i] = h * a;
    }
}

/* ---- dense LU of Radau IIA's real and complex iteration matrices ---- */
int lu_real(long n, double *A, long *piv) {
    for (long k = 0; k < n; ++k) {
        long p = k;
        double best = fabs(A[k * n + k]);
        for (long i = k + 1; i < n; ++i) if (fabs(A[i * n + k]) > best) { best = fabs(A[i * n + k]); p = i; }
        piv[k] = p;
        if (best == 0.0 || !isfinite(best)) return 1;
        if (p != k) for (long j = 0; j < n; ++j) { double tmp = A[k * n + j]; A[k * n + j] = A[p * n + j]; A[p * n + j] = tmp; }
        for (long i = k + 1; i < n; ++i) {
            double l = A[i * n + k] / A[k * n + k];
            A[i * n + k] = l;
            for (long j = k + 1; j < n; ++j) A[i * n + j] -= l * A[k * n + j];
        }
    }
    return 0;
}

void lu_solve_real(long n, const double *A, const long *piv, double *b) {
    for (long k = 0; k < n; ++k) { long p = piv[k]; if (p != k) { double tmp = b[k]; b[k] = b[p]; b[p] = tmp; } }
    for (long i = 0; i < n; ++i) { double s = b[i]; for (long j = 0; j < i; ++j) s -= A[i * n + j] * b[j]; b[i] = s; }
    for (long i = n - 1; i >= 0; --i) { double s = b[i]; for (long j = i + 1; j < n; ++j) s -= A[i * n + j] * b[j]; b[i] = s / A[i * n + i]; }
}

/* complex matrices as separate real and imaginary parts (no C99 complex needed) */
int lu_cplx(long n, double *Ar, double *Ai, long *piv) {
    for (long k = 0; k < n; ++k) {
        long p = k;
        double best = hypot(Ar[k * n + k], Ai[k * n + k]);
        for (long i = k + 1; i < n; ++i) {
            double a = hypot(Ar[i * n + k], Ai[i * n + k]);
            if (a > best) { best = a; p = i; }
        }
        piv[k] = p;
        if (best == 0.0 || !isfinite(best)) return 1;
        if (p != k) for (long j = 0; j < n; ++j) {
            double tr = Ar[k * n + j], ti = Ai[k * n + j];
            Ar[k * n + j] = Ar[p * n + j]; Ai[k * n + j] = Ai[p * n + j];
            Ar[p * n + j] = tr; Ai[p * n + j] = ti;
        }
        double dr = Ar[k * n + k], di = Ai[k * n + k], dd = dr * dr + di * di;
        for (long i = k + 1; i < n; ++i) {
            double ar = Ar[i * n + k], ai = Ai[i * n + k];
            double lr = (ar * dr + ai * di) / dd, li = (ai * dr - ar * di) / dd;
            Ar[i * n + k] = lr; Ai[i * n + k] = li;
            for (long j = k + 1; j < n; ++j) {
                double br = Ar[k * n + j], bi = Ai[k * n + j];
                Ar[i * n + j] -= lr * br - li * bi;
                Ai[i * n + j] -= lr * bi + li * br;
            }
        }
    }
    return 0;
}

void lu_solve_cplx(long n, const double *Ar, const double *Ai, const long *piv,
                   double *br, double *bi) {
    for (long k = 0; k < n; ++k) {
        long p = piv[k];
        if (p != k) { double t = br[k]; br[k] = br[p]; br[p] = t; t = bi[k]; bi[k] = bi[p]; bi[p] = t; }
    }
    for (long i = 0; i < n; ++i) {
        double sr = br[i], si = bi[i];
        for (long j = 0; j < i; ++j) {
            sr -= Ar[i * n + j] * br[j] - Ai[i * n + j] * bi[j];
            si -= Ar[i * n + j] * bi[j] + Ai[i * n + j] * br[j];
        }
        br[i] = sr; bi[i] = si;
    }
    for (long i = n - 1; i >= 0; --i) {
        double sr = br[i], si = bi[i];
        for (long j = i + 1; j < n; ++j) {
            sr -= Ar[i * n + j] * br[j] - Ai[i * n + j] * bi[j];
            si -= Ar[i * n + j] * bi[j] + Ai[i * n + j] * br[j];
        }
        double dr = Ar[i * n + i], di = Ai[i * n + i], dd = dr * dr + di * di;
        br[i] = (sr * dr + si * di) / dd;
        bi[i] = (si * dr - sr * di) / dd;
    }
}

void vector_sum(long n, const double *a, const double *b, double *out) {
    for (long i = 0; i < n; ++i) out[i] = a[i] + b[i];
}

void radau_transform(long n, const double *T, const double *in, double *out) {
    for (int k = 0; k < 3; ++k)
        for (long i = 0; i < n; ++i) {
            double a = 0.0;
            for (int j = 0; j < 3; ++j) a += T[k * 3 + j] * in[j * n + i];
            out[k * n + i] = a;
        }
}

void radau_residual(long n, const double *TI, const double *F, const double *W, double mr,
                    double mcr, double mci, double *fr, double *dW) {
    for (long i = 0; i < n; ++i) {
        double a = 0.0, b = 0.0, e = 0.0;
        for (int st = 0; st < 3; ++st) {
            a += F[st * n + i] * TI[0 * 3 + st];
            b += F[st * n + i] * TI[1 * 3 + st];
            e += F[st * n + i] * TI[2 * 3 + st];
        }
        fr[i] = a - mr * W[i];
        /* (b + i e) - (mcr + i mci) (W1 + i W2) */
        dW[n + i] = b - (mcr * W[n + i] - mci * W[2 * n + i]);
        dW[2 * n + i] = e - (mcr * W[2 * n + i] + mci * W[n + i]);
    }
}

double radau_sum_squares(long n, const double *dW, const double *sc) {
    double s = 0.0;
    for (int q = 0; q < 3; ++q)
        for (long i = 0; i < n; ++i) { double v = dW[q * n + i] / sc[i]; s += v * v; }
    return s;
}

void radau_matrices(long n, const double *J, double mr, double mcr, double mci, double *LUr,
                    double *LCr, double *LCi) {
    for (long i = 0; i < n * n; ++i) {
        LUr[i] = -J[i];
        LCr[i] = -J[i];
        LCi[i] = 0.0;
    }
    for (long i = 0; i < n; ++i) {
        LUr[i * n + i] += mr;
        LCr[i * n + i] += mcr;
        LCi[i * n + i] += mci;
    }
}
#endif
