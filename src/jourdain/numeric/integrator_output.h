/* jourdain's integrator library, part 2 of 4: the methods' data, the continuous extensions
 * (output at requested times), event location and the bookkeeping of an accepted step. */
/* method data */
typedef struct {
    int stages;          /* stages without the FSAL stage */
    int lda;             /* leading dimension of A */
    const double *A, *B, *C;
    double err_exp;      /* -1/k: the step after a rejection (k = order of the estimate + 1) */
    double pi_alpha, pi_beta;  /* PI control of accepted steps: 0.7/k and 0.4/k */
} jd_method;

typedef struct {
    jd_ctx *c;
    const jd_method *m;
    int method;
    long n;
    double t_old, h;
    const double *x_old;
    double *x_new, *K, *F, *tmp;
    const double *dx_new;  /* derivative at x_new */
    int have_dense;
} jd_step;

/* continuous extension on the last step (computes extra stages for DOP853 once per step) */
static int dense_prepare(jd_step *s) {
    long n = s->n;
    if (s->have_dense) return 0;
    if (s->method == 2) {  /* Q = Zᵀ P from the collocation values Z (in K) */
        for (int k = 0; k < 3; ++k)
            for (long i = 0; i < n; ++i) {
                double a = 0.0;
                for (int j = 0; j < 3; ++j) a += s->K[j * n + i] * RADAU_P[j * 3 + k];
                s->F[k * n + i] = a;
            }
    }
    if (s->method == 1) {
        double h = s->h;
        for (int st = 13; st < 16; ++st) {
            for (long i = 0; i < n; ++i) {
                double acc = 0.0;
                for (int j = 0; j < st; ++j) acc += RK8_A[st * 16 + j] * s->K[j * n + i];
                s->tmp[i] = s->x_old[i] + h * acc;
            }
            int r = rhs(s->c, s->t_old + RK8_C[st] * h, s->tmp, s->K + st * n);
            if (r) return r;
        }
        double *F = s->F;
        for (long i = 0; i < n; ++i) {
            double dy = s->x_new[i] - s->x_old[i];
            double f_old = s->K[i], f_new = s->K[12 * n + i];
            F[0 * n + i] = dy;
            F[1 * n + i] = h * f_old - dy;
            F[2 * n + i] = 2.0 * dy - h * (f_new + f_old);
            for (int r2 = 0; r2 < 4; ++r2) {
                double acc = 0.0;
                for (int j = 0; j < 16; ++j) acc += RK8_D[r2 * 16 + j] * s->K[j * n + i];
                F[(3 + r2) * n + i] = h * acc;
            }
        }
    }
    s->have_dense = 1;
    return 0;
}

static void dense_eval(const jd_step *s, double t, double *out) {
    long n = s->n;
    double th = (t - s->t_old) / s->h;
    if (s->method == 2) {  /* collocation polynomial: x_old + Q·(θ, θ², θ³) */
        for (long i = 0; i < n; ++i)
            out[i] = s->x_old[i] + th * (s->F[i] + th * (s->F[n + i] + th * s->F[2 * n + i]));
        return;
    }
    if (s->method == 1) {
        for (long i = 0; i < n; ++i) {
            double y = 0.0;
            for (int k = 6; k >= 0; --k) {
                y += s->F[k * n + i];
                y *= ((6 - k) % 2 == 0) ? th : (1.0 - th);
            }
            out[i] = s->x_old[i] + y;
        }
    } else {
        double th2 = th * th, p[4] = {th, th2, th2 * th, th2 * th2};
        for (long i = 0; i < n; ++i) {
            double acc = 0.0;
            for (int j = 0; j < 7; ++j) {
                double w = 0.0;
                for (int k = 0; k < 4; ++k) w += RK5_P[j * 4 + k] * p[k];
                acc += w * s->K[j * n + i];
            }
            out[i] = s->x_old[i] + s->h * acc;
        }
    }
}

/* root of event ev on the last step by the Illinois variant of regula falsi */
static double event_root(jd_step *s, long ev, double ga, double gb, double *xe, double *g) {
    const jd_problem *P = s->c->P;
    long f = P->f;
    double a = s->t_old, b = s->t_old + s->h;
    int side = 0;
    for (int it = 0; it < 100; ++it) {
        double tm = (a * gb - b * ga) / (gb - ga);
        if (!(tm > a && tm < b)) tm = 0.5 * (a + b);
        dense_eval(s, tm, xe);
        inputs(s->c, tm, xe, xe + f);
        P->events(xe, xe + f, tm, P->p, s->c->u, g);
        double gm = g[ev];
        if ((gm > 0) == (gb > 0) && gm != 0.0) {
            b = tm; gb = gm;
            if (side == -1) ga *= 0.5;
            side = -1;
        } else if (gm == 0.0) {
            a = b = tm; break;
        } else {
            a = tm; ga = gm;
            if (side == 1) gb *= 0.5;
            side = 1;
        }
        if (b - a <= 4e-16 * fabs(b) + 1e-300) break;
    }
    return b;   /* the first time with the new sign */
}

