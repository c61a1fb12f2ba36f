/* jourdain, kinematic loops: the right-hand side of a closed-loop system in its independent
 * coordinates, all in C (jourdain/loops/compiled.py appends this to the generated jd_con and
 * jd_gam). One call: Newton on Phi(y, d, t) = 0 for the dependent coordinates d (warm-started
 * from the last solution plus the first-order prediction J_z (y - y_last)), the LU of Phi_d,
 * its 1-norm condition number (Hager's estimator), J_z = [I; -Phi_d^-1 Phi_y] and the
 * rheonomic and convective terms by linear solves (never an inverse), the tree's M, k, q,
 * M = J_z^T M_tree J_z, and ydd from its Cholesky factor. The integrator calls jd_loop_accel
 * through its jd_accel hook with p pointing at a jd_loop (below). */
#include <string.h>

typedef void (*jd_tree_fn)(const double *z, const double *zd, double t, const double *p,
                           const double *u, double *out);

typedef struct {
    jd_tree_fn tree;       /* the tree's compiled M (n*n), k (n), q (n) */
    const double *p;       /* the parameters */
    long n, m, f, r;       /* tree coordinates, constraint rows, independent, rows kept */
    const long *ind, *dep, *rows;
    double *z;             /* n: the last configuration solved (Newton's start) */
    double *y_last;        /* f: its independent coordinates */
    double *work;          /* jd_loop_work(n, m, f) doubles */
    long *piv;             /* r */
    double *info;          /* [cond_1(Phi_d), Newton steps, reason, |Phi|, J_z and y_last
                            * valid (the prediction), failures, y_last valid] */
    double newton_tol, cond_limit;  /* newton_tol: relative, see jdl_converged */
    long max_newton;
    jd_tree_fn uexpr;      /* the inputs as functions of t and the parameters, or NULL */
    double *u_buf;         /* their values */
} jd_loop;

/* the inputs at t: the integrator's (constants), or the compiled expressions */
static const double *jdl_inputs(const jd_loop *L, double t, const double *u) {
    if (!L->uexpr) return u;
    L->uexpr(L->z, L->z, t, L->p, u, L->u_buf);
    return L->u_buf;
}

/* reasons in info[2] */
#define JD_LOOP_OK 0
#define JD_LOOP_NEWTON 1   /* Newton found no configuration (Phi_d singular or divergence) */
#define JD_LOOP_COND 2     /* cond_1(Phi_d) passed cond_limit */
#define JD_LOOP_MASS 3     /* M not positive definite */
#define JD_LOOP_BRANCH 4   /* Newton's correction far beyond the prediction: a branch jump */
#define JD_LOOP_DY 0.05    /* the largest step in y of a continuation between samples */
#define JD_NEWTON_PLATEAU 1.4901161193847656e-08  /* sqrt(DBL_EPSILON): jdl_converged */

long jd_loop_work(long n, long m, long f) {
    return (2 * m + m * n) + m + (n * n + 2 * n) + n * n + 2 * n * f + 3 * n + f * f + 2 * f
           + 4 * (n + m) + 2 * f;
}

/* A^T x = b with A = P^T L U: U^T w = b, L^T v = w, x = P^T v */
static void jdl_solve_t(long r, const double *A, const long *piv, double *b) {
    for (long i = 0; i < r; ++i) { double s = b[i]; for (long k = 0; k < i; ++k) s -= A[k * r + i] * b[k]; b[i] = s / A[i * r + i]; }
    for (long i = r - 1; i >= 0; --i) { double s = b[i]; for (long k = i + 1; k < r; ++k) s -= A[k * r + i] * b[k]; b[i] = s; }
    for (long k = r - 1; k >= 0; --k) if (piv[k] != k) { double s = b[k]; b[k] = b[piv[k]]; b[piv[k]] = s; }
}

