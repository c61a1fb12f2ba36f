/* jourdain's integrator library, part 3 of 4: Radau IIA of order 5 (Hairer & Wanner II, IV.8):
 * real and complex LU, the forward-difference Jacobian, the simplified Newton iteration and the
 * step loop. */
/* ---- dense linear algebra for Radau IIA ---- */
static int lu_real(long n, double *A, long *piv) {
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

static void lu_solve_real(long n, const double *A, const long *piv, double *b) {
    for (long k = 0; k < n; ++k) { long p = piv[k]; if (p != k) { double tmp = b[k]; b[k] = b[p]; b[p] = tmp; } }
    for (long i = 0; i < n; ++i) { double s = b[i]; for (long j = 0; j < i; ++j) s -= A[i * n + j] * b[j]; b[i] = s; }
    for (long i = n - 1; i >= 0; --i) { double s = b[i]; for (long j = i + 1; j < n; ++j) s -= A[i * n + j] * b[j]; b[i] = s / A[i * n + i]; }
}

/* complex matrices as separate real and imaginary parts (no C99 complex needed) */
static int lu_cplx(long n, double *Ar, double *Ai, long *piv) {
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

static void lu_solve_cplx(long n, const double *Ar, const double *Ai, const long *piv,
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

/* forward-difference Jacobian J[i*n + j] = d f_i / d x_j; the work W (last component) does not
   enter the right-hand side, so its column is zero */
static int jacobian(jd_ctx *c, double t, const double *x, const double *f0, double *J,
                    double *xs, double *fx) {
    long n = c->n;
    memcpy(xs, x, n * sizeof(double));
    for (long j = 0; j < n; ++j) {
        if (j == n - 1) { for (long i = 0; i < n; ++i) J[i * n + j] = 0.0; continue; }
        double d = 1.4901161193847656e-08 * fmax(1.0, fabs(x[j]));
        xs[j] = x[j] + d;
        d = xs[j] - x[j];
        int r = rhs(c, t, xs, fx);
        xs[j] = x[j];
        if (r) return r;
        for (long i = 0; i < n; ++i) J[i * n + j] = (fx[i] - f0[i]) / d;
    }
    return 0;
}

typedef struct {
    double *J, *LUr, *LCr, *LCi, *Z, *Z0, *W, *F, *dW, *fr, *fi, *xs, *fx, *sc;
    long *pr, *pc;
} jd_radau_ws;

/* simplified Newton iteration for the collocation system of one Radau IIA step.
   Returns 1 converged, 0 not converged, or a negative error code that must stop the run */
static int collocation(jd_ctx *c, jd_radau_ws *w, double t, const double *x, double h,
                       double tol, int *n_iter, double *rate_out) {
    long n = c->n;
    double mr = RADAU_MU_REAL / h;
    double mcr = RADAU_MU_CPLX[0] / h, mci = RADAU_MU_CPLX[1] / h;
    for (int k = 0; k < 3; ++k)
        for (long i = 0; i < n; ++i) {
            double a = 0.0;
            for (int j = 0; j < 3; ++j) a += RADAU_TI[k * 3 + j] * w->Z0[j * n + i];
            w->W[k * n + i] = a;
        }
    memcpy(w->Z, w->Z0, 3 * n * sizeof(double));
    double dw_old = -1.0, rate = -1.0;
    int converged = 0, k;
    for (k = 0; k < 6; ++k) {
        for (int st = 0; st < 3; ++st) {
            for (long i = 0; i < n; ++i) w->xs[i] = x[i] + w->Z[st * n + i];
            int r = rhs(c, t + RADAU_C[st] * h, w->xs, w->F + st * n);
            if (r == JD_ECALLBACK || r == JD_ENOMEM) return r;
            if (r) { *n_iter = k + 1; *rate_out = rate; return 0; }
        }
        for (long i = 0; i < n; ++i) {
            double a = 0.0, b = 0.0, e = 0.0;
            for (int st = 0; st < 3; ++st) {
                a += w->F[st * n + i] * RADAU_TI[0 * 3 + st];
                b += w->F[st * n + i] * RADAU_TI[1 * 3 + st];
                e += w->F[st * n + i] * RADAU_TI[2 * 3 + st];
            }
            w->fr[i] = a - mr * w->W[i];
            /* (b + i e) - (mcr + i mci) (W1 + i W2) */
            w->dW[n + i] = b - (mcr * w->W[n + i] - mci * w->W[2 * n + i]);
            w->dW[2 * n + i] = e - (mcr * w->W[2 * n + i] + mci * w->W[n + i]);
        }
        lu_solve_real(n, w->LUr, w->pr, w->fr);
        lu_solve_cplx(n, w->LCr, w->LCi, w->pc, w->dW + n, w->dW + 2 * n);
        memcpy(w->dW, w->fr, n * sizeof(double));
        double s = 0.0;
        for (int q = 0; q < 3; ++q)
            for (long i = 0; i < n; ++i) { double v = w->dW[q * n + i] / w->sc[i]; s += v * v; }
        double dw = sqrt(s / (3.0 * (double)n));
        if (!isfinite(dw)) break;
        if (dw_old >= 0.0) rate = dw / dw_old;
        if (rate >= 0.0 && (rate >= 1.0 || pow(rate, 6 - k) / (1.0 - rate) * dw > tol)) break;
        for (long i = 0; i < 3 * n; ++i) w->W[i] += w->dW[i];
        for (int q = 0; q < 3; ++q)
            for (long i = 0; i < n; ++i) {
                double a = 0.0;
                for (int j = 0; j < 3; ++j) a += RADAU_T[q * 3 + j] * w->W[j * n + i];
                w->Z[q * n + i] = a;
            }
        if (dw == 0.0 || (rate >= 0.0 && rate / (1.0 - rate) * dw < tol)) { converged = 1; break; }
        dw_old = dw;
    }
    *n_iter = k + 1 > 6 ? 6 : k + 1;
    *rate_out = rate;
    return converged;
}

static int radau_lu(jd_radau_ws *w, long n, double h) {
    double mr = RADAU_MU_REAL / h, mcr = RADAU_MU_CPLX[0] / h, mci = RADAU_MU_CPLX[1] / h;
    for (long i = 0; i < n * n; ++i) {
        w->LUr[i] = -w->J[i];
        w->LCr[i] = -w->J[i];
        w->LCi[i] = 0.0;
    }
    for (long i = 0; i < n; ++i) {
        w->LUr[i * n + i] += mr;
        w->LCr[i * n + i] += mcr;
        w->LCi[i * n + i] += mci;
    }
    return lu_real(n, w->LUr, w->pr) || lu_cplx(n, w->LCr, w->LCi, w->pc);
}

static double predict_factor(double h, double h_old, double en, double en_old) {
    double mult = 1.0;
    if (en_old >= 0.0 && h_old > 0.0 && en > 0.0) mult = h / h_old * pow(en_old / en, 0.25);
    return fmin(1.0, mult) * (en > 0.0 ? pow(en, -0.25) : INFINITY);
}

/* the Radau IIA (order 5) step loop of Hairer & Wanner, Solving ODEs II, IV.8 */
static int radau_loop(jd_ctx *c, jd_step *s, jd_io *io, double t_end, double *t_io,
                      double *h_io, double *x, double *k0, long *cnt, long max_steps) {
    const jd_problem *P = c->P;
    long n = c->n;
    double *mem = (double *)malloc(sizeof(double) * (4 * n * n + 26 * n) + sizeof(long) * 2 * n);
    if (!mem) return JD_ENOMEM;
    jd_radau_ws w;
    w.J = mem; w.LUr = w.J + n * n; w.LCr = w.LUr + n * n; w.LCi = w.LCr + n * n;
    w.Z = w.LCi + n * n; w.Z0 = w.Z + 3 * n; w.W = w.Z0 + 3 * n; w.F = w.W + 3 * n;
    w.dW = w.F + 3 * n; w.fr = w.dW + 3 * n; w.fi = w.fr + n; w.xs = w.fi + n;
    w.fx = w.xs + n; w.sc = w.fx + n;
    double *xprev = w.sc + n, *Qprev = xprev + n, *err = Qprev + 3 * n;
    w.pr = (long *)(err + n); w.pc = w.pr + n;
    double t = *t_io, h = *h_io, h_old = -1.0, en_old = -1.0, t_prev = 0.0, h_prev = 0.0;
    double tol = fmax(10.0 * 2.220446049250313e-16 / P->rtol, fmin(0.03, sqrt(P->rtol)));
    int status = JD_CONTINUE, r, have_sol = 0, lu_ok = 0, current_jac = 1, rejected = 0;
    long steps = 0;
    r = jacobian(c, t, x, k0, w.J, w.xs, w.fx);
    if (r) { io->fail[0] = c->fail_t; status = r; goto out; }
    while (1) {
        if (t >= t_end) { status = JD_DONE; break; }
        if (steps >= max_steps) { status = JD_CONTINUE; break; }
        if (io->n_eval == 0 && *io->n_out >= io->cap) { status = JD_CONTINUE; break; }
        double h_min = 10.0 * (nextafter(t, INFINITY) - t);
        if (h > P->h_max) { h = P->h_max; h_old = -1.0; en_old = -1.0; lu_ok = 0; }
        if (h < h_min) { h = h_min; h_old = -1.0; en_old = -1.0; lu_ok = 0; }
        double t_new = t + h;
        if (t_new >= t_end || t_end - t_new < h_min) t_new = t_end;
        if (t_new - t != h) lu_ok = 0;
        h = t_new - t;
        /* starting values from the previous collocation polynomial */
        for (int k = 0; k < 3; ++k)
            for (long i = 0; i < n; ++i) {
                double v = 0.0;
                if (have_sol) {
                    double th = (t + RADAU_C[k] * h - t_prev) / h_prev;
                    v = xprev[i] + th * (Qprev[i] + th * (Qprev[n + i] + th * Qprev[2 * n + i]))
                        - x[i];
                }
                w.Z0[k * n + i] = v;
            }
        for (long i = 0; i < n; ++i) w.sc[i] = P->atol[i] + P->rtol * fabs(x[i]);
        int converged = 0, n_iter = 0;
        double rate = -1.0;
        while (!converged) {
            if (!lu_ok) {
                if (radau_lu(&w, n, h)) break;
                lu_ok = 1;
            }
            r = collocation(c, &w, t, x, h, tol, &n_iter, &rate);
            if (r < 0) { io->fail[0] = c->fail_t; status = r; goto out; }
            converged = r;
            if (!converged) {
                if (current_jac) break;
                r = jacobian(c, t, x, k0, w.J, w.xs, w.fx);
                if (r) { io->fail[0] = c->fail_t; status = r; goto out; }
                current_jac = 1;
                lu_ok = 0;
            }
        }
        cnt[1]++; steps++;
        if (!converged) {
            h *= 0.5; lu_ok = 0; rejected = 1; cnt[3]++;
            if (h < h_min) {
                io->fail[0] = t; memcpy(io->fail + 1, x, n * sizeof(double));
                status = JD_ESTEP; break;
            }
            continue;
        }
        double *x_new = s->x_new;
        for (long i = 0; i < n; ++i) x_new[i] = x[i] + w.Z[2 * n + i];
        /* error estimate */
        for (long i = 0; i < n; ++i) {
            double ze = 0.0;
            for (int k = 0; k < 3; ++k) ze += w.Z[k * n + i] * RADAU_E[k];
            w.fi[i] = ze / h;  /* ZE */
            err[i] = k0[i] + w.fi[i];
            w.sc[i] = P->atol[i] + P->rtol * fmax(fabs(x[i]), fabs(x_new[i]));
        }
        lu_solve_real(n, w.LUr, w.pr, err);
        double en = 0.0;
        for (long i = 0; i < n; ++i) { double v = err[i] / w.sc[i]; en += v * v; }
        en = sqrt(en / (double)n);
        double safety = 0.9 * 13.0 / (12.0 + (double)n_iter);
        if (rejected && en > 1.0) {
            for (long i = 0; i < n; ++i) w.xs[i] = x[i] + err[i];
            r = rhs(c, t, w.xs, w.fx);
            if (r == JD_ECALLBACK || r == JD_ENOMEM) { io->fail[0] = c->fail_t; status = r; goto out; }
            if (!r) {
                for (long i = 0; i < n; ++i) err[i] = w.fx[i] + w.fi[i];
                lu_solve_real(n, w.LUr, w.pr, err);
                en = 0.0;
                for (long i = 0; i < n; ++i) { double v = err[i] / w.sc[i]; en += v * v; }
                en = sqrt(en / (double)n);
            }
        }
        if (!(en <= 1.0)) {
            if (!isfinite(en)) en = 1e10;
            h *= fmax(0.2, safety * predict_factor(h, h_old, en, en_old));
            lu_ok = 0; rejected = 1; cnt[3]++;
            if (h < h_min) {
                io->fail[0] = t; memcpy(io->fail + 1, x, n * sizeof(double));
                status = JD_ESTEP; break;
            }
            continue;
        }
        /* accepted */
        cnt[2]++;
        int recompute_jac = n_iter > 2 && rate > 1e-3;
        double factor = fmin(10.0, safety * predict_factor(h, h_old, en, en_old));
        if (!recompute_jac && factor < 1.2) factor = 1.0; else lu_ok = 0;
        r = rhs(c, t_new, x_new, w.fx);
        if (r) { io->fail[0] = c->fail_t; status = r; goto out; }
        /* collocation polynomial of the step, for output, events and the next start */
        s->t_old = t; s->h = h; s->x_old = x; s->have_dense = 0; s->dx_new = w.fx;
        memcpy(s->K, w.Z, 3 * n * sizeof(double));
        double t_stop;
        r = post_step(s, io, t_new, &t_stop);
        if (r == JD_EVENT) {
            memcpy(x, io->xe, n * sizeof(double));
            t = t_stop; cnt[4] = 0; status = JD_EVENT; break;
        }
        if (r) { status = r; goto out; }
        dense_prepare(s);
        memcpy(Qprev, s->F, 3 * n * sizeof(double));
        memcpy(xprev, x, n * sizeof(double));
        t_prev = t; h_prev = h; have_sol = 1;
        memcpy(x, x_new, n * sizeof(double));
        memcpy(k0, w.fx, n * sizeof(double));
        t = t_new;
        if (recompute_jac) {
            r = jacobian(c, t, x, k0, w.J, w.xs, w.fx);
            if (r) { io->fail[0] = c->fail_t; status = r; goto out; }
            current_jac = 1;
        } else {
            current_jac = 0;
        }
        h_old = h; en_old = en;
        h *= factor;
        rejected = 0;
    }
out:
    *t_io = t; *h_io = h;
    free(mem);
    return status;
}
