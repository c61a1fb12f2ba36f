/* FMI adapter of jourdain's kernel for velocity constraints (jourdain.io.fmu, a system with
   contacts whose speeds are rates of independent coordinates).

   jd_loop.c is the generated jd_gpos (Φ, Φ_y, Φ_t of the holonomic rows), jd_gvel (A, a of
   every row) and jd_gacc (their c), dense_c.h and the hand-written kernel general_c.h of
   jourdain.loops (Newton on the holonomic rows, W = [E_z; A] by LU, ẏ = L·z + l, γ, M_z = LᵀM_tree·L by Cholesky) and this
   file, which runs the kernel in the partition fixed at export (model.h: jd_ind, jd_dep,
   jd_rows, jd_rows_v, jd_spd) with the tree's compiled M, k, q (jd_fn of jd_engine.c). It
   gives the interface of closed.c (model.h defines JD_CLOSED): the states are the independent
   coordinates and their rates; the rates of those without a speed follow ẏ = L·z + l to the
   importer's integration accuracy. info: [cond (not used: 0), Newton steps, reason, |Φ|]. */
#include "model.h"

void jd_fn(const double *y, const double *yd, double t, const double *p, const double *u,
           double *out);

long jd_closed_work(void) { return jd_gen_work(JD_NZ, JD_NPOS, JD_NPHI, JD_NSPD) + JD_NZ + 16; }

/* ÿ (JD_NY) of the independent coordinates y with rates yd, and out = [dependent coordinates
   (JD_NDEP), their rates (JD_NDEP), every row's residual (JD_NPHI: Φ of the holonomic rows,
   A·ẏ + a of the velocity rows)]. Returns 0; 2: not finite; 11 Newton found no configuration,
   15 W singular (the velocity rows and the speeds), 13 M in the speeds not positive definite. */
int jd_closed_dynamics(double *z, double *y_last, double *info, double *work, long *piv,
                       const double *y, const double *yd, double t, const double *p,
                       const double *u, double *ydd, double *out) {
    jd_gen G;
    double gi[4] = {0.0, 0.0, 0.0, 0.0};
    double *ydf, *L, *gam, *tree, *zd, *vel;
    (void)y_last;
    (void)piv;
    memset(&G, 0, sizeof G);
    G.tree = jd_fn;
    G.p = p;
    G.n = JD_NZ;
    G.ni = JD_NY;
    G.g = JD_NSPD;
    G.mh = JD_NPOS;
    G.mv = JD_NPHI;
    G.rh = JD_NDEP;
    G.ind = jd_ind;
    G.dep = jd_dep;
    G.rows_h = jd_rows;
    G.rows_v = jd_rows_v;
    G.spd = jd_spd;
    G.y = z;
    G.piv = (long *)(void *)work;
    G.work = work + JD_NZ + 8;
    G.info = gi;
    G.newton_tol = JD_NEWTON_TOL;
    G.max_newton = JD_MAX_NEWTON;
    int r = jdg_state(&G, y, yd, t, u, &ydf, &L, &gam, &tree, &zd, &vel);
    info[0] = 0.0;
    info[1] = gi[0];
    info[2] = gi[1];
    info[3] = gi[2];
    if (r == 1) return isfinite(gi[2]) ? 11 : 2;
    if (r == 2) return 15;
    if (r == 3) return 13;
    jdg_ydd(&G, L, gam, zd, jd_ind, JD_NY, ydd);
    for (long k = 0; k < JD_NY; ++k)
        if (!isfinite(ydd[k])) return 2;
    for (long i = 0; i < JD_NDEP; ++i) {
        out[i] = z[jd_dep[i]];
        out[JD_NDEP + i] = ydf[jd_dep[i]];
    }
    {   /* the rows' residuals: Φ at the configuration solved, then A·ẏ + a */
        double *pos = work + JD_NZ + 8;
        double zero[JD_NZ];
        memset(zero, 0, sizeof zero);
        jd_gpos(z, zero, t, p, u, pos);
        for (long i = 0; i < JD_NPHI; ++i) {
            double v;
            if (i < JD_NPOS) {
                v = pos[i];
            } else {
                v = vel[JD_NPHI * JD_NZ + i];
                for (long j = 0; j < JD_NZ; ++j) v += vel[i * JD_NZ + j] * ydf[j];
            }
            out[2 * JD_NDEP + i] = v;
            if (!isfinite(v)) return 2;
        }
    }
    return 0;
}
