/* The first derivatives of the inverse dynamics tau = M*ydd + k - q of a tree (derivatives.py):
   the kinematic recursion of recursive_engine.h run in forward mode, with prefix tangents.

   Every quantity of body i carries its derivatives with respect to the variables its value
   depends on, in two blocks: the coordinates y (block 0) and the rates and inputs (block 1:
   ydot_j is variable j, u_k is variable f + k). Body i's variables are its parent's, in the
   same order, followed by those its joint's and its own local expressions bring in (the
   tables jdd_vars_*): so the derivatives of a parent's quantity are a prefix of its child's,
   and a step that combines them is a loop over that prefix. A tangent array of r rows holds
   row a's derivative with respect to the body's variable k at [a*n + k].

   Backward, the wrench W^c_i of each sub-tree (about the inertial origin) keeps the prefix of
   body i's variables; the derivatives with respect to a variable that a body b brings in are
   complete once W^c_b is, and reach every column above b as V^T dW^c_b (the sub-trees of the
   bodies that bring in one variable are disjoint: no derivative is counted twice).

   Local expressions (generated jdd_parts): per body the 40 numbers of recursive.py's layout
   (A 9, d 3, omega_bar 3, v_bar 3, alpha_bar 3, a_bar 3, m, com 3, I 6, f 3, l 3), per column
   J_R 3, J_T 3, then their nonzero first derivatives, which jdd_spread_at puts in place. */

typedef struct { double *x; double *d[2]; int n[2]; } jdd_t;
#define JDD_BODY_ROWS 40
#include <string.h>

#if defined(__GNUC__)
#define JDD_INLINE static inline __attribute__((always_inline))
#else
#define JDD_INLINE static inline
#endif

/* r = A x or Aᵀ x (A 3x3 row-major). Each block's loop runs over the variables once, the
   3x3 product inside; tangents shorter than r's count as zero beyond their end */
JDD_INLINE void jdd_mv(jdd_t A, jdd_t x, jdd_t r, int transpose) {
    int e[9];
    for (int a = 0; a < 3; ++a)
        for (int s = 0; s < 3; ++s) e[3 * a + s] = transpose ? 3 * s + a : 3 * a + s;
    double E[9], v[3];
    for (int k = 0; k < 9; ++k) E[k] = A.x[e[k]];
    const double x0 = x.x[0], x1 = x.x[1], x2 = x.x[2];
    for (int a = 0; a < 3; ++a) v[a] = E[3 * a] * x0 + E[3 * a + 1] * x1 + E[3 * a + 2] * x2;
    for (int b = 0; b < 2; ++b) {
        const int n = r.n[b];
        if (!n) continue;
        const int sa = A.n[b], sx = x.n[b], na = sa < n ? sa : n, nx = sx < n ? sx : n;
        double *o0 = r.d[b], *o1 = o0 + n, *o2 = o1 + n;
        const double *dA = A.d[b], *dx0 = x.d[b], *dx1 = dx0 + sx, *dx2 = dx1 + sx;
        const double *a0 = dA + e[0] * sa, *a1 = dA + e[1] * sa, *a2 = dA + e[2] * sa;
        const double *a3 = dA + e[3] * sa, *a4 = dA + e[4] * sa, *a5 = dA + e[5] * sa;
        const double *a6 = dA + e[6] * sa, *a7 = dA + e[7] * sa, *a8 = dA + e[8] * sa;
        const int m = na < nx ? na : nx;
        int k = 0;
        for (; k < m; ++k) {
            const double p0 = dx0[k], p1 = dx1[k], p2 = dx2[k];
            o0[k] = a0[k] * x0 + a1[k] * x1 + a2[k] * x2 + E[0] * p0 + E[1] * p1 + E[2] * p2;
            o1[k] = a3[k] * x0 + a4[k] * x1 + a5[k] * x2 + E[3] * p0 + E[4] * p1 + E[5] * p2;
            o2[k] = a6[k] * x0 + a7[k] * x1 + a8[k] * x2 + E[6] * p0 + E[7] * p1 + E[8] * p2;
        }
        for (; k < na; ++k) {
            o0[k] = a0[k] * x0 + a1[k] * x1 + a2[k] * x2;
            o1[k] = a3[k] * x0 + a4[k] * x1 + a5[k] * x2;
            o2[k] = a6[k] * x0 + a7[k] * x1 + a8[k] * x2;
        }
        for (; k < nx; ++k) {
            const double p0 = dx0[k], p1 = dx1[k], p2 = dx2[k];
            o0[k] = E[0] * p0 + E[1] * p1 + E[2] * p2;
            o1[k] = E[3] * p0 + E[4] * p1 + E[5] * p2;
            o2[k] = E[6] * p0 + E[7] * p1 + E[8] * p2;
        }
        for (; k < n; ++k) { o0[k] = 0.0; o1[k] = 0.0; o2[k] = 0.0; }
    }
    r.x[0] = v[0]; r.x[1] = v[1]; r.x[2] = v[2];
}