/* ||A^-1||_1 by Hager's estimator (Higham, Accuracy and Stability, Alg. 15.3), from the LU */
static double jdl_inv_norm1(long r, const double *A, const long *piv, double *x, double *v, double *w) {
    double est = 0.0;
    for (long i = 0; i < r; ++i) x[i] = 1.0 / (double)r;
    for (int it = 0; it < 5; ++it) {
        memcpy(v, x, r * sizeof(double));
        jdl_solve(r, A, piv, v);
        double e = 0.0;
        for (long i = 0; i < r; ++i) e += fabs(v[i]);
        if (it > 0 && e <= est) break;
        est = e;
        for (long i = 0; i < r; ++i) w[i] = v[i] >= 0.0 ? 1.0 : -1.0;
        jdl_solve_t(r, A, piv, w);
        long j = 0;
        double zx = 0.0;
        for (long i = 0; i < r; ++i) { zx += w[i] * x[i]; if (fabs(w[i]) > fabs(w[j])) j = i; }
        if (fabs(w[j]) <= zx) break;
        for (long i = 0; i < r; ++i) x[i] = 0.0;
        x[j] = 1.0;
    }
    return est;
}

/* Newton's stop, the same test as jourdain.loops.evaluator._newton_stop (keep them equal).
 * Returns 1 when z solves Phi = 0 to rounding, 0 to go on, -1 when Phi is not finite; *res is
 * |Phi|_inf over the kept rows (for the report), *last the plateau measure of the previous
 * iterate.
 *
 * Why a scaled residual: the rows of Phi carry the units of the closing joints (metres for a
 * point, none for an orientation) and z mixes radians and metres, so no absolute bound on
 * |Phi| (or on the step) fits every mechanism: the former |Phi| <= 1e-13 (1 + max|z|) let a
 * four-bar of 10 um links stop at residuals of 5e-8 of its lengths, and its integrator took
 * 50 times the right-hand sides of the same four-bar in metres. Row i is scaled by
 *     w_i = sum_j |dPhi_i/dz_j| |z_j| + |dPhi_i/dt| |t|,
 * the change of Phi_i when every coordinate (and t) moves by its own relative amount: w_i has
 * the units of row i whatever the units of the z_j, and |Phi_i| <= tol w_i for every row says
 * that z is the exact solution for coordinates perturbed by at most tol relative (a
 * componentwise backward error, Oettli-Prager), so the test is the same for a mechanism in
 * metres or micrometres. newton_tol is that relative tolerance (1e-13, about 450 eps: above
 * the evaluation rounding of rows whose terms exceed w_i a hundredfold, so that the plateau
 * exit below stays rare; Newton's quadratic convergence usually leaves far less). A row
 * keeps a scale where some coordinates are 0, as long as one of its coordinates is not.
 *
 * Why a plateau exit: rounding in Phi_i is relative to the magnitude of the terms it is summed
 * from, which w_i does not see where they do not move with z (a mechanism far from the origin,
 * or all the row's coordinates near 0): there the test above can be out of reach. Newton
 * then stops reducing the residual; an iterate whose residual, relative to
 * w_i + sum_j |dPhi_i/dz_j| (a coordinate counted at least 1: a radian for an angle), did
 * not decrease and is below sqrt(eps) is at rounding level and taken. Non-convergence does
 * not stop there: a residual that is not decreasing is larger by orders (a diverging or
 * cycling Newton), and near a singular position Newton still decreases it (linearly), so it
 * ends at max_newton with JD_LOOP_NEWTON. The floor of 1 (for a length, 1 of its unit) only
 * widens this rejection bound, never the accuracy, which is that of the plateau itself. */
static int jdl_converged(const jd_loop *L, const double *z, double t, const double *Phi,
                         const double *Pz, const double *Pt, double *res, double *last) {
    long n = L->n;
    int ok = 1;
    double a_max = 0.0, rel = 0.0;
    for (long k = 0; k < L->r; ++k) {
        long i = L->rows[k];
        double a = fabs(Phi[i]), w = fabs(Pt[i] * t), lever = 0.0;
        for (long j = 0; j < n; ++j) {
            double g = fabs(Pz[i * n + j]);
            w += g * fabs(z[j]);
            lever += g;
        }
        if (!(a <= a_max)) a_max = a;  /* NaN propagates */
        if (!(a <= L->newton_tol * w)) ok = 0;
        double q = a > 0.0 ? a / (w + lever) : 0.0;
        if (!(q <= rel)) rel = q;
    }
    *res = a_max;
    if (!isfinite(a_max)) return -1;
    if (ok) return 1;
    if (rel >= *last && rel <= JD_NEWTON_PLATEAU) return 1;
    *last = rel;
    return 0;
}

/* the work array, carved */
typedef struct { double *con, *gam, *tr, *A, *Jz, *MJ, *zd, *g, *h, *Mf, *b, *v1, *v2, *v3, *v4; } jdl_parts;

