/* jourdain, velocity constraints: the right-hand side of a general system in C
 * (jourdain/loops/general_kernel.py appends this to the generated jd_gpos: Phi, Phi_y, Phi_t
 * of the holonomic rows, jd_gvel: A, a of every row, jd_gacc: their c, and dense_c.h). The
 * integrator's state is the independent coordinates y_i and their rates; the speeds z are the rates of the speed
 * coordinates among them. One call: Newton on Phi = 0 for the dependent coordinates (warm
 * started from the last solution), W = [E_z; A_kept] by LU with partial pivoting,
 * yd = W^-1 [z; -a], L = W^-1 [E; 0], gamma = -W^-1 [0; c], the tree's M, k, q,
 * M_z = L^T M L, zd by Cholesky, ydd_i = (L zd + gamma)_i and the power yd . q.
 * The integrator calls jd_gen_accel through its jd_accel hook with p pointing at a jd_gen. */
#include <string.h>

typedef void (*jdg_fn)(const double *y, const double *yd, double t, const double *p,
                       const double *u, double *out);

typedef struct {
    jdg_fn tree;           /* the tree's compiled M (n*n), k (n), q (n) */
    const double *p;       /* the parameters */
    long n, ni, g, mh, mv, rh;  /* coordinates, independent ones, speeds, rows of Phi, rows,
                                   holonomic rows kept (= dependent coordinates) */
    const long *ind, *dep, *rows_h, *rows_v, *spd;  /* spd: the speeds' coordinates (g) */
    double *y;             /* n: the last configuration solved (Newton's start) */
    double *work;          /* jd_gen_work(n, mh, mv, g) doubles */
    long *piv;             /* n */
    double *info;          /* [Newton steps, reason (1 Newton, 2 W singular, 3 M), |Phi|] */
    double newton_tol;
    long max_newton;
} jd_gen;

long jd_gen_work(long n, long mh, long mv, long g) {
    /* pos, vel, W, M k q, L, yd, gamma, zeros and spare, Pd, M_z, r_z, zd, M L (+ slack) */
    return (mh + mh * n + mh) + (3 * mv + mv * n) + n * n + (n * n + 2 * n) + n * g + n + n
           + 3 * n + n * n + g * g + g + 2 * g + n * g + 4 * n;
}

/* LU (dense_c.h's jdl_lu) with a singular matrix refused at rounding: a pivot below
 * eps * r * max|A| (W of rows that are redundant with the speeds) */
static int jdg_lu(long r, double *A, long *piv) {
    double big = 0.0;
    for (long i = 0; i < r * r; ++i) if (fabs(A[i]) > big) big = fabs(A[i]);
    if (jdl_lu(r, A, piv)) return 1;
    for (long k = 0; k < r; ++k)
        if (!(fabs(A[k * r + k]) > 2.220446049250313e-16 * (double)r * big)) return 1;
    return 0;
}

/* Newton on the kept holonomic rows for the dependent coordinates, y_i held: 0, or 1 when it
 * found no configuration. Converged: every row's residual within newton_tol of its scale
 * sum_j |dPhi_i/dy_j| |y_j| + |dPhi_i/dt t| (the test of loops/evaluator.py), or a step at
 * rounding (1e-14 relative: the residual after it is rounding) */
static int jdg_positions(jd_gen *G, double t, const double *u, double *buf, double *Pd,
                         double *zero) {
    long n = G->n, rh = G->rh, mh = G->mh;
    double *y = G->y;
    if (rh == 0) return 0;
    for (long it = 0; it <= G->max_newton; ++it) {
        jd_gpos(y, zero, t, G->p, u, buf);
        const double *Phi = buf, *Py = buf + mh, *Pt = buf + mh + mh * n;
        int ok = 1;
        double res = 0.0;
        for (long k = 0; k < rh; ++k) {
            long i = G->rows_h[k];
            double w = fabs(Pt[i] * t);
            for (long j = 0; j < n; ++j) w += fabs(Py[i * n + j]) * fabs(y[j]);
            if (!(fabs(Phi[i]) <= G->newton_tol * w)) ok = 0;
            if (!(fabs(Phi[i]) <= res)) res = fabs(Phi[i]);
        }
        G->info[0] = (double)it;
        G->info[2] = res;
        if (!isfinite(res)) return 1;
        if (ok) return 0;
        if (it == G->max_newton) break;
        double step[64];
        double *s = rh <= 64 ? step : zero + n;  /* zero + n: n spare doubles */
        for (long a = 0; a < rh; ++a) {
            long i = G->rows_h[a];
            s[a] = Phi[i];
            for (long b = 0; b < rh; ++b) Pd[a * rh + b] = Py[i * n + G->dep[b]];
        }
        if (jdg_lu(rh, Pd, G->piv)) return 1;
        jdl_solve(rh, Pd, G->piv, s);
        double big = 0.0;
        for (long b = 0; b < rh; ++b) {
            y[G->dep[b]] -= s[b];
            double rel = fabs(s[b]) / (1.0 + fabs(y[G->dep[b]]));
            if (rel > big) big = rel;
        }
        if (big <= 1e-14) return 0;
    }
    return 1;
}

