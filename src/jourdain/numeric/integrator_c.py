"""C source of jourdain's explicit Runge–Kutta integrators for ``M(y,t)·ÿ + k(y,ẏ,t) = q(y,ẏ,t)``.

The step loop runs in C: Dormand–Prince 5(4) ("RK45") and 8(5,3) ("DOP853") with adaptive
steps (Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.4–II.6) and the implicit Radau IIA method
of order 5 for stiff problems (Hairer & Wanner, *Solving ODEs II*, §IV.8: simplified Newton
iterations in the eigenbasis of the Runge–Kutta matrix, a forward-difference Jacobian, the
embedded error estimate and Gustafsson's step-size predictor), their continuous extensions for
output at requested times and for locating events, and a Cholesky factorization of ``M`` in
every right-hand-side evaluation. The coefficient tables are the published constants, written
out once in ``rk_tables.h`` (no run-time dependency on SciPy's private modules).

The state is ``x = [y, ẏ, W]`` with ``W`` the work of the generalized applied forces
``q`` (``Ẇ = ẏᵀq``), integrated to the same tolerance, for the energy balance.
"""

from __future__ import annotations

import re
from importlib import resources

import numpy as np


def _arr(name: str, a: np.ndarray) -> str:
    vals = ", ".join(repr(float(v)) for v in np.asarray(a, dtype=float).reshape(-1))
    return f"static const double {name}[{max(a.size, 1)}] = {{{vals}}};\n"


def tables() -> str:
    """C constants of the methods' coefficients (``rk_tables.h`` beside this module: the
    published tables written out once; tests check them against the order conditions and
    against SciPy's tabulation)."""
    return (resources.files(__package__) / "rk_tables.h").read_text()


def table_values(text: str | None = None) -> dict[str, np.ndarray]:
    """The arrays of :func:`tables` by name (for the tests of the coefficients)."""
    out: dict[str, np.ndarray] = {}
    for m in re.finditer(r"static const double (\w+)(\[\d+\])? = \{?([^};]*)\}?;",
                         tables() if text is None else text):
        out[m.group(1)] = np.array([float(v) for v in m.group(3).split(",")])
    return out