static jdl_parts jdl_carve(const jd_loop *L) {
    long n = L->n, m = L->m, f = L->f;
    double *w = L->work;
    jdl_parts s;
    s.con = w; w += 2 * m + m * n;
    s.gam = w; w += m;
    s.tr = w; w += n * n + 2 * n;
    s.A = w; w += n * n;
    s.Jz = w; w += n * f;
    s.MJ = w; w += n * f;
    s.zd = w; w += n;
    s.g = w; w += n;
    s.h = w; w += n;
    s.Mf = w; w += f * f;
    s.b = w; w += 2 * f;
    s.v1 = w; w += n + m;
    s.v2 = w; w += n + m;
    s.v3 = w; w += n + m;
    s.v4 = w;
    return s;
}

/* the configuration, rates and the constraint data on the manifold at (y, yd, t); returns a
 * JD_LOOP_* reason */
static int jdl_manifold(const jd_loop *L, const double *y, const double *yd, double t,
                        const double *u, jdl_parts *s) {
    long n = L->n, m = L->m, f = L->f, r = L->r;
    double *z = L->z, *info = L->info;
    const double *Phi = s->con, *Pz = s->con + m, *Pt = s->con + m + m * n;
    /* prediction along the manifold from the last solution; its size d_pred bounds the
     * Newton correction on the same branch (second order in y - y_last) */
    double d_pred = 0.0, *z_pred = s->v4 + 2 * f;  /* after the samples' y0, yi */
    int predicted = info[4] != 0.0;
    if (predicted)
        for (long i = 0; i < r; ++i) {
            double d = 0.0;
            for (long j = 0; j < f; ++j) d += s->Jz[L->dep[i] * f + j] * (y[j] - L->y_last[j]);
            z[L->dep[i]] += d;
            z_pred[i] = z[L->dep[i]];
            if (fabs(d) > d_pred) d_pred = fabs(d);
        }
    for (long j = 0; j < f; ++j) z[L->ind[j]] = y[j];
    double scale = 1.0, last = INFINITY, res = 0.0;
    for (long i = 0; i < n; ++i) if (1.0 + fabs(z[i]) > scale) scale = 1.0 + fabs(z[i]);
    for (long i = 0; i < n; ++i) s->zd[i] = 0.0;
    long it = 0;
    for (;; ++it) {
        jd_con(z, s->zd, t, L->p, u, s->con);
        int stop = jdl_converged(L, z, t, Phi, Pz, Pt, &res, &last);
        if (stop > 0) break;
        if (stop < 0 || it == L->max_newton) { info[1] = (double)it; info[3] = res; return JD_LOOP_NEWTON; }
        for (long i = 0; i < r; ++i)
            for (long j = 0; j < r; ++j) s->A[i * r + j] = Pz[L->rows[i] * n + L->dep[j]];
        if (jdl_lu(r, s->A, L->piv)) { info[1] = (double)it; info[3] = res; return JD_LOOP_NEWTON; }
        for (long i = 0; i < r; ++i) s->v1[i] = Phi[L->rows[i]];
        jdl_solve(r, s->A, L->piv, s->v1);
        for (long i = 0; i < r; ++i) z[L->dep[i]] -= s->v1[i];
    }
    info[1] = (double)it;
    info[3] = res;
    /* a correction far larger than the prediction: Newton left the branch (another assembly
     * mode, or the same configuration 2 pi away), which the integrator must not see */
    if (predicted) {
        double d_newton = 0.0;
        for (long i = 0; i < r; ++i)
            if (fabs(z[L->dep[i]] - z_pred[i]) > d_newton) d_newton = fabs(z[L->dep[i]] - z_pred[i]);
        if (d_newton > 10.0 * d_pred + 1e-6 * scale) return JD_LOOP_BRANCH;
    }
    /* Phi_d at the solution: its LU and condition number */
    double norm = 0.0;
    for (long j = 0; j < r; ++j) {
        double c = 0.0;
        for (long i = 0; i < r; ++i) c += fabs(s->A[i * r + j] = Pz[L->rows[i] * n + L->dep[j]]);
        if (c > norm) norm = c;
    }
    if (jdl_lu(r, s->A, L->piv)) { info[0] = INFINITY; return JD_LOOP_COND; }
    double cond = norm * jdl_inv_norm1(r, s->A, L->piv, s->v1, s->v2, s->v3);
    info[0] = cond;
    if (!(cond <= L->cond_limit)) return JD_LOOP_COND;
    /* J_z and the rheonomic rates */
    for (long j = 0; j < f; ++j) {
        for (long i = 0; i < r; ++i) s->v1[i] = Pz[L->rows[i] * n + L->ind[j]];
        jdl_solve(r, s->A, L->piv, s->v1);
        for (long i = 0; i < r; ++i) s->Jz[L->dep[i] * f + j] = -s->v1[i];
        for (long i = 0; i < f; ++i) s->Jz[L->ind[i] * f + j] = i == j ? 1.0 : 0.0;
    }
    for (long i = 0; i < r; ++i) s->v1[i] = Pt[L->rows[i]];
    jdl_solve(r, s->A, L->piv, s->v1);
    for (long i = 0; i < n; ++i) s->zd[i] = 0.0;
    for (long i = 0; i < r; ++i) s->zd[L->dep[i]] = -s->v1[i];
    for (long i = 0; i < n; ++i) {
        double a = s->zd[i];
        for (long j = 0; j < f; ++j) a += s->Jz[i * f + j] * yd[j];
        s->zd[i] = a;
    }
    /* the convective term: zdd = J_z ydd + g, g_d = -Phi_d^-1 c */
    jd_gam(z, s->zd, t, L->p, u, s->gam);
    for (long i = 0; i < r; ++i) s->v1[i] = s->gam[L->rows[i]];
    jdl_solve(r, s->A, L->piv, s->v1);
    for (long i = 0; i < n; ++i) s->g[i] = 0.0;
    for (long i = 0; i < r; ++i) s->g[L->dep[i]] = -s->v1[i];
    memcpy(L->y_last, y, f * sizeof(double));
    info[4] = info[6] = 1.0;
    return JD_LOOP_OK;
}

