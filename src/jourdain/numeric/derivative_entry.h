/* the entry points of the derivatives' library (derivatives.py): per state and for a batch,
   over jdd_inverse_with / jdd_forward_with of derivative_engine.h or derivative_screw.h */

/* the work of this thread, allocated once (a model's work does not change size); a call per
   state then costs no allocation, where malloc of a large block maps fresh pages every time */
#if defined(__GNUC__) || defined(__clang__)
#define JDD_THREAD __thread
#else
#define JDD_THREAD
#endif
static JDD_THREAD double *jdd_work_of_thread = NULL;
static double *jdd_work(void) {
    if (!jdd_work_of_thread) jdd_work_of_thread = (double *)malloc(sizeof(double) * JDD_WORK);
    return jdd_work_of_thread;
}

/* one state */
int jd_inverse_derivatives(const double *y, const double *yd, const double *ydd, double t,
                           const double *p, const double *u, double *out) {
    double *work = jdd_work();
    if (!work) return 3;
    return jdd_inverse_with(y, yd, ydd, t, p, u, out, work);
}

int jd_forward_derivatives(const double *y, const double *yd, double t, const double *p,
                           const double *u, double *out) {
    double *work = jdd_work();
    if (!work) return 3;
    return jdd_forward_with(y, yd, t, p, u, out, work);
}

/* n states one after the other; p and u advance by their stride (0: shared); returns -1, or
   the first state that failed (its status in *status) */
long jd_inverse_derivatives_batch(long n, const double *y, const double *yd, const double *ydd,
                                  const double *t, const double *p, long ps, const double *u,
                                  long us, double *out, int *status) {
    const long size = JDD_F + 3L * JDD_F * JDD_F + (long)JDD_F * JDD_NU;
    double *work = jdd_work();
    if (!work) { *status = 3; return 0; }
    for (long i = 0; i < n; ++i) {
        int s = jdd_inverse_with(y + i * JDD_F, yd + i * JDD_F, ydd + i * JDD_F, t[i],
                                 p + i * ps, u + i * us, out + i * size, work);
        if (s) { *status = s; return i; }
    }
    return -1;
}

long jd_forward_derivatives_batch(long n, const double *y, const double *yd, const double *t,
                                  const double *p, long ps, const double *u, long us,
                                  double *out, int *status) {
    const long size = JDD_F + 2L * JDD_F * JDD_F + (long)JDD_F * JDD_NU;
    double *work = jdd_work();
    if (!work) { *status = 3; return 0; }
    for (long i = 0; i < n; ++i) {
        int s = jdd_forward_with(y + i * JDD_F, yd + i * JDD_F, t[i], p + i * ps, u + i * us,
                                 out + i * size, work);
        if (s) { *status = s; return i; }
    }
    return -1;
}
