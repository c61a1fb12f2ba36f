/* jourdain's integrator library, part 4 of 4: the step loop of the explicit methods and its
 * entry points jd_integrate and jd_rhs. */
/* DOP853's error norm of the trial step from x to x_new (Hairer, Norsett & Wanner I, II.10:
   the 5th-order estimate scaled by the 3rd-order one); its rows S + 1 and S + 2 */
static double error_norm8(long n, const jd_problem *P, const jd_row *rows, double h,
                          const double *x, const double *x_new, const double *K, double *sc,
                          double *e5v, double *e3v) {
    double e5 = 0.0, e3 = 0.0;
    error_scales(n, P->atol, P->rtol, x, x_new, sc);
    stage_sum(n, rows, 1.0, NULL, K, e5v);
    stage_sum(n, rows + 1, 1.0, NULL, K, e3v);
    error_sums8(n, e5v, e3v, sc, &e5, &e3);
    return (e5 == 0.0 && e3 == 0.0) ? 0.0 : h * e5 / sqrt((e5 + 0.01 * e3) * (double)n);
}

/* PI step-size control of an accepted step (Gustafsson; Hairer, Norsett & Wanner I, II.4 and
   Hairer & Wanner II, IV.2): h_new = h * safety * en^-alpha * en_old^beta. Against the plain
   en^(-1/k) it rejects a quarter as many steps on the benchmarks' pendulums and needs 10-17 %
   fewer evaluations for the same error. */
static double pi_factor(const jd_method *m, double en, double en_old) {
    const double SAFETY = 0.9, MAX_FACTOR = 10.0;
    return en == 0.0 ? MAX_FACTOR
        : fmin(MAX_FACTOR, SAFETY * pow(en, -m->pi_alpha) * pow(en_old, m->pi_beta));
}

/*
 * Advance from st[0] = t towards t_end. st[1] holds the step size (0: choose one), st[2]
 * whether the last trial step was rejected and st[3] the last accepted step's error (0: none
 * yet; explicit methods).
 * x (n), k0 (n: derivative at x, valid when cnt[4] != 0), g_old (nev: events at x).
 * t_eval mode (n_eval > 0): dense output at t_eval[*i_eval ...] into out_t/out_x;
 * else every accepted step is written to out_t/out_x (capacity cap; JD_CONTINUE when full).
 * Events go to ev_t/ev_x/ev_i (capacity ev_cap). cnt: nfev, nstep, naccept, nreject, have_k0.
 * On an error, fail[0] = t and fail[1..n] = the state at which it happened.
 */