/* M ydd = J_z^T (q - k - M_tree g) with M = J_z^T M_tree J_z; power = yd^T J_z^T q_tree */
static int jdl_dynamics(const jd_loop *L, const double *yd, double t, const double *u,
                        jdl_parts *s, double *ydd, double *power) {
    long n = L->n, f = L->f;
    L->tree(L->z, s->zd, t, L->p, u, s->tr);
    const double *Mt = s->tr, *kt = s->tr + n * n, *qt = kt + n;
    for (long i = 0; i < n; ++i) {
        double a = qt[i] - kt[i];
        for (long j = 0; j < n; ++j) a -= Mt[i * n + j] * s->g[j];
        s->h[i] = a;
        for (long j = 0; j < f; ++j) {
            double b = 0.0;
            for (long k = 0; k < n; ++k) b += Mt[i * n + k] * s->Jz[k * f + j];
            s->MJ[i * f + j] = b;
        }
    }
    double w = 0.0, dmax = 0.0;
    for (long i = 0; i < f; ++i) {
        double a = 0.0, qi = 0.0;
        for (long k = 0; k < n; ++k) { a += s->Jz[k * f + i] * s->h[k]; qi += s->Jz[k * f + i] * qt[k]; }
        s->b[i] = a;
        w += yd[i] * qi;
        for (long j = 0; j <= i; ++j) {
            double c = 0.0;
            for (long k = 0; k < n; ++k) c += s->Jz[k * f + i] * s->MJ[k * f + j];
            s->Mf[i * f + j] = c;
        }
        if (fabs(s->Mf[i * f + i]) > dmax) dmax = fabs(s->Mf[i * f + i]);
    }
    *power = w;
    /* Cholesky M = L L^T in the lower triangle of Mf, then the two triangular solves */
    double *C = s->Mf;
    for (long j = 0; j < f; ++j) {
        double d = C[j * f + j];
        for (long k = 0; k < j; ++k) d -= C[j * f + k] * C[j * f + k];
        if (!(d > 1e-13 * dmax)) {
            if (!isfinite(d)) return 2;
            L->info[2] = JD_LOOP_MASS;
            return 1;
        }
        d = sqrt(d);
        C[j * f + j] = d;
        for (long i = j + 1; i < f; ++i) {
            double a = C[i * f + j];
            for (long k = 0; k < j; ++k) a -= C[i * f + k] * C[j * f + k];
            C[i * f + j] = a / d;
        }
    }
    for (long i = 0; i < f; ++i) {
        double a = s->b[i];
        for (long k = 0; k < i; ++k) a -= C[i * f + k] * ydd[k];
        ydd[i] = a / C[i * f + i];
    }
    for (long i = f - 1; i >= 0; --i) {
        double a = ydd[i];
        for (long k = i + 1; k < f; ++k) a -= C[k * f + i] * ydd[k];
        ydd[i] = a / C[i * f + i];
    }
    for (long i = 0; i < f; ++i) if (!isfinite(ydd[i])) return 2;
    return 0;
}