/* r = A B (3x3): column by column, r e_c = A (B e_c) */
JDD_INLINE void jdd_mm(jdd_t A, jdd_t B, jdd_t r) {
    double v[9];
    for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c)
            v[3 * a + c] = A.x[3 * a] * B.x[c] + A.x[3 * a + 1] * B.x[3 + c]
                           + A.x[3 * a + 2] * B.x[6 + c];
    for (int b = 0; b < 2; ++b) {
        const int n = r.n[b];
        if (!n) continue;
        const int sa = A.n[b], sb = B.n[b], na = sa < n ? sa : n, nb = sb < n ? sb : n;
        for (int a = 0; a < 3; ++a)
            for (int c = 0; c < 3; ++c) {
                double *o = r.d[b] + (3 * a + c) * n;
                const double A0 = A.x[3 * a], A1 = A.x[3 * a + 1], A2 = A.x[3 * a + 2];
                const double B0 = B.x[c], B1 = B.x[3 + c], B2 = B.x[6 + c];
                const double *dA0 = A.d[b] + (3 * a) * sa, *dA1 = dA0 + sa, *dA2 = dA1 + sa;
                const double *dB0 = B.d[b] + c * sb, *dB1 = dB0 + 3 * sb, *dB2 = dB1 + 3 * sb;
                const int m = na < nb ? na : nb;
                int k = 0;
                for (; k < m; ++k)
                    o[k] = dA0[k] * B0 + dA1[k] * B1 + dA2[k] * B2
                           + A0 * dB0[k] + A1 * dB1[k] + A2 * dB2[k];
                for (; k < na; ++k) o[k] = dA0[k] * B0 + dA1[k] * B1 + dA2[k] * B2;
                for (; k < nb; ++k) o[k] = A0 * dB0[k] + A1 * dB1[k] + A2 * dB2[k];
                for (; k < n; ++k) o[k] = 0.0;
            }
    }
    for (int a = 0; a < 9; ++a) r.x[a] = v[a];
}