/* the state (y_i, yd_i) -> y, yd, L (n x g), gamma, the tree's M, k, q, zd; 0 or a reason */
static int jdg_state(jd_gen *G, const double *yi, const double *ydi, double t, const double *u,
                     double **out_yd, double **out_L, double **out_gam, double **out_tree,
                     double **out_zd, double **out_vel) {
    long n = G->n, g = G->g, mh = G->mh, mv = G->mv, ni = G->ni;
    double *w = G->work;
    double *pos = w;            w += mh + mh * n + mh;
    double *vel = w;            w += 3 * mv + mv * n;
    double *W = w;              w += n * n;
    double *tree = w;           w += n * n + 2 * n;
    double *L = w;              w += n * g;
    double *yd = w;             w += n;
    double *gam = w;            w += n;
    double *zero = w;           w += 3 * n;  /* n zeros, then 2n spare */
    double *Pd = w;             w += n * n;
    double *Mz = w;             w += g * g;
    double *rz = w;             w += g;
    double *zd = w;             w += 2 * g;
    double *ML = w;             w += n * g;
    memset(zero, 0, n * sizeof(double));
    for (long k = 0; k < ni; ++k) G->y[G->ind[k]] = yi[k];
    if (jdg_positions(G, t, u, pos, Pd, zero)) { G->info[1] = 1; return 1; }
    memset(zero, 0, 3 * n * sizeof(double));
    const double *y = G->y;
    jd_gvel(y, zero, t, G->p, u, vel);
    const double *A = vel, *a = vel + mv * n;
    /* W = [E_z; A_kept], LU */
    memset(W, 0, n * n * sizeof(double));
    for (long k = 0; k < g; ++k) W[k * n + G->spd[k]] = 1.0;
    for (long r = 0; r < n - g; ++r) memcpy(W + (g + r) * n, A + G->rows_v[r] * n, n * sizeof(double));
    if (jdg_lu(n, W, G->piv)) { G->info[1] = 2; return 2; }
    /* the speeds: the rates of their coordinates among y_i */
    for (long k = 0; k < g; ++k) {
        double z = 0.0;
        for (long j = 0; j < ni; ++j) if (G->ind[j] == G->spd[k]) z = ydi[j];
        yd[k] = z;
    }
    for (long r = 0; r < n - g; ++r) yd[g + r] = -a[G->rows_v[r]];
    jdl_solve(n, W, G->piv, yd);
    for (long k = 0; k < g; ++k) {
        double *col = zero + n;  /* spare */
        memset(col, 0, n * sizeof(double));
        col[k] = 1.0;
        jdl_solve(n, W, G->piv, col);
        for (long i = 0; i < n; ++i) L[i * g + k] = col[i];
    }
    double *c = vel + mv * n + mv;
    jd_gacc(y, yd, t, G->p, u, c);
    memset(gam, 0, g * sizeof(double));
    for (long r = 0; r < n - g; ++r) gam[g + r] = -c[G->rows_v[r]];
    jdl_solve(n, W, G->piv, gam);
    G->tree(y, yd, t, G->p, u, tree);
    const double *M = tree, *kk = tree + n * n, *q = kk + n;
    /* ML = M L (n x g), Mz = L^T M L, rz = L^T (q - k - M gamma) */
    for (long i = 0; i < n; ++i)
        for (long k = 0; k < g; ++k) {
            double s = 0.0;
            for (long j = 0; j < n; ++j) s += M[i * n + j] * L[j * g + k];
            ML[i * g + k] = s;
        }
    for (long a1 = 0; a1 < g; ++a1) {
        for (long b = 0; b < g; ++b) {
            double s = 0.0;
            for (long i = 0; i < n; ++i) s += L[i * g + a1] * ML[i * g + b];
            Mz[a1 * g + b] = s;
        }
        double s = 0.0;
        for (long i = 0; i < n; ++i) {
            double Mg = 0.0;
            for (long j = 0; j < n; ++j) Mg += M[i * n + j] * gam[j];
            s += L[i * g + a1] * (q[i] - kk[i] - Mg);
        }
        rz[a1] = s;
    }
    /* Cholesky of Mz, then zd */
    if (jdl_chol(g, Mz)) { G->info[1] = 3; return 3; }
    jdl_chol_solve(g, Mz, rz, zd);
    *out_yd = yd; *out_L = L; *out_gam = gam; *out_tree = tree; *out_zd = zd; *out_vel = vel;
    return 0;
}