/* the integrator's jd_accel: p points at a jd_loop; 0, 1 (singular: reason in info[2]), 2 NaN */
int jd_loop_accel(const double *y, const double *yd, double t, const double *p,
                  const double *u, double *ydd, double *power) {
    const jd_loop *L = (const jd_loop *)(const void *)p;
    jdl_parts s = jdl_carve(L);
    u = jdl_inputs(L, t, u);
    int reason = jdl_manifold(L, y, yd, t, u, &s);
    if (reason) {
        L->info[2] = reason;
        L->info[4] = 0.0;
        L->info[5] += 1.0;
        return 1;
    }
    return jdl_dynamics(L, yd, t, u, &s, ydd, power);
}

/* Samples of a motion: for each of the N states x_k = [y, yd] (stride sx) at t_k, out_k =
 * [z (n), zd (n), zdd (n), Phi (m), Phi_dot (m), lambda (m), cond_1(Phi_d)]; lambda from the
 * tree's equations M_tree zdd + k_tree - q_tree = Phi_z^T lambda (rows not kept: 0). Returns
 * the index of the first state that failed, or -1. */
long jd_loop_samples(const jd_loop *L, long N, const double *t, const double *x, long sx,
                     const double *u_const, double *out) {
    long n = L->n, m = L->m, f = L->f, r = L->r, w = 3 * n + 3 * m + 1;
    jdl_parts s = jdl_carve(L);
    for (long k = 0; k < N; ++k) {
        const double *y = x + k * sx, *yd = y + f, *u = jdl_inputs(L, t[k], u_const);
        double *o = out + k * w, *ydd = s.b + f, pw;
        /* far from the last solution: continuation in steps of at most JD_LOOP_DY in y, so
         * that the dependent coordinates follow their branch (Newton from afar may land on
         * the same configuration with an angle 2 pi away, or on another assembly mode) */
        if (L->info[6] != 0.0) {
            double *y0 = s.v4, *yi = s.v4 + f, dmax = 0.0;
            memcpy(y0, L->y_last, f * sizeof(double));
            for (long j = 0; j < f; ++j) if (fabs(y[j] - y0[j]) > dmax) dmax = fabs(y[j] - y0[j]);
            long K = (long)ceil(dmax / JD_LOOP_DY);
            for (long i = 1; i < K; ++i) {
                for (long j = 0; j < f; ++j) yi[j] = y0[j] + (double)i / (double)K * (y[j] - y0[j]);
                if (jdl_manifold(L, yi, yd, t[k], u, &s)) break;
            }
        }
        int reason = jdl_manifold(L, y, yd, t[k], u, &s);
        if (reason) { L->info[2] = reason; L->info[4] = 0.0; return k; }
        if (jdl_dynamics(L, yd, t[k], u, &s, ydd, &pw)) return k;
        const double *Phi = s.con, *Pz = s.con + m, *Pt = s.con + m + m * n;
        const double *Mt = s.tr, *kt = s.tr + n * n, *qt = kt + n;
        for (long i = 0; i < n; ++i) {
            double a = s.g[i];
            for (long j = 0; j < f; ++j) a += s.Jz[i * f + j] * ydd[j];
            o[i] = L->z[i];
            o[n + i] = s.zd[i];
            o[2 * n + i] = a;
        }
        for (long i = 0; i < m; ++i) {
            double a = Pt[i];
            for (long j = 0; j < n; ++j) a += Pz[i * n + j] * s.zd[j];
            o[3 * n + i] = Phi[i];
            o[3 * n + m + i] = a;
            o[3 * n + 2 * m + i] = 0.0;
        }
        /* Phi_d^T lambda_kept = (M_tree zdd + k - q)_d */
        for (long i = 0; i < r; ++i) {
            long d = L->dep[i];
            double a = kt[d] - qt[d];
            for (long j = 0; j < n; ++j) a += Mt[d * n + j] * o[2 * n + j];
            s.v1[i] = a;
        }
        jdl_solve_t(r, s.A, L->piv, s.v1);
        for (long i = 0; i < r; ++i) o[3 * n + 2 * m + L->rows[i]] = s.v1[i];
        o[3 * n + 3 * m] = L->info[0];
    }
    return -1;
}