/* r = x × y */
JDD_INLINE void jdd_cross(jdd_t x, jdd_t y, jdd_t r) {
    const double x0 = x.x[0], x1 = x.x[1], x2 = x.x[2], y0 = y.x[0], y1 = y.x[1], y2 = y.x[2];
    for (int b = 0; b < 2; ++b) {
        const int n = r.n[b];
        if (!n) continue;
        const int sx = x.n[b], sy = y.n[b], nx = sx < n ? sx : n, ny = sy < n ? sy : n;
        double *o0 = r.d[b], *o1 = o0 + n, *o2 = o1 + n;
        const double *dx0 = x.d[b], *dx1 = dx0 + sx, *dx2 = dx1 + sx;
        const double *dy0 = y.d[b], *dy1 = dy0 + sy, *dy2 = dy1 + sy;
        const int m = nx < ny ? nx : ny;
        int k = 0;
        for (; k < m; ++k) {
            o0[k] = dx1[k] * y2 - dx2[k] * y1 + x1 * dy2[k] - x2 * dy1[k];
            o1[k] = dx2[k] * y0 - dx0[k] * y2 + x2 * dy0[k] - x0 * dy2[k];
            o2[k] = dx0[k] * y1 - dx1[k] * y0 + x0 * dy1[k] - x1 * dy0[k];
        }
        for (; k < nx; ++k) {
            o0[k] = dx1[k] * y2 - dx2[k] * y1;
            o1[k] = dx2[k] * y0 - dx0[k] * y2;
            o2[k] = dx0[k] * y1 - dx1[k] * y0;
        }
        for (; k < ny; ++k) {
            o0[k] = x1 * dy2[k] - x2 * dy1[k];
            o1[k] = x2 * dy0[k] - x0 * dy2[k];
            o2[k] = x0 * dy1[k] - x1 * dy0[k];
        }
        for (; k < n; ++k) { o0[k] = 0.0; o1[k] = 0.0; o2[k] = 0.0; }
    }
    r.x[0] = x1 * y2 - x2 * y1; r.x[1] = x2 * y0 - x0 * y2; r.x[2] = x0 * y1 - x1 * y0;
}

/* r += c x (c a number), r's tangents at least as long as x's */
JDD_INLINE void jdd_axpy(double c, jdd_t x, jdd_t r, int rows) {
    for (int a = 0; a < rows; ++a) r.x[a] += c * x.x[a];
    for (int b = 0; b < 2; ++b) {
        int n = r.n[b], nx = x.n[b], m = nx < n ? nx : n;
        for (int a = 0; a < rows; ++a) {
            double *o = r.d[b] + a * n;
            const double *dx = x.d[b] + a * nx;
            for (int k = 0; k < m; ++k) o[k] += c * dx[k];
        }
    }
}

/* r = x (r's tangents at least as long; the rest zero) */
JDD_INLINE void jdd_copy(jdd_t x, jdd_t r, int rows) {
    for (int a = 0; a < rows; ++a) r.x[a] = x.x[a];
    for (int b = 0; b < 2; ++b) {
        int n = r.n[b], nx = x.n[b], m = nx < n ? nx : n;
        for (int a = 0; a < rows; ++a) {
            double *o = r.d[b] + a * n;
            const double *dx = x.d[b] + a * nx;
            for (int k = 0; k < m; ++k) o[k] = dx[k];
            for (int k = m; k < n; ++k) o[k] = 0.0;
        }
    }
}

/* the quantities of one body: values in x, tangents in the work array (offsets jdd_off) */
enum { JQ_R, JQ_O, JQ_W, JQ_V, JQ_AL, JQ_A, JQ_P, JQ_CC, JQ_WC, JQ_PARTS, JQ_COLS, JQ_VCOLS,
       JQ_N };

JDD_INLINE jdd_t jdd_at(double *X, double *D, int i, int q, int row0) {
    const int *o = jdd_off + 2 * (JQ_N * i + q);
    int ny = jdd_ny[i], nv = jdd_nv[i];
    int val = jdd_val[JQ_N * i + q];
    jdd_t t = {X + val + row0, {D + o[0] + row0 * ny, D + o[1] + row0 * nv}, {ny, nv}};
    if (o[0] < 0) { t.d[0] = D; t.n[0] = 0; }
    if (o[1] < 0) { t.d[1] = D; t.n[1] = 0; }
    if (q == JQ_PARTS || q == JQ_COLS) {  /* a local expression without derivatives: none */
        int live = jdd_live[jdd_live_start[i] + (q == JQ_COLS ? JDD_BODY_ROWS : 0) + row0];
        if (!(live & 1)) t.n[0] = 0;
        if (!(live & 2)) t.n[1] = 0;
    }
    return t;
}

/* a temporary of one body: tangents in scratch */
JDD_INLINE jdd_t jdd_tmp(double *x, double *scratch, int i, int rows, int with_rates) {
    int ny = jdd_ny[i], nv = with_rates ? jdd_nv[i] : 0;
    jdd_t t = {x, {scratch, scratch + rows * ny}, {ny, nv}};
    return t;
}