SOURCE = r"""
#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef void (*jd_model)(const double *y, const double *yd, double t, const double *p,
                         const double *u, double *out);
typedef int (*jd_input_cb)(double t, const double *y, const double *yd, double *u);
typedef int (*jd_accel_fn)(const double *y, const double *yd, double t, const double *p,
                           const double *u, double *ydd, double *power);

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
    jd_accel_fn accel;     /* the model's fused M, k, q and Cholesky solve, or NULL */
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
    if (P->accel) {
        int r = P->accel(y, yd, t, P->p, c->u, dx + f, dx + 2 * f);
        for (long i = 0; i < f; ++i) dx[i] = yd[i];
        if (r == 2) goto nan;
        if (r == 1) {
            c->fail_t = t; memcpy(c->fail_x, x, c->n * sizeof(double));
            return JD_ESINGULAR;
        }
        return 0;
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
        /* L L^T = M; the diagonal of L holds 1/l_jj (one division per column) */
        for (long j = 0; j < f; ++j) {
            const double *Lj = L + j * f;
            double d = M[j * f + j];
            for (long m = 0; m < j; ++m) d -= Lj[m] * Lj[m];
            if (!(d > 1e-13 * dmax)) {
                if (!isfinite(d)) goto nan;
                c->fail_t = t; memcpy(c->fail_x, x, c->n * sizeof(double));
                return JD_ESINGULAR;
            }
            double inv = 1.0 / sqrt(d);
            L[j * f + j] = inv;
            for (long i = j + 1; i < f; ++i) {
                const double *Li = L + i * f;
                double s = M[i * f + j];
                for (long m = 0; m < j; ++m) s -= Li[m] * Lj[m];
                L[i * f + j] = s * inv;
            }
        }
        for (long i = 0; i < f; ++i) {      /* L z = b */
            double s = b[i];
            for (long m = 0; m < i; ++m) s -= L[i * f + m] * b[m];
            b[i] = s * L[i * f + i];
        }
        for (long i = f - 1; i >= 0; --i) { /* L^T a = z */
            double s = b[i];
            for (long m = i + 1; m < f; ++m) s -= L[m * f + i] * b[m];
            b[i] = s * L[i * f + i];
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
    double err_exp;      /* -1/k: the step after a rejection (k = order of the estimate + 1) */
    double pi_alpha, pi_beta;  /* PI control of accepted steps: 0.7/k and 0.4/k */
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
    double *mem = (double *)malloc(sizeof(double) *
        (2 * nu + f * f + 2 * f + f * f + n * (16 + 7 + 5) + 3 * (nev + 1)));
    if (!mem) return JD_ENOMEM;
    jd_ctx c = {P, n, mem, mem + nu, mem + 2 * nu, mem + 2 * nu + f * f + 2 * f, 0, 0.0, fail + 1};
    double *K = c.L + f * f, *F = K + 16 * n, *x_new = F + 7 * n, *xs = x_new + n,
           *sc = xs + n, *err = sc + n, *xe = err + n, *g_new = xe + n, *g_tmp = g_new + nev + 1,
           *roots = g_tmp + nev + 1;
    jd_step s = {&c, m, P->method, n, 0.0, 0.0, x, x_new, K, F, xs, NULL, 0};
    jd_io io = {t_eval, n_eval, i_eval, out_t, out_x, out_dx, cap, n_out, ev_t, ev_x, ev_i, ev_cap,
                n_ev, g_old, g_new, g_tmp, roots, xe, fail};
    double t = st[0], h = st[1];
    int status = JD_CONTINUE, r = 0;
    long steps = 0;
    const double SAFETY = 0.9, MIN_FACTOR = 0.2, MAX_FACTOR = 10.0;

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
        /* stage sums column by column: contiguous, and the zeros of the tables skipped */
        for (int si = 1; si < S && !r; ++si) {
            memcpy(xs, x, n * sizeof(double));
            for (int j = 0; j < si; ++j) {
                double a = h * m->A[si * m->lda + j];
                if (a == 0.0) continue;
                const double *Kj = K + j * n;
                for (long i = 0; i < n; ++i) xs[i] += a * Kj[i];
            }
            r = rhs(&c, t + m->C[si] * h, xs, K + si * n);
        }
        if (!r) {
            memcpy(x_new, x, n * sizeof(double));
            for (int j = 0; j < S; ++j) {
                double b = h * m->B[j];
                if (b == 0.0) continue;
                const double *Kj = K + j * n;
                for (long i = 0; i < n; ++i) x_new[i] += b * Kj[i];
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
            double e5 = 0.0, e3 = 0.0, *a3v = xe;
            memset(err, 0, n * sizeof(double));
            memset(a3v, 0, n * sizeof(double));
            for (int j = 0; j <= S; ++j) {
                const double *Kj = K + j * n;
                double c5 = RK8_E5[j], c3 = RK8_E3[j];
                if (c5 != 0.0) for (long i = 0; i < n; ++i) err[i] += c5 * Kj[i];
                if (c3 != 0.0) for (long i = 0; i < n; ++i) a3v[i] += c3 * Kj[i];
            }
            for (long i = 0; i < n; ++i) {
                double a5 = err[i] / sc[i], a3 = a3v[i] / sc[i];
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
        /* PI step-size control (Gustafsson; Hairer, Norsett & Wanner I, II.4 and Hairer &
           Wanner II, IV.2): h_new = h * safety * en^-alpha * en_old^beta. Against the plain
           en^(-1/k) it rejects a quarter as many steps on the benchmarks' pendulums and needs
           10-17 % fewer evaluations for the same error. */
        double factor = en == 0.0 ? MAX_FACTOR
            : fmin(MAX_FACTOR, SAFETY * pow(en, -m->pi_alpha) * pow(en_old, m->pi_beta));
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