/* ---- the augmented-Lagrangian (penalty) form in all tree coordinates (Bayo & Ledesma) ----
 * (M + alpha G^T G) zdd = q - k - G^T lam - alpha G^T (c + 2 xi omega Phi_dot + omega^2 Phi),
 * lam <- lam + alpha (G zdd + c + 2 xi omega Phi_dot + omega^2 Phi), `iterations` times from 0
 * (G = Phi_z); system.simulate(..., formulation="penalty"), jourdain.loops.redundant. */
typedef struct {
    jd_tree_fn tree;
    const double *p;
    long n, m, iterations;
    double alpha, xi, omega;
    double *work;          /* jd_penalty_work(n, m) doubles */
    double *lam;           /* m: the multipliers of the last evaluation */
} jd_penalty;

long jd_penalty_work(long n, long m) {
    return (2 * m + m * n) + m + (n * n + 2 * n) + n * n + 2 * n + 2 * m;
}

/* Cholesky factor in the lower triangle of the n x n row-major A; 1 when not positive definite */
int jd_penalty_accel(const double *z, const double *zd, double t, const double *pp,
                     const double *u, double *zdd, double *power) {
    const jd_penalty *P = (const jd_penalty *)(const void *)pp;
    long n = P->n, m = P->m;
    double *w = P->work;
    double *con = w; w += 2 * m + m * n;
    double *gam = w; w += m;
    double *tr = w; w += n * n + 2 * n;
    double *A = w; w += n * n;
    double *b0 = w; w += n;
    double *b = w; w += n;
    double *stab = w; w += m;
    const double *Phi = con, *G = con + m, *Pt = con + m + m * n;
    jd_con(z, zd, t, P->p, u, con);
    jd_gam(z, zd, t, P->p, u, gam);
    P->tree(z, zd, t, P->p, u, tr);
    const double *M = tr, *k = tr + n * n, *q = k + n;
    double c2 = 2.0 * P->xi * P->omega, w2 = P->omega * P->omega, pw = 0.0;
    for (long r = 0; r < m; ++r) {
        double pd = Pt[r];
        for (long j = 0; j < n; ++j) pd += G[r * n + j] * zd[j];
        stab[r] = gam[r] + c2 * pd + w2 * Phi[r];
    }
    for (long i = 0; i < n; ++i) {
        double a = q[i] - k[i];
        for (long r = 0; r < m; ++r) a -= P->alpha * G[r * n + i] * stab[r];
        b0[i] = a;
        pw += zd[i] * q[i];
        for (long j = 0; j <= i; ++j) A[i * n + j] = M[i * n + j];
    }
    /* alpha G^T G row by row of G, over its nonzero entries (a closing joint's rows touch
     * the coordinates of its loop only) */
    for (long r = 0; r < m; ++r) {
        const double *g = G + r * n;
        for (long i = 0; i < n; ++i) {
            if (g[i] == 0.0) continue;
            double ai = P->alpha * g[i];
            for (long j = 0; j <= i; ++j) if (g[j] != 0.0) A[i * n + j] += ai * g[j];
        }
    }
    *power = pw;
    if (jdl_chol(n, A)) return isfinite(A[0]) ? 1 : 2;
    jdl_chol_solve(n, A, b0, zdd);
    for (long r = 0; r < m; ++r) P->lam[r] = 0.0;
    for (long it = 0; it < P->iterations; ++it) {
        for (long r = 0; r < m; ++r) {
            double a = stab[r];
            for (long j = 0; j < n; ++j) a += G[r * n + j] * zdd[j];
            P->lam[r] += P->alpha * a;
        }
        for (long i = 0; i < n; ++i) {
            double a = b0[i];
            for (long r = 0; r < m; ++r) a -= G[r * n + i] * P->lam[r];
            b[i] = a;
        }
        jdl_chol_solve(n, A, b, zdd);
    }
    for (long i = 0; i < n; ++i) if (!isfinite(zdd[i])) return 2;
    return 0;
}