int jd_integrate(const jd_problem *P, double t_end, double *st, double *x, double *k0,
                 double *g_old, long *cnt, const double *t_eval, long n_eval, long *i_eval,
                 double *out_t, double *out_x, double *out_dx, long cap, long *n_out,
                 double *ev_t, double *ev_x, long *ev_i, long ev_cap, long *n_ev, long max_steps,
                 double *fail) {
    long f = P->f, n = 2 * f + 1, nev = P->nev;
    jd_method m5 = {6, 7, RK5_A, RK5_B, RK5_C, -1.0 / 5.0, 0.7 / 5.0, 0.4 / 5.0};
    jd_method m8 = {12, 16, RK8_A, RK8_B, RK8_C, -1.0 / 8.0, 0.7 / 8.0, 0.4 / 8.0};
    jd_method mr = {3, 3, RADAU_T, RADAU_E, RADAU_C, -1.0 / 4.0, 0.0, 0.0};  /* err_exp only */
    const jd_method *m = P->method == 1 ? &m8 : P->method == 2 ? &mr : &m5;
    int S = m->stages;
    long nu = P->nu > 0 ? P->nu : 1;
    /* M and its factor: none where the problem brings its own accel (the monodromy matrix's
       columns of analysis/floquet.py are 2f² coordinates, an f⁴ matrix never formed) */
    long ff = (P->accel || P->accel_ctx) ? 0 : f * f;
    double *mem = (double *)malloc(sizeof(double) *
        (2 * nu + ff + 2 * f + ff + n * (16 + 7 + 5) + 3 * (nev + 1)));
    if (!mem) return JD_ENOMEM;
    jd_ctx c = {P, n, mem, mem + nu, mem + 2 * nu, mem + 2 * nu + ff + 2 * f, 0, 0.0, fail + 1,
                0, 0};
    inputs_fix(&c);
    double *K = c.L + ff, *F = K + 16 * n, *x_new = F + 7 * n, *xs = x_new + n,
           *sc = xs + n, *err = sc + n, *xe = err + n, *g_new = xe + n, *g_tmp = g_new + nev + 1,
           *roots = g_tmp + nev + 1;
    jd_step s = {&c, m, P->method, n, 0.0, 0.0, x, x_new, K, F, xs, NULL, 0};
    jd_io io = {t_eval, n_eval, i_eval, out_t, out_x, out_dx, cap, n_out, ev_t, ev_x, ev_i, ev_cap,
                n_ev, g_old, g_new, g_tmp, roots, xe, fail};
    double t = st[0], h = st[1];
    int status = JD_CONTINUE, r = 0;
    long steps = 0;
    const double SAFETY = 0.9, MIN_FACTOR = 0.2;

    if (!cnt[4]) {  /* the start of a run */
        r = rhs(&c, t, x, k0);
        if (r) { fail[0] = c.fail_t; status = r; goto done; }
        cnt[4] = 1;
        if (nev) {
            inputs(&c, t, x, x + f);
            P->events(x, x + f, t, P->p, c.u, g_old);
        }
        if (n_eval == 0) emit(&s, &io, t, x, k0);
    }
    /* requested output at the start */
    while (n_eval > 0 && *i_eval < n_eval && t_eval[*i_eval] <= t) {
        emit(&s, &io, t_eval[*i_eval], x, k0);
        ++*i_eval;
    }
    if (h <= 0.0) {
        if (P->h_first > 0.0) {
            h = P->h_first;
        } else {  /* Hairer's starting step */
            for (long i = 0; i < n; ++i) sc[i] = P->atol[i] + P->rtol * fabs(x[i]);
            double d0 = rms_scaled(n, x, sc), d1 = rms_scaled(n, k0, sc);
            double h0 = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
            h0 = fmin(h0, t_end - t);
            for (long i = 0; i < n; ++i) xs[i] = x[i] + h0 * k0[i];
            r = rhs(&c, t + h0, xs, K + n);
            if (r) { fail[0] = c.fail_t; status = r; goto done; }
            for (long i = 0; i < n; ++i) err[i] = (K[n + i] - k0[i]);
            double d2 = rms_scaled(n, err, sc) / h0;
            double h1 = (d1 <= 1e-15 && d2 <= 1e-15) ? fmax(1e-6, h0 * 1e-3)
                        : pow(0.01 / fmax(d1, d2), -m->err_exp);
            h = fmin(100.0 * h0, h1);
        }
    }
    if (P->method == 2) {
        status = radau_loop(&c, &s, &io, t_end, &t, &h, x, k0, cnt, max_steps);
        goto done;
    }
    /* carried between calls in st[2] and st[3], so that a run split into calls steps exactly
       as one */
    int rejected = st[2] != 0.0;
    double en_old = st[3] > 0.0 ? st[3] : 1e-4;
    /* the rows of the tables without their zeros: the stages 1 … S − 1, the solution (S) and
       DOP853's two error estimates (S + 1, S + 2) */
    jd_row rows[16];
    for (int si = 1; si < S; ++si) row_of(si, m->A + si * m->lda, rows + si);
    row_of(S, m->B, rows + S);
    if (P->method == 1) {
        row_of(S + 1, RK8_E5, rows + S + 1);
        row_of(S + 1, RK8_E3, rows + S + 2);
    }
    while (1) {
        if (t >= t_end) { status = JD_DONE; break; }
        if (steps >= max_steps) { status = JD_CONTINUE; break; }
        if (n_eval == 0 && *n_out >= cap) { status = JD_CONTINUE; break; }
        double h_min = 10.0 * (nextafter(t, INFINITY) - t);
        if (h > P->h_max) h = P->h_max;
        if (h < h_min) h = h_min;
        double t_new = t + h;
        if (t_new >= t_end || t_end - t_new < h_min) { t_new = t_end; }
        h = t_new - t;
        /* stages */
        memcpy(K, k0, n * sizeof(double));
        r = 0;
        for (int si = 1; si < S && !r; ++si) {  /* each stage's state checked as it is summed */
            int fin = stage_sum(n, rows + si, h, x, K, xs);
            r = rhs_at(&c, t + m->C[si] * h, xs, K + si * n, fin);
        }
        /* DOP853: the error norm and the next step's factor (pure arithmetic on K_0 … K_11,
           whose error rows have no term in the last stage) before the right-hand side at
           x_new, not after it: in the order of the program they come before that call's
           long chain of dependent operations, and the processor does them beside it, where
           after it they waited for its end (they decide the next step's h, which its first
           stage needs). Measured (cart(4), 10 s, one process alternating the libraries,
           best of 100 runs, 4-10 rounds): 0.1132-0.1133 → 0.1119-0.1120 µs per right-hand
           side. The same operations on the same values: the same numbers to the bit. */
        double en = 0.0, factor = 0.0;
        if (!r) {
            int fin = stage_sum(n, rows + S, h, x, K, x_new);
            if (P->method == 1 && fin) {
                en = error_norm8(n, P, rows + S + 1, h, x, x_new, K, sc, err, xe);
                if (en <= 1.0) factor = pi_factor(m, en, en_old);
            }
            r = rhs_at(&c, t_new, x_new, K + S * n, fin);
        }
        cnt[1]++; steps++;
        if (r == JD_ECALLBACK || r == JD_ENOMEM) { fail[0] = c.fail_t; status = r; break; }
        if (r) {  /* a trial stage failed: retry with a smaller step */
            rejected = 1; cnt[3]++;
            h *= 0.25;
            if (h < h_min * 4.0) { fail[0] = c.fail_t; status = r; break; }
            continue;
        }
        /* RK45's error estimate (with a term in the last stage: after it; DOP853 with x_new
           not finite does not get here, rhs_at failed) */
        if (P->method != 1) {
            error_scales(n, P->atol, P->rtol, x, x_new, sc);
            error_rk5(n, S + 1, h, RK5_E, K, err);
            en = rms_scaled(n, err, sc);
            if (en <= 1.0) factor = pi_factor(m, en, en_old);
        }
        if (!(en <= 1.0)) {
            if (!isfinite(en)) en = 1e10;
            h *= fmax(MIN_FACTOR, SAFETY * pow(en, m->err_exp));
            rejected = 1; cnt[3]++;
            if (h < h_min) {
                fail[0] = t; memcpy(fail + 1, x, n * sizeof(double));
                status = JD_ESTEP; break;
            }
            continue;
        }
        /* accepted */
        cnt[2]++;
        s.t_old = t; s.h = h; s.have_dense = 0; s.dx_new = K + S * n;
        double t_stop;
        r = post_step(&s, &io, t_new, &t_stop);
        if (r == JD_EVENT) {
            memcpy(x, xe, n * sizeof(double));
            t = t_stop; cnt[4] = 0; status = JD_EVENT; break;
        }
        if (r) { status = r; break; }
        memcpy(x, x_new, n * sizeof(double));
        memcpy(k0, K + S * n, n * sizeof(double));
        t = t_new;
        /* PI step-size control (pi_factor) */
        en_old = fmax(en, 1e-4);
        if (rejected) factor = fmin(1.0, factor);
        rejected = 0;
        h *= factor;
    }
    st[2] = rejected;
    st[3] = en_old;
done:
    st[0] = t; st[1] = h;
    cnt[0] += c.nfev;
    free(mem);
    return status;
}

/* one right-hand side, for scipy's implicit methods (no step loop in C) */
int jd_rhs(const jd_problem *P, double t, const double *x, double *dx, double *fail) {
    long f = P->f, n = 2 * f + 1;
    long nu = P->nu > 0 ? P->nu : 1;
    double *mem = (double *)malloc(sizeof(double) * (2 * nu + 2 * f * f + 2 * f));
    if (!mem) return JD_ENOMEM;
    jd_ctx c = {P, n, mem, mem + nu, mem + 2 * nu, mem + 2 * nu + f * f + 2 * f, 0, 0.0, fail + 1,
                0, 0};
    int r = rhs(&c, t, x, dx);
    fail[0] = c.fail_t;
    free(mem);
    return r;
}
