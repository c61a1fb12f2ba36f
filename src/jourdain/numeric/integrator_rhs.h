/* jourdain's integrator library, part 1 of 4 (numeric/integrator_c.py joins them, after the
 * declarations of integrator_kernels.h): the problem
 * a run integrates, its inputs, and the right-hand side dx = [yd, M^-1 (q - k), yd.q]. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef void (*jd_model)(const double *y, const double *yd, double t, const double *p,
                         const double *u, double *out);
typedef int (*jd_input_cb)(double t, const double *y, const double *yd, double *u);
typedef int (*jd_accel_fn)(const double *y, const double *yd, double t, const double *p,
                           const double *u, double *ydd, double *power);
/* the same with a context (an interpreted model: numeric/interpreter.py) */
typedef int (*jd_accel_ctx_fn)(const void *ctx, const double *y, const double *yd, double t,
                               const double *p, const double *u, double *ydd, double *power);

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
    jd_accel_ctx_fn accel_ctx; /* where accel is NULL: this one, called with ctx */
    const void *ctx;
} jd_problem;

typedef struct {
    const jd_problem *P;
    long n;
    double *u, *u2, *buf, *L;
    long nfev;
    double fail_t;
    double *fail_x;
    int u_fixed;   /* 1: the inputs are constants, in u for every t (inputs_fix) */
    int u_bad;     /* with u_fixed: one of them is not finite */
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

/* inputs all constant (no table, expression or callback): u set here once for the run,
   instead of at each right-hand side */
static void inputs_fix(jd_ctx *c) {
    const jd_problem *P = c->P;
    if (P->uexpr || P->ucb) return;
    for (long i = 0; i < P->nu; ++i) if (P->u_kind[i] == 1) return;
    inputs_const(P, 0.0, c->u);
    c->u_fixed = 1;
    for (long i = 0; i < P->nu; ++i) if (!isfinite(c->u[i])) c->u_bad = 1;
}

static int inputs(jd_ctx *c, double t, const double *y, const double *yd) {
    const jd_problem *P = c->P;
    if (c->u_fixed) return c->u_bad ? JD_ENAN : 0;
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

/* dx = [yd, M^-1 (q - k), yd.q] with M = L L^T (Cholesky), at x whose every component is
   finite where finite is 1 (the caller checked, as stage_sum does while it writes x), else
   JD_ENAN */
static int rhs_at(jd_ctx *c, double t, const double *x, double *dx, int finite) {
    const jd_problem *P = c->P;
    long f = P->f;
    const double *y = x, *yd = x + f;
    c->nfev++;
    if (!finite || c->u_bad) goto nan;
    if (!c->u_fixed) {
        int r = inputs(c, t, y, yd);
        if (r == JD_ENAN) goto nan;
        if (r) { c->fail_t = t; memcpy(c->fail_x, x, c->n * sizeof(double)); return r; }
    }
    if (P->accel || P->accel_ctx) {
        int r = P->accel ? P->accel(y, yd, t, P->p, c->u, dx + f, dx + 2 * f)
                         : P->accel_ctx(P->ctx, y, yd, t, P->p, c->u, dx + f, dx + 2 * f);
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

/* the same at any x (checked here) */
static int rhs(jd_ctx *c, double t, const double *x, double *dx) {
    return rhs_at(c, t, x, dx, all_finite(c->n, x));
}