static const double jdd_I3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, jdd_Z6[6] = {0, 0, 0, 0, 0, 0};

/* the inverse dynamics tau (f) and its derivatives tau_y (f*f), tau_yd (f*f), tau_u (f*nu) */
static int jdd_inverse(const double *y, const double *yd, const double *ydd, double t,
                       const double *p, const double *u, double *tau, double *tau_y,
                       double *tau_yd, double *tau_u, double *X, double *D) {
    double *L = X + JDD_NVAL;  /* the local expressions, then their derivatives */
    jdd_parts(y, yd, t, p, u, L);
    for (int g = 0; g < JDD_NZERO; ++g) memset(D + jdd_zero_off[g], 0, sizeof(double) * jdd_zero_len[g]);
    for (long m = 0; m < JDD_NPD; ++m) D[jdd_pd_dst[m]] = L[JDD_NL + m];
    double scratch[JDD_SCRATCH];
    for (int i = 0; i < JDD_P; ++i) {
        int lam = jdd_parent[i];
        const double *Lb = L + 40 * i;
        jdd_t A = jdd_at(X, D, i, JQ_PARTS, 0), d = jdd_at(X, D, i, JQ_PARTS, 9);
        jdd_t wb = jdd_at(X, D, i, JQ_PARTS, 12), vb = jdd_at(X, D, i, JQ_PARTS, 15);
        jdd_t abr = jdd_at(X, D, i, JQ_PARTS, 18), abl = jdd_at(X, D, i, JQ_PARTS, 21);
        jdd_t com = jdd_at(X, D, i, JQ_PARTS, 25);
        jdd_t fe = jdd_at(X, D, i, JQ_PARTS, 34), le = jdd_at(X, D, i, JQ_PARTS, 37);
        const double m = Lb[24], *In = Lb + 28;
        jdd_t world = {(double *)jdd_I3, {D, D}, {0, 0}}, zero = {(double *)jdd_Z6, {D, D}, {0, 0}};
        jdd_t Rl = lam < 0 ? world : jdd_at(X, D, lam, JQ_R, 0);
        jdd_t ol = lam < 0 ? zero : jdd_at(X, D, lam, JQ_O, 0);
        jdd_t wl = lam < 0 ? zero : jdd_at(X, D, lam, JQ_W, 0);
        jdd_t vl = lam < 0 ? zero : jdd_at(X, D, lam, JQ_V, 0);
        jdd_t all = lam < 0 ? zero : jdd_at(X, D, lam, JQ_AL, 0);
        jdd_t al_ = lam < 0 ? zero : jdd_at(X, D, lam, JQ_A, 0);
        jdd_t Pl = lam < 0 ? zero : jdd_at(X, D, lam, JQ_P, 0);
        jdd_t R = jdd_at(X, D, i, JQ_R, 0), o = jdd_at(X, D, i, JQ_O, 0);
        jdd_t w = jdd_at(X, D, i, JQ_W, 0), v = jdd_at(X, D, i, JQ_V, 0);
        jdd_t al = jdd_at(X, D, i, JQ_AL, 0), a = jdd_at(X, D, i, JQ_A, 0);
        jdd_t P = jdd_at(X, D, i, JQ_P, 0), cc = jdd_at(X, D, i, JQ_CC, 0);
        /* temporaries: values t*, tangents in scratch (3 rows, both blocks: 3*(ny+nv)) */
        double tv[12][3];
        int span = 3 * (jdd_ny[i] + jdd_nv[i]);
        jdd_t T[12];
        for (int k = 0; k < 12; ++k) T[k] = jdd_tmp(tv[k], scratch + k * span, i, 3, 1);
        jdd_mm(Rl, A, R);
        jdd_mv(Rl, d, T[0], 0);                        /* dw = S_λ d */
        jdd_copy(ol, o, 3); jdd_axpy(1.0, T[0], o, 3);  /* r_O = r_O,λ + dw */
        jdd_copy(wb, T[1], 3); jdd_copy(vb, T[2], 3);   /* rho, dd */
        for (int c = jdd_col_start[i]; c < jdd_col_start[i + 1]; ++c) {
            int j = jdd_col_coord[c], kv = jdd_col_rate[c];
            jdd_t JR = jdd_at(X, D, i, JQ_COLS, 6 * (c - jdd_col_start[i]));
            jdd_t JT = jdd_at(X, D, i, JQ_COLS, 6 * (c - jdd_col_start[i]) + 3);
            jdd_axpy(yd[j], JR, T[1], 3);
            jdd_axpy(yd[j], JT, T[2], 3);
            for (int s = 0; s < 3; ++s) {  /* ∂/∂ẏ_j of J·ẏ_j */
                T[1].d[1][s * T[1].n[1] + kv] += JR.x[s];
                T[2].d[1][s * T[2].n[1] + kv] += JT.x[s];
            }
        }
        jdd_mv(R, T[1], T[3], 0);                       /* rhow = S ρ */
        jdd_mv(Rl, T[2], T[4], 0);                      /* ddw = S_λ dd */
        jdd_cross(wl, T[0], T[5]);                      /* ω_λ × dw */
        jdd_cross(wl, T[3], T[6]);                      /* ω_λ × rhow */
        jdd_copy(wl, w, 3); jdd_axpy(1.0, T[3], w, 3);
        jdd_copy(vl, v, 3); jdd_axpy(1.0, T[5], v, 3); jdd_axpy(1.0, T[4], v, 3);
        jdd_mv(R, abr, T[7], 0);
        jdd_copy(all, al, 3); jdd_axpy(1.0, T[6], al, 3); jdd_axpy(1.0, T[7], al, 3);
        jdd_cross(all, T[0], T[8]);                     /* α_λ × dw */
        jdd_cross(wl, T[5], T[9]);                      /* ω_λ × (ω_λ × dw) */
        jdd_cross(wl, T[4], T[10]);                     /* ω_λ × ddw */
        jdd_mv(Rl, abl, T[11], 0);
        jdd_copy(al_, a, 3);
        jdd_axpy(1.0, T[8], a, 3); jdd_axpy(1.0, T[9], a, 3);
        jdd_axpy(2.0, T[10], a, 3); jdd_axpy(1.0, T[11], a, 3);
        /* twist columns about the origin, and the ÿ part of the acceleration P = P_λ + Σ V ÿ */
        jdd_copy(Pl, P, 6);
        for (int c = jdd_col_start[i]; c < jdd_col_start[i + 1]; ++c) {
            int cl = c - jdd_col_start[i];
            jdd_t JR = jdd_at(X, D, i, JQ_COLS, 6 * cl), JT = jdd_at(X, D, i, JQ_COLS, 6 * cl + 3);
            jdd_t Vw = jdd_at(X, D, i, JQ_VCOLS, 6 * cl), Vu = jdd_at(X, D, i, JQ_VCOLS, 6 * cl + 3);
            jdd_mv(R, JR, Vw, 0);
            jdd_mv(Rl, JT, Vu, 0);
            jdd_cross(o, Vw, T[0]);
            jdd_axpy(1.0, T[0], Vu, 3);
            jdd_t V = jdd_at(X, D, i, JQ_VCOLS, 6 * cl);
            jdd_axpy(ydd[jdd_col_coord[c]], V, P, 6);
        }
        /* centre of mass c = r_O + S com; its acceleration with ÿ */
        jdd_mv(R, com, T[0], 0);                        /* cw */
        jdd_copy(o, cc, 3); jdd_axpy(1.0, T[0], cc, 3);
        jdd_t Pw = jdd_at(X, D, i, JQ_P, 0), Pu = jdd_at(X, D, i, JQ_P, 3);
        jdd_copy(al, T[1], 3); jdd_axpy(1.0, Pw, T[1], 3);     /* α */
        jdd_cross(T[1], T[0], T[2]);                             /* α × cw  (includes P_ω × cw) */
        jdd_cross(w, T[0], T[3]);
        jdd_cross(w, T[3], T[4]);                                /* ω × (ω × cw) */
        jdd_cross(Pw, o, T[5]);                                  /* P_ω × r_O */
        jdd_copy(a, T[6], 3);
        jdd_axpy(1.0, T[2], T[6], 3); jdd_axpy(1.0, T[4], T[6], 3);
        jdd_axpy(1.0, Pu, T[6], 3); jdd_axpy(1.0, T[5], T[6], 3);  /* a_c */
        /* body frame: ω_B = Sᵀω, α_B = Sᵀα; τ = I α_B + ω_B × I ω_B; F = m a_c */
        jdd_mv(R, w, T[7], 1);
        jdd_mv(R, T[1], T[8], 1);
        const double Is[9] = {In[0], In[1], In[2], In[1], In[3], In[4], In[2], In[4], In[5]};
        jdd_t I = {(double *)Is, {D, D}, {0, 0}};
        jdd_mv(I, T[7], T[9], 0);
        jdd_cross(T[7], T[9], T[10]);
        jdd_mv(I, T[8], T[11], 0);
        jdd_axpy(1.0, T[10], T[11], 3);                          /* τ (body frame) */
        jdd_axpy(-1.0, le, T[11], 3);                            /* τ − l */
        for (int s = 0; s < 3; ++s) T[6].x[s] *= m;
        for (int b = 0; b < 2; ++b)
            for (int k = 0; k < 3 * T[6].n[b]; ++k) T[6].d[b][k] *= m;
        jdd_axpy(-1.0, fe, T[6], 3);                             /* F − f */
        /* the body's wrench about the origin: (c × (F − f) + S (τ − l), F − f) */
        jdd_t Wm = jdd_at(X, D, i, JQ_WC, 0), WF = jdd_at(X, D, i, JQ_WC, 3);
        jdd_cross(cc, T[6], Wm);
        jdd_mv(R, T[11], T[0], 0);
        jdd_axpy(1.0, T[0], Wm, 3);
        jdd_copy(T[6], WF, 3);
    }
    /* sub-tree sums, children first; the derivatives each body brings in reach the columns
       above it; tau and the prefix derivatives at each body's own columns */
    for (long a = 0; a < JDD_F; ++a) tau[a] = 0.0;
    for (long a = 0; a < (long)JDD_F * JDD_F; ++a) { tau_y[a] = 0.0; tau_yd[a] = 0.0; }
    for (long a = 0; a < (long)JDD_F * JDD_NU; ++a) tau_u[a] = 0.0;
    for (int i = JDD_P - 1; i >= 0; --i) {
        int lam = jdd_parent[i];
        jdd_t Wc = jdd_at(X, D, i, JQ_WC, 0);
        int n0 = lam < 0 ? 0 : jdd_ny[lam], n1 = lam < 0 ? 0 : jdd_nv[lam];
        /* own columns: tau_j += V·W^c, and the derivatives over all of body i's variables */
        for (int c = jdd_col_start[i]; c < jdd_col_start[i + 1]; ++c) {
            int cl = c - jdd_col_start[i], j = jdd_col_coord[c];
            jdd_t V = jdd_at(X, D, i, JQ_VCOLS, 6 * cl);
            double s = 0.0;
            for (int e = 0; e < 6; ++e) s += V.x[e] * Wc.x[e];
            tau[j] += s;
            for (int b = 0; b < 2; ++b) {
                int n = Wc.n[b], nV = V.n[b];
                const int *var = b == 0 ? jdd_vars_y + jdd_vars_y_start[i] : jdd_vars_v + jdd_vars_v_start[i];
                for (int k = 0; k < n; ++k) {
                    double g = 0.0;
                    for (int e = 0; e < 6; ++e) {
                        g += V.x[e] * Wc.d[b][e * n + k];
                        if (k < nV) g += V.d[b][e * nV + k] * Wc.x[e];
                    }
                    int x = var[k];
                    if (b == 0) tau_y[(long)j * JDD_F + x] += g;
                    else if (x < JDD_F) tau_yd[(long)j * JDD_F + x] += g;
                    else tau_u[(long)j * JDD_NU + (x - JDD_F)] += g;
                }
            }
        }
        if (lam < 0) continue;
        /* the variables body i brings in: V_a·dW^c_i for every column above */
        for (int b = 0; b < 2; ++b) {
            int n = Wc.n[b], nfrom = b == 0 ? n0 : n1;
            const int *var = b == 0 ? jdd_vars_y + jdd_vars_y_start[i] : jdd_vars_v + jdd_vars_v_start[i];
            for (int k = nfrom; k < n; ++k) {
                int x = var[k];
                for (int an = lam; an >= 0; an = jdd_parent[an])
                    for (int c = jdd_col_start[an]; c < jdd_col_start[an + 1]; ++c) {
                        jdd_t V = jdd_at(X, D, an, JQ_VCOLS, 6 * (c - jdd_col_start[an]));
                        double g = 0.0;
                        for (int e = 0; e < 6; ++e) g += V.x[e] * Wc.d[b][e * n + k];
                        int j = jdd_col_coord[c];
                        if (b == 0) tau_y[(long)j * JDD_F + x] += g;
                        else if (x < JDD_F) tau_yd[(long)j * JDD_F + x] += g;
                        else tau_u[(long)j * JDD_NU + (x - JDD_F)] += g;
                    }
            }
        }
        /* add W^c_i (its parent's prefix of the derivatives) into the parent's */
        jdd_t Wp = jdd_at(X, D, lam, JQ_WC, 0);
        for (int e = 0; e < 6; ++e) Wp.x[e] += Wc.x[e];
        for (int b = 0; b < 2; ++b) {
            int n = Wc.n[b], np = Wp.n[b];
            for (int e = 0; e < 6; ++e)
                for (int k = 0; k < np; ++k) Wp.d[b][e * np + k] += Wc.d[b][e * n + k];
        }
    }
    for (long a = 0; a < JDD_F; ++a) if (!isfinite(tau[a])) return 2;
    return 0;
}