/* ydd_i = (L zd + gamma)_i of the coordinates idx (k of them; idx NULL: 0 .. k-1) */
static void jdg_ydd(const jd_gen *G, const double *L, const double *gam, const double *zd,
                    const long *idx, long k, double *out) {
    for (long a = 0; a < k; ++a) {
        long i = idx ? idx[a] : a;
        double s = gam[i];
        for (long j = 0; j < G->g; ++j) s += L[i * G->g + j] * zd[j];
        out[a] = s;
    }
}

/* the integrator's jd_accel hook: ydd_i and the power yd . q; 1 on failure, 2 on NaN */
int jd_gen_accel(const double *y, const double *yd, double t, const double *p,
                 const double *u, double *ydd, double *power) {
    jd_gen *G = (jd_gen *)p;
    double *ydf, *L, *gam, *tree, *zd, *vel;
    int r = jdg_state(G, y, yd, t, u, &ydf, &L, &gam, &tree, &zd, &vel);
    if (r) return r == 1 && !isfinite(G->info[2]) ? 2 : 1;
    long n = G->n;
    jdg_ydd(G, L, gam, zd, G->ind, G->ni, ydd);
    const double *q = tree + n * n + n;
    double w = 0.0;
    for (long i = 0; i < n; ++i) w += ydf[i] * q[i];
    *power = w;
    return 0;
}

/* the multipliers of A^T lam = r when every row is independent (the kept rows are all rows):
 * (A A^T) lam = A r by Cholesky (mv <= n); 0, or 1 (then lam is left to the caller: NaN) */
static int jdg_lambda(long n, long mv, const double *A, const double *r, double *G2,
                      double *lam) {
    for (long i = 0; i < mv; ++i) {
        double s = 0.0;
        for (long k = 0; k < n; ++k) s += A[i * n + k] * r[k];
        lam[i] = s;
        for (long j = 0; j <= i; ++j) {
            double v = 0.0;
            for (long k = 0; k < n; ++k) v += A[i * n + k] * A[j * n + k];
            G2[i * mv + j] = v;
        }
    }
    if (jdl_chol(mv, G2)) return 1;
    jdl_chol_solve(mv, G2, lam, lam);
    return 0;
}

/* states x (N rows of stride sx: y_i, yd_i) at times t -> out rows: y (n), yd (n), ydd (n),
 * the residual r = M ydd + k - q (n), Phi (mh), A yd + a (mv), the multipliers (mv; NaN
 * where rows are redundant: the caller's least-norm solve); the index of the first that
 * failed, or -1. G2: mv * mv doubles of scratch */
long jd_gen_samples(jd_gen *G, long N, const double *t, const double *x, long sx,
                    const double *u, double *out, double *G2) {
    long n = G->n, g = G->g, mh = G->mh, mv = G->mv, ni = G->ni;
    long w = 4 * n + mh + 2 * mv;
    for (long s = 0; s < N; ++s) {
        double *o = out + s * w;
        double *ydf, *L, *gam, *tree, *zd, *vel;
        if (jdg_state(G, x + s * sx, x + s * sx + ni, t[s], u, &ydf, &L, &gam, &tree, &zd,
                      &vel)) return s;
        const double *M = tree, *kk = tree + n * n, *q = kk + n;
        memcpy(o, G->y, n * sizeof(double));
        memcpy(o + n, ydf, n * sizeof(double));
        jdg_ydd(G, L, gam, zd, NULL, n, o + 2 * n);
        for (long i = 0; i < n; ++i) {
            double v = kk[i] - q[i];
            for (long j = 0; j < n; ++j) v += M[i * n + j] * o[2 * n + j];
            o[3 * n + i] = v;
        }
        double *pos = G->work;
        double *zero = G->work + (mh + mh * n + mh) + (3 * mv + mv * n) + n * n + n * n + 2 * n
                       + n * g + n + n;
        memset(zero, 0, n * sizeof(double));
        jd_gpos(G->y, zero, t[s], G->p, u, pos);
        memcpy(o + 4 * n, pos, mh * sizeof(double));
        const double *A = vel, *a = vel + mv * n;
        for (long i = 0; i < mv; ++i) {
            double v = a[i];
            for (long j = 0; j < n; ++j) v += A[i * n + j] * ydf[j];
            o[4 * n + mh + i] = v;
        }
        double *lam = o + 4 * n + mh + mv;
        if (n - g != mv || jdg_lambda(n, mv, A, o + 3 * n, G2, lam))
            for (long i = 0; i < mv; ++i) lam[i] = NAN;
    }
    return -1;
}
