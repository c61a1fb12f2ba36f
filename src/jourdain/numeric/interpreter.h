/* jourdain's interpreter of generated code (numeric/interpreter.py): a model's M, k, q and
 * its ÿ = M⁻¹(q − k) evaluated from a list of operations instead of compiled code, for the
 * first run of a model whose library is still being compiled (in a thread).
 *
 * Every operation is the one C operation of the generated source that it stands for, on the
 * same operands in the same order (the program is read from that source: sums and products
 * left to right, jd_sq, jd_cube, jd_powi, jd_sign and jd_sincos_n from the same header), and
 * the solve is the generated one's: right-looking LDLᵀ (integrator_ldl.py) up to
 * JD_WRITTEN_OUT_MAX_F, else ldl_solve.h itself. No operation is reassociated or contracted
 * (-ffp-contract=off, no -ffast-math), so the numbers are those of the compiled library to
 * the bit, and a run may switch from one to the other between two calls.
 *
 * The unit (integrator_c.UNITS) is jd_inline.h, sincos.h, ldl_solve.h with the size a
 * parameter (jd_solve_loop) and this file. */
#include <string.h>

enum {
    JI_ADD, JI_SUB, JI_MUL, JI_DIV, JI_NEG, JI_SQ, JI_CUBE, JI_POWI, JI_SQRT, JI_FN1,
    JI_ATAN2, JI_POW, JI_FMAX, JI_FMIN, JI_SINCOS, JI_STORE, JI_COPY
};
/* the functions of one argument (JI_FN1's last operand), in interpreter.py's order */
enum {
    JF_SIN, JF_COS, JF_TAN, JF_ASIN, JF_ACOS, JF_ATAN, JF_EXP, JF_LOG, JF_SINH, JF_COSH,
    JF_TANH, JF_ASINH, JF_ACOSH, JF_ATANH, JF_FABS, JF_SIGN, JF_FLOOR, JF_CEIL, JF_ERF
};

typedef struct {
    long f, n_p, n_u;
    long n_reg, n_const, n_ops, n_out, n_mirror;
    long in_y, in_yd, in_t, in_p, in_u;  /* the registers of the arguments */
    long written_out;                     /* the solve written out (f ≤ 10) or the loop */
    const double *consts;                 /* n_const: registers 0 … n_const − 1 */
    const int *ops;                       /* 4 per operation: code, destination, a, b */
    const long *mirror;                   /* n_mirror pairs: out[dst] = out[src] */
} jd_interp;

static double jd_fn1(int which, double x) {
    switch (which) {
    case JF_SIN: return sin(x);
    case JF_COS: return cos(x);
    case JF_TAN: return tan(x);
    case JF_ASIN: return asin(x);
    case JF_ACOS: return acos(x);
    case JF_ATAN: return atan(x);
    case JF_EXP: return exp(x);
    case JF_LOG: return log(x);
    case JF_SINH: return sinh(x);
    case JF_COSH: return cosh(x);
    case JF_TANH: return tanh(x);
    case JF_ASINH: return asinh(x);
    case JF_ACOSH: return acosh(x);
    case JF_ATANH: return atanh(x);
    case JF_FABS: return fabs(x);
    case JF_SIGN: return jd_sign(x);
    case JF_FLOOR: return floor(x);
    case JF_CEIL: return ceil(x);
    default: return erf(x);
    }
}

/* the program on one state: the outputs it writes (the mirrors are the caller's) */
static void jd_interp_run(const jd_interp *P, double *r, const double *y, const double *yd,
                          double t, const double *p, const double *u, double *out) {
    memcpy(r, P->consts, sizeof(double) * P->n_const);
    memcpy(r + P->in_y, y, sizeof(double) * P->f);
    memcpy(r + P->in_yd, yd, sizeof(double) * P->f);
    r[P->in_t] = t;
    if (P->n_p) memcpy(r + P->in_p, p, sizeof(double) * P->n_p);
    if (P->n_u) memcpy(r + P->in_u, u, sizeof(double) * P->n_u);
    const int *o = P->ops, *end = P->ops + 4 * P->n_ops;
    for (; o < end; o += 4) {
        const double a = r[o[2]];
        switch (o[0]) {
        case JI_ADD: r[o[1]] = a + r[o[3]]; break;
        case JI_SUB: r[o[1]] = a - r[o[3]]; break;
        case JI_MUL: r[o[1]] = a * r[o[3]]; break;
        case JI_DIV: r[o[1]] = a / r[o[3]]; break;
        case JI_NEG: r[o[1]] = -a; break;
        case JI_SQ: r[o[1]] = jd_sq(a); break;
        case JI_CUBE: r[o[1]] = jd_cube(a); break;
        case JI_POWI: r[o[1]] = jd_powi(a, o[3]); break;
        case JI_SQRT: r[o[1]] = sqrt(a); break;
        case JI_FN1: r[o[1]] = jd_fn1(o[3], a); break;
        case JI_ATAN2: r[o[1]] = atan2(a, r[o[3]]); break;
        case JI_POW: r[o[1]] = pow(a, r[o[3]]); break;
        case JI_FMAX: r[o[1]] = fmax(a, r[o[3]]); break;
        case JI_FMIN: r[o[1]] = fmin(a, r[o[3]]); break;
        case JI_SINCOS: jd_sincos_n(r + o[2], o[3], r + o[1], r + o[1] + o[3]); break;
        case JI_STORE: out[o[1]] = a; break;
        default: r[o[1]] = a; break;  /* JI_COPY */
        }
    }
}