/* ---- the driver: tau and M, or ydd and its derivatives, per state and for a batch ---- */
void jd_fn(const double *y, const double *yd, double t, const double *p, const double *u,
           double *out);  /* the recursion's M, k, q (the other translation unit) */

/* Cholesky M = L Lᵀ in place (lower triangle; the diagonal holds 1/l_jj); 0, or 1 where M is
   not positive definite, 2 where not finite */
static int jdd_cholesky(double *M, int n) {
    double dmax = 0.0;
    for (int i = 0; i < n; ++i) dmax = fmax(dmax, fabs(M[i * n + i]));
    for (int j = 0; j < n; ++j) {
        double d = M[j * n + j];
        for (int m = 0; m < j; ++m) d -= M[j * n + m] * M[j * n + m];
        if (!(d > 1e-13 * dmax)) return isfinite(d) ? 1 : 2;
        double inv = 1.0 / sqrt(d);
        M[j * n + j] = inv;
        for (int i = j + 1; i < n; ++i) {
            double s = M[j * n + i];  /* the upper triangle: M_ji = M_ij */
            for (int m = 0; m < j; ++m) s -= M[i * n + m] * M[j * n + m];
            M[i * n + j] = s * inv;
        }
    }
    return 0;
}

/* b = (L Lᵀ)⁻¹ b for `cols` right-hand sides stored as the columns of a row-major n×cols b */
static void jdd_solve(const double *Lc, double *b, int n, int cols) {
    for (int i = 0; i < n; ++i) {
        double *bi = b + (long)i * cols, li = Lc[i * n + i];
        for (int m = 0; m < i; ++m) {
            double l = Lc[i * n + m];
            const double *bm = b + (long)m * cols;
            for (int c = 0; c < cols; ++c) bi[c] -= l * bm[c];
        }
        for (int c = 0; c < cols; ++c) bi[c] *= li;
    }
    for (int i = n - 1; i >= 0; --i) {
        double *bi = b + (long)i * cols, li = Lc[i * n + i];
        for (int m = i + 1; m < n; ++m) {
            double l = Lc[m * n + i];
            const double *bm = b + (long)m * cols;
            for (int c = 0; c < cols; ++c) bi[c] -= l * bm[c];
        }
        for (int c = 0; c < cols; ++c) bi[c] *= li;
    }
}

