/* FMI adapter of jourdain's closed-loop kernel (jourdain.io.fmu, a system with closing joints).

   jd_loop.c is the generated jd_con (Φ, Φ_z, Φ_t) and jd_gam (the convective term c), the
   hand-written kernel loop_c.h of jourdain.loops (Newton on Φ(y, d, t) = 0 for the dependent
   coordinates d, the LU of Φ_d and its condition number, J_z, M = J_zᵀ M_tree J_z, ÿ by
   Cholesky) and this file, which runs the kernel in the partition fixed at export (model.h:
   jd_ind, jd_dep, jd_rows) with the tree's compiled M, k, q (jd_fn of jd_engine.c). The
   instance keeps the kernel's state (the last configuration solved: Newton's start, its
   independent coordinates and the kernel's info) in plain numbers, so that fmi2GetFMUstate
   saves it. */
#include "model.h"

void jd_fn(const double *y, const double *yd, double t, const double *p, const double *u,
           double *out);

/* doubles of the kernel's work array */
long jd_closed_work(void) { return jd_loop_work(JD_NZ, JD_NPHI, JD_NY); }

/* ÿ (JD_NY) of the independent coordinates y with rates yd, and out = [dependent coordinates
   (JD_NDEP), their rates (JD_NDEP), Φ (JD_NPHI, every closing row)] at that state. Returns 0;
   2: not finite; 10 + the kernel's reason (info[2]): 11 Newton found no configuration, 12 the
   condition number of Φ_d (info[0]) passed JD_COND_LIMIT, 13 M not positive definite, 14 a
   branch jump. z, y_last, info: the kernel's state (Newton's start and the prediction). */
int jd_closed_dynamics(double *z, double *y_last, double *info, double *work, long *piv,
                       const double *y, const double *yd, double t, const double *p,
                       const double *u, double *ydd, double *out) {
    jd_loop L;
    jdl_parts s;
    double power = 0.0;
    int status;
    memset(&L, 0, sizeof L);
    L.tree = jd_fn;
    L.p = p;
    L.n = JD_NZ;
    L.m = JD_NPHI;
    L.f = JD_NY;
    L.r = JD_NDEP;
    L.ind = jd_ind;
    L.dep = jd_dep;
    L.rows = jd_rows;
    L.z = z;
    L.y_last = y_last;
    L.work = work;
    L.piv = piv;
    L.info = info;
    L.newton_tol = JD_NEWTON_TOL;
    L.cond_limit = JD_COND_LIMIT;
    L.max_newton = JD_MAX_NEWTON;
    L.uexpr = NULL;
    L.u_buf = NULL;
    status = jd_loop_accel(y, yd, t, (const double *)(const void *)&L, u, ydd, &power);
    if (status == 1) return 10 + (int)info[2];
    if (status) return status;
    s = jdl_carve(&L);
    for (long i = 0; i < JD_NDEP; ++i) {
        out[i] = z[jd_dep[i]];
        out[JD_NDEP + i] = s.zd[jd_dep[i]];
    }
    jd_con(z, s.zd, t, p, u, s.con);  /* Φ at the configuration solved, every row */
    for (long i = 0; i < JD_NPHI; ++i) {
        out[2 * JD_NDEP + i] = s.con[i];
        if (!isfinite(s.con[i])) return 2;
    }
    return 0;
}