/* ÿ = M⁻¹(q − k) as integrator_ldl.ldl_source(f) writes it out: the same operations on the
   same operands (a: the lower triangle of M, overwritten; l, rinv, b, x: f each) */
static int jd_solve_written(const long f, const double *M, const double *k, const double *q,
                            double *ydd, double *a, double *l, double *rinv, double *b,
                            double *x) {
    double dmax = 0.0;
    for (long i = 0; i < f; ++i)
        for (long j = 0; j <= i; ++j) a[i * f + j] = M[j * f + i];
    for (long i = 0; i < f; ++i) { double t_ = fabs(a[i * f + i]); dmax = t_ > dmax ? t_ : dmax; }
    for (long i = 0; i < f; ++i) b[i] = q[i] - k[i];
    const double tiny = 1e-13 * dmax;
    for (long j = 0; j < f; ++j) {
        const double d = a[j * f + j];
        if (!(d > tiny)) return isfinite(d) ? 1 : 2;
        rinv[j] = 1.0 / d;
        for (long m = j + 1; m < f; ++m) l[m * f + j] = a[m * f + j] * rinv[j];
        for (long m = j + 1; m < f; ++m)
            for (long i = m; i < f; ++i) a[i * f + m] -= a[i * f + j] * l[m * f + j];
        for (long i = j + 1; i < f; ++i) b[i] -= l[i * f + j] * b[j];
    }
    int finite = 1;
    for (long i = f - 1; i >= 0; --i) {
        double s = b[i] * rinv[i];
        for (long m = f - 1; m > i; --m) s = s - l[m * f + i] * x[m];
        x[i] = s;
        ydd[i] = s;
        finite = finite && isfinite(s);
    }
    return finite ? 0 : 2;
}

/* the work of one evaluation: registers, then M, k, q, then the solve's */
static double *jd_interp_work(const jd_interp *P) {
    long f = P->f;
    return (double *)malloc(sizeof(double) * (P->n_reg + P->n_out + 3 * f * f + 4 * f + 1));
}

/* M, k, q (all outputs, the mirrors copied), as the library's jd_fn */
void jd_interp_fn(const jd_interp *P, const double *y, const double *yd, double t,
                  const double *p, const double *u, double *out) {
    double *r = (double *)malloc(sizeof(double) * (P->n_reg > 0 ? P->n_reg : 1));
    if (!r) { for (long i = 0; i < P->n_out; ++i) out[i] = NAN; return; }
    jd_interp_run(P, r, y, yd, t, p, u, out);
    for (long i = 0; i < P->n_mirror; ++i) out[P->mirror[2 * i]] = out[P->mirror[2 * i + 1]];
    free(r);
}

void jd_interp_batch(const jd_interp *P, long n, long f, const double *y, const double *yd,
                     const double *t, const double *p, long p_stride, const double *u,
                     long u_stride, double *out) {
    for (long i = 0; i < n; ++i)
        jd_interp_fn(P, y + i * f, yd + i * f, t[i], p + i * p_stride, u + i * u_stride,
                     out + i * P->n_out);
}

/* the program on one state into out, the mirrors copied (r: its n_reg registers): the
   runtime-sized engines' jd_local (runtime_engine.h) */
void jd_interp_eval(const void *ctx, double *r, const double *y, const double *yd, double t,
                    const double *p, const double *u, double *out) {
    const jd_interp *P = (const jd_interp *)ctx;
    jd_interp_run(P, r, y, yd, t, p, u, out);
    for (long i = 0; i < P->n_mirror; ++i) out[P->mirror[2 * i]] = out[P->mirror[2 * i + 1]];
}

/* the generated jd_accel's power ẏᵀq and solve ÿ = M⁻¹(q − k) from buf = [M (its upper
   triangle and diagonal read), k, q], written out or the loop (work: 2f² + 3f): 0, 1 (M not
   positive definite) or 2 (NaN or inf); also the runtime-sized engines' where the
   articulated bodies do not apply */
int jd_interp_solve(long f, long written_out, const double *buf, const double *yd,
                    double *ydd, double *power, double *work) {
    const double *M = buf, *k = buf + f * f, *q = k + f;
    double w = 0.0;
    for (long i = 0; i < f; ++i) w += yd[i] * q[i];
    *power = w;
    return written_out
        ? jd_solve_written(f, M, k, q, ydd, work, work + f * f, work + 2 * f * f,
                           work + 2 * f * f + f, work + 2 * f * f + 2 * f)
        : jd_solve_loop(f, M, k, q, ydd, work);
}

/* the integrator's right-hand side (jd_problem.accel_ctx), as the library's jd_accel:
   0, 1 (M not positive definite) or 2 (NaN or inf) */
int jd_interp_accel(const void *ctx, const double *y, const double *yd, double t,
                    const double *p, const double *u, double *ydd, double *power) {
    const jd_interp *P = (const jd_interp *)ctx;
    double *r = jd_interp_work(P);
    if (!r) return 2;
    double *buf = r + P->n_reg, *work = buf + P->n_out;
    jd_interp_run(P, r, y, yd, t, p, u, buf);  /* M's upper triangle and diagonal, k, q */
    int status = jd_interp_solve(P->f, P->written_out, buf, yd, ydd, power, work);
    free(r);
    return status;
}