/* the work of one state: values and local expressions (X), tangents (D), M k q, a matrix */
#define JDD_WORK (JDD_NX + JDD_NTAN + JDD_F * JDD_F + 2 * JDD_F \
                  + (long)JDD_F * (2 * JDD_F + JDD_NU))

/* out = [tau (f), tau_y (f×f), tau_yd (f×f), tau_u (f×nu), M (f×f)]; 0 or 2 (not finite) */
static int jdd_inverse_with(const double *y, const double *yd, const double *ydd, double t,
                            const double *p, const double *u, double *out, double *work) {
    const long F = JDD_F, FF = (long)JDD_F * JDD_F;
    double *X = work, *D = X + JDD_NX, *Mkq = D + JDD_NTAN;
    int status = jdd_inverse(y, yd, ydd, t, p, u, out, out + F, out + F + FF,
                             out + F + 2 * FF, X, D);
    jd_fn(y, yd, t, p, u, Mkq);
    double *M = out + F + 2 * FF + F * JDD_NU;
    for (long a = 0; a < FF; ++a) M[a] = Mkq[a];
    return status;
}

/* out = [ydd (f), ydd_y (f×f), ydd_yd (f×f), ydd_u (f×nu)]; 0, 1 (M not positive definite)
   or 2 (not finite) */
