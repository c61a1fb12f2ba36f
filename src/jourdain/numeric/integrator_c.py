"""C source of jourdain's explicit Runge–Kutta integrators for ``M(y,t)·ÿ + k(y,ẏ,t) = q(y,ẏ,t)``.

The step loop runs in C: Dormand–Prince 5(4) ("RK45") and 8(5,3) ("DOP853") with adaptive
steps (Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.4–II.6), their continuous extensions for
output at requested times and for locating events, and a Cholesky factorization of ``M`` in
every right-hand-side evaluation. The Butcher tables are read from SciPy, which tabulates the
same published coefficients, and written into the source as constants.

The state is ``x = [y, ẏ, W]`` with ``W`` the work of the generalized applied forces
``q`` (``Ẇ = ẏᵀq``), integrated to the same tolerance, for the energy balance.
"""

from __future__ import annotations

import numpy as np


def _arr(name: str, a: np.ndarray) -> str:
    vals = ", ".join(repr(float(v)) for v in np.asarray(a, dtype=float).reshape(-1))
    return f"static const double {name}[{max(a.size, 1)}] = {{{vals}}};\n"


def tables() -> str:
    """C constants of the two methods' coefficients."""
    from scipy.integrate._ivp import dop853_coefficients as d8
    from scipy.integrate._ivp.rk import RK45

    out = ["/* Dormand-Prince 5(4): 6 stages + FSAL stage */\n"]
    A5 = np.zeros((7, 7))
    A5[:6, :5] = RK45.A
    out.append(_arr("RK5_A", A5))
    out.append(_arr("RK5_B", RK45.B))
    out.append(_arr("RK5_C", RK45.C))
    out.append(_arr("RK5_E", RK45.E))
    out.append(_arr("RK5_P", RK45.P))  # 7 x 4: dense output polynomial in theta
    out.append("/* Dormand-Prince 8(5,3): 12 stages + FSAL + 3 stages for dense output */\n")
    out.append(_arr("RK8_A", d8.A))  # 16 x 16
    out.append(_arr("RK8_B", d8.B))
    out.append(_arr("RK8_C", d8.C))
    out.append(_arr("RK8_E3", d8.E3))
    out.append(_arr("RK8_E5", d8.E5))
    out.append(_arr("RK8_D", d8.D))  # 4 x 16
    return "".join(out)


