/* jourdain's integrator library, part 3 of 4: Radau IIA of order 5 (Hairer & Wanner II, IV.8):
 * the forward-difference Jacobian, the simplified Newton iteration and the step loop (its LU
 * factorizations and loops over the state vector are in integrator_kernels.h). */
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
    radau_transform(n, RADAU_TI, w->Z0, w->W);
    memcpy(w->Z, w->Z0, 3 * n * sizeof(double));
    double dw_old = -1.0, rate = -1.0;
    int converged = 0, k;
    for (k = 0; k < 6; ++k) {
        for (int st = 0; st < 3; ++st) {
            vector_sum(n, x, w->Z + st * n, w->xs);
            int r = rhs(c, t + RADAU_C[st] * h, w->xs, w->F + st * n);
            if (r == JD_ECALLBACK || r == JD_ENOMEM) return r;
            if (r) { *n_iter = k + 1; *rate_out = rate; return 0; }
        }
        radau_residual(n, RADAU_TI, w->F, w->W, mr, mcr, mci, w->fr, w->dW);
        lu_solve_real(n, w->LUr, w->pr, w->fr);
        lu_solve_cplx(n, w->LCr, w->LCi, w->pc, w->dW + n, w->dW + 2 * n);
        memcpy(w->dW, w->fr, n * sizeof(double));
        double dw = sqrt(radau_sum_squares(n, w->dW, w->sc) / (3.0 * (double)n));
        if (!isfinite(dw)) break;
        if (dw_old >= 0.0) rate = dw / dw_old;
        if (rate >= 0.0 && (rate >= 1.0 || pow(rate, 6 - k) / (1.0 - rate) * dw > tol)) break;
        vector_sum(3 * n, w->W, w->dW, w->W);
        radau_transform(n, RADAU_T, w->W, w->Z);
        if (dw == 0.0 || (rate >= 0.0 && rate / (1.0 - rate) * dw < tol)) { converged = 1; break; }
        dw_old = dw;
    }
    *n_iter = k + 1 > 6 ? 6 : k + 1;
    *rate_out = rate;
    return converged;
}

static int radau_lu(jd_radau_ws *w, long n, double h) {
    double mr = RADAU_MU_REAL / h, mcr = RADAU_MU_CPLX[0] / h, mci = RADAU_MU_CPLX[1] / h;
    radau_matrices(n, w->J, mr, mcr, mci, w->LUr, w->LCr, w->LCi);
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