static int jdd_forward_with(const double *y, const double *yd, double t, const double *p,
                            const double *u, double *out, double *work) {
    const long F = JDD_F, FF = (long)JDD_F * JDD_F, NC = 2 * JDD_F + JDD_NU;
    double *X = work, *D = X + JDD_NX, *Mkq = D + JDD_NTAN, *G = Mkq + FF + 2 * F;
    jd_fn(y, yd, t, p, u, Mkq);
    double *M = Mkq, *k = Mkq + FF, *q = k + F, *ydd = out;
    int status = jdd_cholesky(M, JDD_F);
    if (status) return status;
    for (long i = 0; i < F; ++i) ydd[i] = q[i] - k[i];
    jdd_solve(M, ydd, JDD_F, 1);
    /* tau_y, tau_yd, tau_u at ÿ, into scratch; then the columns −M⁻¹[τ_y τ_ẏ τ_u] */
    double *ty_s = out + F, *tyd_s = out + F + FF, *tu_s = out + F + 2 * FF;
    double tau_v[JDD_F];
    status = jdd_inverse(y, yd, ydd, t, p, u, tau_v, ty_s, tyd_s, tu_s, X, D);
    if (status) return status;
    for (long i = 0; i < F; ++i) {
        for (long j = 0; j < F; ++j) {
            G[i * NC + j] = -ty_s[i * F + j];
            G[i * NC + F + j] = -tyd_s[i * F + j];
        }
        for (long j = 0; j < JDD_NU; ++j) G[i * NC + 2 * F + j] = -tu_s[i * JDD_NU + j];
    }
    jdd_solve(M, G, JDD_F, (int)NC);
    for (long i = 0; i < F; ++i) {
        for (long j = 0; j < F; ++j) {
            ty_s[i * F + j] = G[i * NC + j];
            tyd_s[i * F + j] = G[i * NC + F + j];
        }
        for (long j = 0; j < JDD_NU; ++j) tu_s[i * JDD_NU + j] = G[i * NC + 2 * F + j];
    }
    for (long a = 0; a < F + 2 * FF + F * JDD_NU; ++a) if (!isfinite(out[a])) return 2;
    return 0;
}