SOURCE = r"""
#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef void (*jd_model)(const double *y, const double *yd, double t, const double *p,
                         const double *u, double *out);
typedef int (*jd_input_cb)(double t, const double *y, const double *yd, double *u);

/* return codes */
#define JD_DONE 0
#define JD_CONTINUE 1      /* buffer full or step budget used: call again */
#define JD_EVENT 2         /* a terminal event stopped the run */
#define JD_ESINGULAR -1    /* M not positive definite */
#define JD_ENAN -2         /* NaN or inf in the state or its derivative */
#define JD_ESTEP -3        /* step size underflow */
#define JD_ECALLBACK -4    /* the input callback failed */
#define JD_ENOMEM -5

typedef struct {
    long f, nu, nev;
    jd_model mkq;          /* out = M (f*f, row-major), k (f), q (f) */
    jd_model uexpr;        /* compiled input expressions (all nu), or NULL */
    jd_model events;       /* event functions (nev), or NULL */
    jd_input_cb ucb;       /* Python input callback, or NULL */
    const double *p;
    const double *u_const; /* nu */
    const int *u_kind;     /* nu: 0 constant, 1 table, 2 expression, 3 callback */
    const long *tab_off;   /* nu + 1 offsets into tab_t / tab_v */
    const double *tab_t;
    const double *tab_v;
    const int *ev_dir;     /* nev: +1 rising, -1 falling, 0 both */
    const int *ev_term;    /* nev: 1 terminal */
    int method;            /* 0: RK45 (Dormand-Prince 5(4)), 1: DOP853 */
    double rtol;
    const double *atol;    /* n = 2f + 1 */
    double h_max, h_first;
} jd_problem;

typedef struct {
    const jd_problem *P;
    long n;
    double *u, *u2, *buf, *L;
    long nfev;
    double fail_t;
    double *fail_x;
} jd_ctx;

static void inputs_const(const jd_problem *P, double t, double *u) {
    for (long i = 0; i < P->nu; ++i) {
        if (P->u_kind[i] == 1) {
            const double *T = P->tab_t + P->tab_off[i], *V = P->tab_v + P->tab_off[i];
            long m = P->tab_off[i + 1] - P->tab_off[i];
            if (t <= T[0]) { u[i] = V[0]; continue; }
            if (t >= T[m - 1]) { u[i] = V[m - 1]; continue; }
            long lo = 0, hi = m - 1;
            while (hi - lo > 1) { long mid = (lo + hi) / 2; if (T[mid] <= t) lo = mid; else hi = mid; }
            double s = (t - T[lo]) / (T[hi] - T[lo]);
            u[i] = V[lo] + s * (V[hi] - V[lo]);
        } else {
            u[i] = P->u_const[i];
        }
    }
}

static int inputs(jd_ctx *c, double t, const double *y, const double *yd) {
    const jd_problem *P = c->P;
    inputs_const(P, t, c->u);
    if (P->uexpr) {
        P->uexpr(y, yd, t, P->p, c->u, c->u2);
        for (long i = 0; i < P->nu; ++i) if (P->u_kind[i] == 2) c->u[i] = c->u2[i];
    }
    if (P->ucb) {
        for (long i = 0; i < P->nu; ++i) c->u2[i] = c->u[i];
        if (P->ucb(t, y, yd, c->u2)) return JD_ECALLBACK;
        for (long i = 0; i < P->nu; ++i) if (P->u_kind[i] == 3) c->u[i] = c->u2[i];
    }
    for (long i = 0; i < P->nu; ++i) if (!isfinite(c->u[i])) return JD_ENAN;
    return 0;
}

/* dx = [yd, M^-1 (q - k), yd.q] with M = L L^T (Cholesky) */
static int rhs(jd_ctx *c, double t, const double *x, double *dx) {
    const jd_problem *P = c->P;
    long f = P->f;
    const double *y = x, *yd = x + f;
    c->nfev++;
    for (long i = 0; i < c->n; ++i) {
        if (!isfinite(x[i])) goto nan;
    }
    {
        int r = inputs(c, t, y, yd);
        if (r == JD_ENAN) goto nan;
        if (r) { c->fail_t = t; memcpy(c->fail_x, x, c->n * sizeof(double)); return r; }
    }
    P->mkq(y, yd, t, P->p, c->u, c->buf);
    {
        double *M = c->buf, *k = c->buf + f * f, *q = k + f, *L = c->L, *b = dx + f;
        double w = 0.0, dmax = 0.0;
        for (long i = 0; i < f; ++i) {
            dx[i] = yd[i];
            b[i] = q[i] - k[i];
            w += yd[i] * q[i];
            if (fabs(M[i * f + i]) > dmax) dmax = fabs(M[i * f + i]);
        }
        dx[2 * f] = w;
        for (long j = 0; j < f; ++j) {
            double d = M[j * f + j];
            for (long m = 0; m < j; ++m) d -= L[j * f + m] * L[j * f + m];
            if (!(d > 1e-13 * dmax)) {
                if (!isfinite(d)) goto nan;
                c->fail_t = t; memcpy(c->fail_x, x, c->n * sizeof(double));
                return JD_ESINGULAR;
            }
            double ljj = sqrt(d);
            L[j * f + j] = ljj;
            for (long i = j + 1; i < f; ++i) {
                double s = M[i * f + j];
                for (long m = 0; m < j; ++m) s -= L[i * f + m] * L[j * f + m];
                L[i * f + j] = s / ljj;
            }
        }
        for (long i = 0; i < f; ++i) {      /* L z = b */
            double s = b[i];
            for (long m = 0; m < i; ++m) s -= L[i * f + m] * b[m];
            b[i] = s / L[i * f + i];
        }
        for (long i = f - 1; i >= 0; --i) { /* L^T a = z */
            double s = b[i];
            for (long m = i + 1; m < f; ++m) s -= L[m * f + i] * b[m];
            b[i] = s / L[i * f + i];
        }
        for (long i = 0; i < c->n; ++i) if (!isfinite(dx[i])) goto nan;
    }
    return 0;
nan:
    c->fail_t = t; memcpy(c->fail_x, x, c->n * sizeof(double));
    return JD_ENAN;
}

/* method data */
typedef struct {
    int stages;          /* stages without the FSAL stage */
    int lda;             /* leading dimension of A */
    const double *A, *B, *C;
    double err_exp;
} jd_method;

static double rms_scaled(long n, const double *v, const double *sc) {
    double s = 0.0;
    for (long i = 0; i < n; ++i) { double r = v[i] / sc[i]; s += r * r; }
    return sqrt(s / (double)n);
}

typedef struct {
    jd_ctx *c;
    const jd_method *m;
    int method;
    long n;
    double t_old, h;
    double *x_old, *x_new, *K, *F, *tmp;
    int have_dense;
} jd_step;

/* continuous extension on the last step (computes extra stages for DOP853 once per step) */
static int dense_prepare(jd_step *s) {
    long n = s->n;
    if (s->have_dense) return 0;
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

/*
 * Advance from st[0] = t towards t_end. st[1] holds the step size (0: choose one).
 * x (n), k0 (n: derivative at x, valid when cnt[4] != 0), g_old (nev: events at x).
 * t_eval mode (n_eval > 0): dense output at t_eval[*i_eval ...] into out_t/out_x;
 * else every accepted step is written to out_t/out_x (capacity cap; JD_CONTINUE when full).
 * Events go to ev_t/ev_x/ev_i (capacity ev_cap). cnt: nfev, nstep, naccept, nreject, have_k0.
 * On an error, fail[0] = t and fail[1..n] = the state at which it happened.
 */
int jd_integrate(const jd_problem *P, double t_end, double *st, double *x, double *k0,
                 double *g_old, long *cnt, const double *t_eval, long n_eval, long *i_eval,
                 double *out_t, double *out_x, long cap, long *n_out, double *ev_t, double *ev_x,
                 long *ev_i, long ev_cap, long *n_ev, long max_steps, double *fail) {
    long f = P->f, n = 2 * f + 1, nev = P->nev;
    jd_method m5 = {6, 7, RK5_A, RK5_B, RK5_C, -1.0 / 5.0};
    jd_method m8 = {12, 16, RK8_A, RK8_B, RK8_C, -1.0 / 8.0};
    const jd_method *m = P->method == 1 ? &m8 : &m5;
    int S = m->stages;
    long nu = P->nu > 0 ? P->nu : 1;
    double *mem = (double *)malloc(sizeof(double) *
        (2 * nu + f * f + 2 * f + f * f + n * (16 + 7 + 5) + 3 * (nev + 1)));
    if (!mem) return JD_ENOMEM;
    jd_ctx c = {P, n, mem, mem + nu, mem + 2 * nu, mem + 2 * nu + f * f + 2 * f, 0, 0.0, fail + 1};
    double *K = c.L + f * f, *F = K + 16 * n, *x_new = F + 7 * n, *xs = x_new + n,
           *sc = xs + n, *err = sc + n, *xe = err + n, *g_new = xe + n, *g_tmp = g_new + nev + 1,
           *roots = g_tmp + nev + 1;
    jd_step s = {&c, m, P->method, n, 0.0, 0.0, x, x_new, K, F, xs, 0};
    double t = st[0], h = st[1];
    int status = JD_CONTINUE, r = 0;
    long steps = 0;
    const double SAFETY = 0.9, MIN_FACTOR = 0.2, MAX_FACTOR = 10.0;

    /* requested output at the start */
    while (n_eval > 0 && *i_eval < n_eval && t_eval[*i_eval] <= t) {
        out_t[*n_out] = t_eval[*i_eval];
        memcpy(out_x + *n_out * n, x, n * sizeof(double));
        ++*n_out; ++*i_eval;
    }
    if (!cnt[4]) {
        r = rhs(&c, t, x, k0);
        if (r) { fail[0] = c.fail_t; status = r; goto done; }
        cnt[4] = 1;
        if (nev) {
            inputs(&c, t, x, x + f);
            P->events(x, x + f, t, P->p, c.u, g_old);
        }
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
    int rejected = 0;
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
        for (int si = 1; si < S && !r; ++si) {
            for (long i = 0; i < n; ++i) {
                double acc = 0.0;
                for (int j = 0; j < si; ++j) acc += m->A[si * m->lda + j] * K[j * n + i];
                xs[i] = x[i] + h * acc;
            }
            r = rhs(&c, t + m->C[si] * h, xs, K + si * n);
        }
        if (!r) {
            for (long i = 0; i < n; ++i) {
                double acc = 0.0;
                for (int j = 0; j < S; ++j) acc += m->B[j] * K[j * n + i];
                x_new[i] = x[i] + h * acc;
            }
            r = rhs(&c, t_new, x_new, K + S * n);
        }
        cnt[1]++; steps++;
        if (r == JD_ECALLBACK || r == JD_ENOMEM) { fail[0] = c.fail_t; status = r; break; }
        if (r) {  /* a trial stage failed: retry with a smaller step */
            rejected = 1; cnt[3]++;
            h *= 0.25;
            if (h < h_min * 4.0) { fail[0] = c.fail_t; status = r; break; }
            continue;
        }
        /* error estimate */
        for (long i = 0; i < n; ++i)
            sc[i] = P->atol[i] + P->rtol * fmax(fabs(x[i]), fabs(x_new[i]));
        double en;
        if (P->method == 1) {
            double e5 = 0.0, e3 = 0.0;
            for (long i = 0; i < n; ++i) {
                double a5 = 0.0, a3 = 0.0;
                for (int j = 0; j <= S; ++j) {
                    a5 += RK8_E5[j] * K[j * n + i];
                    a3 += RK8_E3[j] * K[j * n + i];
                }
                a5 /= sc[i]; a3 /= sc[i];
                e5 += a5 * a5; e3 += a3 * a3;
            }
            en = (e5 == 0.0 && e3 == 0.0) ? 0.0 : h * e5 / sqrt((e5 + 0.01 * e3) * (double)n);
        } else {
            for (long i = 0; i < n; ++i) {
                double a = 0.0;
                for (int j = 0; j <= S; ++j) a += RK5_E[j] * K[j * n + i];
                err[i] = h * a;
            }
            en = rms_scaled(n, err, sc);
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
        s.t_old = t; s.h = h; s.have_dense = 0;
        double t_stop = t_new;
        int terminal = -1;
        if (nev) {
            inputs(&c, t_new, x_new, x_new + f);
            P->events(x_new, x_new + f, t_new, P->p, c.u, g_new);
            long n_found = 0;
            for (long e = 0; e < nev; ++e) {
                if (!crossed(P->ev_dir[e], g_old[e], g_new[e])) continue;
                r = dense_prepare(&s);
                if (r) { fail[0] = c.fail_t; status = r; goto done; }
                double te = event_root(&s, e, g_old[e], g_new[e], xe, g_tmp);
                roots[e] = te;
                n_found++;
                if (P->ev_term[e] && te <= t_stop) { t_stop = te; terminal = (int)e; }
            }
            /* record the events up to the stop, in time order */
            while (n_found > 0) {
                long best = -1;
                for (long e = 0; e < nev; ++e) {
                    if (!crossed(P->ev_dir[e], g_old[e], g_new[e])) continue;
                    if (best < 0 || roots[e] < roots[best]) best = e;
                }
                if (best < 0) break;
                if (roots[best] <= t_stop && *n_ev < ev_cap) {
                    ev_t[*n_ev] = roots[best];
                    dense_eval(&s, roots[best], ev_x + *n_ev * n);
                    ev_i[*n_ev] = best;
                    ++*n_ev;
                }
                roots[best] = -INFINITY;
                g_old[best] = g_new[best];   /* mark as consumed */
                n_found--;
                (void)n_found;
            }
        }
        /* output */
        if (n_eval > 0) {
            while (*i_eval < n_eval && t_eval[*i_eval] <= t_stop) {
                double te = t_eval[*i_eval];
                out_t[*n_out] = te;
                if (te == t_new && terminal < 0) {
                    memcpy(out_x + *n_out * n, x_new, n * sizeof(double));
                } else {
                    r = dense_prepare(&s);
                    if (r) { fail[0] = c.fail_t; status = r; goto done; }
                    dense_eval(&s, te, out_x + *n_out * n);
                }
                ++*n_out; ++*i_eval;
            }
        }
        if (terminal >= 0) {
            r = dense_prepare(&s);
            if (r) { fail[0] = c.fail_t; status = r; goto done; }
            dense_eval(&s, t_stop, xe);
            if (n_eval == 0) {
                out_t[*n_out] = t_stop;
                memcpy(out_x + *n_out * n, xe, n * sizeof(double));
                ++*n_out;
            }
            memcpy(x, xe, n * sizeof(double));
            t = t_stop;
            cnt[4] = 0;
            status = JD_EVENT;
            break;
        }
        if (n_eval == 0) {
            out_t[*n_out] = t_new;
            memcpy(out_x + *n_out * n, x_new, n * sizeof(double));
            ++*n_out;
        }
        memcpy(x, x_new, n * sizeof(double));
        memcpy(k0, K + S * n, n * sizeof(double));
        if (nev) memcpy(g_old, g_new, nev * sizeof(double));
        t = t_new;
        double factor = en == 0.0 ? MAX_FACTOR : fmin(MAX_FACTOR, SAFETY * pow(en, m->err_exp));
        if (rejected) factor = fmin(1.0, factor);
        rejected = 0;
        h *= factor;
    }
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
    jd_ctx c = {P, n, mem, mem + nu, mem + 2 * nu, mem + 2 * nu + f * f + 2 * f, 0, 0.0, fail + 1};
    int r = rhs(&c, t, x, dx);
    fail[0] = c.fail_t;
    free(mem);
    return r;
}
"""


def source() -> str:
    """The complete C source of the integrator library."""
    return tables() + SOURCE