static int crossed(int dir, double g0, double g1) {
    if (dir >= 0 && g0 < 0.0 && g1 >= 0.0) return 1;
    if (dir <= 0 && g0 > 0.0 && g1 <= 0.0) return 1;
    return 0;
}

int jd_state_size(long f) { return (int)(2 * f + 1); }

/* where the results of a run go */
typedef struct {
    const double *t_eval; long n_eval; long *i_eval;
    double *out_t, *out_x, *out_dx; long cap; long *n_out;
    double *ev_t, *ev_x; long *ev_i; long ev_cap; long *n_ev;
    double *g_old, *g_new, *g_tmp, *roots, *xe;
    double *fail;
} jd_io;

/* one output row: time, state and its derivative (evaluated when not at hand) */
static void emit(jd_step *s, jd_io *io, double t, const double *x, const double *dx) {
    long n = s->n, k = *io->n_out;
    io->out_t[k] = t;
    memcpy(io->out_x + k * n, x, n * sizeof(double));
    if (dx) {
        memcpy(io->out_dx + k * n, dx, n * sizeof(double));
    } else if (rhs(s->c, t, io->out_x + k * n, io->out_dx + k * n)) {
        for (long i = 0; i < n; ++i) io->out_dx[k * n + i] = NAN;
    }
    ++*io->n_out;
}

/*
 * Events and output for the accepted step s from s->t_old to t_new (end state s->x_new).
 * Returns 0, JD_EVENT (a terminal event: *t_stop and io->xe hold its time and state) or an
 * error code.
 */
static int post_step(jd_step *s, jd_io *io, double t_new, double *t_stop_out) {
    const jd_problem *P = s->c->P;
    long f = P->f, n = s->n, nev = P->nev;
    double t_stop = t_new;
    int terminal = -1, r;
    if (nev) {
        inputs(s->c, t_new, s->x_new, s->x_new + f);
        P->events(s->x_new, s->x_new + f, t_new, P->p, s->c->u, io->g_new);
        long n_found = 0;
        for (long e = 0; e < nev; ++e) {
            if (!crossed(P->ev_dir[e], io->g_old[e], io->g_new[e])) continue;
            r = dense_prepare(s);
            if (r) { io->fail[0] = s->c->fail_t; return r; }
            double te = event_root(s, e, io->g_old[e], io->g_new[e], io->xe, io->g_tmp);
            io->roots[e] = te;
            n_found++;
            if (P->ev_term[e] && te <= t_stop) { t_stop = te; terminal = (int)e; }
        }
        /* record the events up to the stop, in time order */
        while (n_found > 0) {
            long best = -1;
            for (long e = 0; e < nev; ++e) {
                if (!crossed(P->ev_dir[e], io->g_old[e], io->g_new[e])) continue;
                if (best < 0 || io->roots[e] < io->roots[best]) best = e;
            }
            if (best < 0) break;
            if (io->roots[best] <= t_stop && *io->n_ev < io->ev_cap) {
                io->ev_t[*io->n_ev] = io->roots[best];
                dense_eval(s, io->roots[best], io->ev_x + *io->n_ev * n);
                io->ev_i[*io->n_ev] = best;
                ++*io->n_ev;
            }
            io->g_old[best] = io->g_new[best];   /* consumed */
            n_found--;
        }
    }
    if (io->n_eval > 0) {
        while (*io->i_eval < io->n_eval && io->t_eval[*io->i_eval] <= t_stop) {
            double te = io->t_eval[*io->i_eval];
            if (te == t_new && terminal < 0) {
                emit(s, io, te, s->x_new, s->dx_new);
            } else {
                r = dense_prepare(s);
                if (r) { io->fail[0] = s->c->fail_t; return r; }
                dense_eval(s, te, io->xe);
                emit(s, io, te, io->xe, NULL);
            }
            ++*io->i_eval;
        }
    }
    if (terminal >= 0) {
        r = dense_prepare(s);
        if (r) { io->fail[0] = s->c->fail_t; return r; }
        if (io->n_eval == 0) {
            dense_eval(s, t_stop, io->xe);
            emit(s, io, t_stop, io->xe, NULL);
        }
        dense_eval(s, t_stop, io->xe);
        *t_stop_out = t_stop;
        return JD_EVENT;
    }
    if (io->n_eval == 0) emit(s, io, t_new, s->x_new, s->dx_new);
    if (nev) memcpy(io->g_old, io->g_new, nev * sizeof(double));
    return 0;
}
