/* The entry points of a recursion engine sized at run time (after runtime_head.h and the
 * engine's text; JD_RT_PLANAR: planar_engine.h, else recursive_engine.h), in the integrator's
 * library: jd_rt_<engine>_fn (M, k, q as the library's jd_fn), _batch, _accel (ÿ by the
 * articulated bodies and the power, as its jd_accel) and _ldl (its jd_accel where the
 * articulated bodies do not apply: jd_fn, then the generated solve, jd_interp_solve), each
 * taking the context (jd_rt) first. Each evaluation takes one allocation (the registers of
 * jd_local's program, its outputs and the work), freed before it returns, as the interpreter's
 * do: one context may serve runs in several threads at once. */
#if JD_RT_PLANAR
#define JD_RT_WORK jd_plane
#define JD_RT_WORK_ARRAYS JD_PLANE_ARRAYS
#define JD_RT_ABA_WORK jd_plane_aba_work
#define JD_RT_ABA_ARRAYS JD_PLANE_ABA_ARRAYS
#define JD_RT_RECURSION jd_plane_recursion
#define JD_RT_PROJECT jd_plane_project
#define JD_RT_POWER jd_plane_power
#define JD_RT_ABA(W, K, ydd) jd_plane_aba(W, K, ydd)
#define JD_RT_NAME(x) jd_rt_plane_##x
#else
#define JD_RT_WORK jd_work
#define JD_RT_WORK_ARRAYS JD_WORK_ARRAYS
#define JD_RT_ABA_WORK jd_aba_work
#define JD_RT_ABA_ARRAYS JD_ABA_ARRAYS
#define JD_RT_RECURSION jd_recursion
#define JD_RT_PROJECT jd_project
#define JD_RT_POWER jd_power
#define JD_RT_ABA(W, K, ydd) jd_aba(W, K, ydd, NULL)
#define JD_RT_NAME(x) jd_rt_spatial_##x
#endif

/* interpreter.h's, in the library's interpreter unit */
void jd_interp_eval(const void *ctx, double *r, const double *y, const double *yd, double t,
                    const double *p, const double *u, double *out);
int jd_interp_solve(long f, long written_out, const double *buf, const double *yd,
                    double *ydd, double *power, double *work);

/* the work's arrays laid out one after the other (their lengths read through W->rt) */
#define JD_RT_BYTES(type, name, n) + sizeof(type) * (size_t)(n)
#define JD_RT_CARVE(type, name, n) JD_RT_TO->name = (type *)m; m += sizeof(type) * (size_t)(n);

static size_t jd_rt_work_bytes(const JD_RT_WORK *W) { return 0 JD_RT_WORK_ARRAYS(JD_RT_BYTES); }
static size_t jd_rt_aba_bytes(const JD_RT_WORK *W) { return 0 JD_RT_ABA_ARRAYS(JD_RT_BYTES); }

static char *jd_rt_carve(JD_RT_WORK *W, char *m) {
#define JD_RT_TO W
    JD_RT_WORK_ARRAYS(JD_RT_CARVE)
#undef JD_RT_TO
    return m;
}

static char *jd_rt_carve_aba(const JD_RT_WORK *W, JD_RT_ABA_WORK *K, char *m) {
#define JD_RT_TO K
    JD_RT_ABA_ARRAYS(JD_RT_CARVE)
#undef JD_RT_TO
    return m;
}

/* one evaluation's memory: the registers r of jd_local's program, its outputs L, W's arrays
   and, with K, the articulated bodies'; NULL where there is none */
static void *jd_rt_alloc(const jd_rt *R, JD_RT_WORK *W, JD_RT_ABA_WORK *K, double **r,
                         double **L) {
    W->rt = R;
    size_t n = sizeof(double) * (size_t)(R->n_reg + R->nl + 1) + jd_rt_work_bytes(W)
               + (K ? jd_rt_aba_bytes(W) : 0);
    char *m = (char *)malloc(n);
    if (!m) return NULL;
    *r = (double *)m;
    *L = *r + R->n_reg;
    char *rest = jd_rt_carve(W, (char *)(*L + R->nl + 1));
    if (K) jd_rt_carve_aba(W, K, rest);
    return m;
}

/* M, k, q: the library's jd_fn */
void JD_RT_NAME(fn)(const void *ctx, const double *y, const double *yd, double t,
                    const double *p, const double *u, double *out) {
    const jd_rt *R = (const jd_rt *)ctx;
    JD_RT_WORK work, *W = &work;
    double *r, *L;
    void *m = jd_rt_alloc(R, W, NULL, &r, &L);
    if (!m) { for (long a = 0; a < (long)R->f * R->f + 2L * R->f; ++a) out[a] = NAN; return; }
    jd_interp_eval(R->local, r, y, yd, t, p, u, L);
    JD_RT_RECURSION(L, yd, W, 0);
    JD_RT_PROJECT(W, out, out + JD_F * JD_F, out + JD_F * JD_F + JD_F);
    free(m);
}

void JD_RT_NAME(batch)(const void *ctx, long n, long f, const double *y, const double *yd,
                       const double *t, const double *p, long p_stride, const double *u,
                       long u_stride, double *out) {
    const jd_rt *R = (const jd_rt *)ctx;
    const long size = (long)R->f * R->f + 2L * R->f;
    for (long i = 0; i < n; ++i)
        JD_RT_NAME(fn)(ctx, y + i * f, yd + i * f, t[i], p + i * p_stride, u + i * u_stride,
                       out + i * size);
}

/* the integrator's right-hand side (jd_problem.accel_ctx) by the articulated bodies: the
   library's jd_accel; 0, 1 (a joint's D not positive definite) or 2 (NaN or inf) */
int JD_RT_NAME(accel)(const void *ctx, const double *y, const double *yd, double t,
                      const double *p, const double *u, double *ydd, double *power) {
    const jd_rt *R = (const jd_rt *)ctx;
    JD_RT_WORK work, *W = &work;
    JD_RT_ABA_WORK aba, *K = &aba;
    double *r, *L;
    void *m = jd_rt_alloc(R, W, K, &r, &L);
    if (!m) return 2;
    jd_interp_eval(R->local, r, y, yd, t, p, u, L);
    JD_RT_RECURSION(L, yd, W, 1);
    *power = JD_RT_POWER(W, yd);
    int status = JD_RT_ABA(W, K, ydd);
    free(m);
    return status;
}

/* the same where the articulated bodies do not apply: M, k, q, then the solve of the library's
   jd_accel (symbolic_accel.ACCEL_TEMPLATE) */
int JD_RT_NAME(ldl)(const void *ctx, const double *y, const double *yd, double t,
                    const double *p, const double *u, double *ydd, double *power) {
    const jd_rt *R = (const jd_rt *)ctx;
    const long f = R->f;
    double *buf = (double *)malloc(sizeof(double) * (size_t)(3 * f * f + 5 * f + 1));
    if (!buf) return 2;
    JD_RT_NAME(fn)(ctx, y, yd, t, p, u, buf);
    int status = jd_interp_solve(f, R->written_out, buf, yd, ydd, power, buf + f * f + 2 * f);
    free(buf);
    return status;
}
