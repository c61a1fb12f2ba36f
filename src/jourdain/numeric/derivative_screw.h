/* The first derivatives of tau = M*ydd + k - q for trees of screw joints (derivatives.py):
   every coordinate drives one elementary rotation or translation along a constant axis, in the
   order of its joint's steps ("columns" j, each with the column before it on its path,
   jda_pred), gravity and generalized forces of the inputs alone.

   Spatial vectors about the inertial origin in inertial components: motion (w, u), force
   (moment, force); S_j the twist of column j, v_j and a_j the velocity and acceleration after
   it (a_0 = (0, -g): gravity as an acceleration of the base), so that
       v_j = v_p + S_j ẏ_j,   a_j = a_p + S_j ÿ_j + v_j × S_j ẏ_j      (p = jda_pred[j]).
   Each body: I_i its spatial inertia, f_i = I_i a_i + v_i ×* I_i v_i, and the operator
   B_i x = −I_i (v_i × x) + x ×* (I_i v_i) + v_i ×* (I_i x); I^C, B^C, F the sums over the
   sub-tree. With ψ̇_k = v_k × S_k and ψ̈_k = a_k × S_k + v_k × ψ̇_k (the first and second time
   derivatives of S_k), the derivatives of the sub-tree's force are
       ∂F_b/∂y_k = S_k ×* F_b + I^C_b ψ̈_k + B^C_b ψ̇_k,  ∂F_b/∂ẏ_k = 2 I^C_b ψ̇_k + B^C_b S_k
   for k on the path of body b, and τ_j = S_jᵀF_b (∂S_j/∂y_k = S_k × S_j cancels S_k ×* F_b):
       k before or at j:  ∂τ_j/∂y_k = (I^C S_j)·ψ̈_k + (B^Cᵀ S_j)·ψ̇_k,
                          ∂τ_j/∂ẏ_k = 2 (I^C S_j)·ψ̇_k + (B^Cᵀ S_j)·S_k,
       k after j:         ∂τ_j/∂y_k = S_j·(S_k ×* F + I^C ψ̈_k + B^C ψ̇_k)   (at k's body),
                          ∂τ_j/∂ẏ_k = S_j·(2 I^C ψ̇_k + B^C S_k),
   and M_jk = S_k·(I^C S_j) for k before j (Carpentier & Mansard 2018 derive the same
   relations). O(Σ depth) dot products of 6-vectors per state. */


static inline void jda_cross3(const double *a, const double *b, double *r) {
    double r0 = a[1] * b[2] - a[2] * b[1], r1 = a[2] * b[0] - a[0] * b[2];
    double r2 = a[0] * b[1] - a[1] * b[0];
    r[0] = r0; r[1] = r1; r[2] = r2;
}
/* motion × motion */
static inline void jda_crm(const double *v, const double *x, double *r) {
    double a[3], b[3], c[3];
    jda_cross3(v, x, a);
    jda_cross3(v, x + 3, b);
    jda_cross3(v + 3, x, c);
    for (int k = 0; k < 3; ++k) { r[k] = a[k]; r[3 + k] = b[k] + c[k]; }
}
/* motion ×* force */
static inline void jda_crf(const double *v, const double *F, double *r) {
    double a[3], b[3], c[3];
    jda_cross3(v, F, a);
    jda_cross3(v + 3, F + 3, b);
    jda_cross3(v, F + 3, c);
    for (int k = 0; k < 3; ++k) { r[k] = a[k] + b[k]; r[3 + k] = c[k]; }
}
static inline double jda_dot6(const double *a, const double *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4] + a[5] * b[5];
}
/* a spatial inertia about the origin as (Ī 9, h = m·c 3, m): I x = (Ī xw + h × xu, m xu − h × xw) */
static inline void jda_inertia(const double *I, const double *x, double *r) {
    double a[3], b[3];
    jda_cross3(I + 9, x + 3, a);
    jda_cross3(I + 9, x, b);
    for (int k = 0; k < 3; ++k) {
        r[k] = I[3 * k] * x[0] + I[3 * k + 1] * x[1] + I[3 * k + 2] * x[2] + a[k];
        r[3 + k] = I[12] * x[3 + k] - b[k];
    }
}
/* B = [[B11, 0], [−2[h_f]×, 0]] as (B11 9, h_f 3): B x and Bᵀ x */
static inline void jda_bx(const double *B, const double *x, double *r) {
    double c[3];
    jda_cross3(B + 9, x, c);
    for (int k = 0; k < 3; ++k) {
        r[k] = B[3 * k] * x[0] + B[3 * k + 1] * x[1] + B[3 * k + 2] * x[2];
        r[3 + k] = -2.0 * c[k];
    }
}
static inline void jda_btx(const double *B, const double *x, double *r) {
    double c[3];
    jda_cross3(B + 9, x + 3, c);
    for (int k = 0; k < 3; ++k) {
        r[k] = B[k] * x[0] + B[3 + k] * x[1] + B[6 + k] * x[2] + 2.0 * c[k];
        r[3 + k] = 0.0;
    }
}

typedef struct {
    double R[9 * JDA_P], o[3 * JDA_P];
    double S[6 * JDA_NC], v[6 * JDA_NC], a[6 * JDA_NC], pd[6 * JDA_NC], pdd[6 * JDA_NC];
    double Ib[13 * JDA_P], Iv[6 * JDA_P], IC[13 * JDA_P], BC[12 * JDA_P], F[6 * JDA_P];
    double A[6 * JDA_NC], Bt[6 * JDA_NC], G[6 * JDA_NC], H[6 * JDA_NC];
    double L[JDA_NL > 0 ? JDA_NL : 1], K[JDA_NK > 0 ? JDA_NK : 1];
} jda_work;

/* frames, twists, velocities, accelerations; the bodies' inertias, forces and B; the sums;
   with derivs: A, Bt, G, H per column; tau always */
/* frames, twists, velocities, ψ̇; each body's inertia I, I·v and B about the origin; the
   sums I^C, B^C over the sub-trees (nothing here depends on ÿ) */
static void jda_geometry(const double *y, const double *yd, double t, const double *p,
                         const double *u, jda_work *W) {
    static const double I3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, Z3[3] = {0, 0, 0};
    static const double z6[6] = {0, 0, 0, 0, 0, 0};
    jda_local(y, yd, t, p, u, W->L);
    jda_consts(y, yd, t, p, u, W->K);
    const double *L = W->L;
    for (int i = 0; i < JDA_P; ++i) {  /* frames */
        const double *b = L + 40 * i, *A = b, *d = b + 9;
        int lam = jda_parent[i];
        const double *Rl = lam < 0 ? I3 : W->R + 9 * lam, *ol = lam < 0 ? Z3 : W->o + 3 * lam;
        double *R = W->R + 9 * i, *o = W->o + 3 * i;
        for (int r = 0; r < 3; ++r)
            for (int s = 0; s < 3; ++s)
                R[3 * r + s] = Rl[3 * r] * A[s] + Rl[3 * r + 1] * A[3 + s] + Rl[3 * r + 2] * A[6 + s];
        for (int r = 0; r < 3; ++r)
            o[r] = ol[r] + Rl[3 * r] * d[0] + Rl[3 * r + 1] * d[1] + Rl[3 * r + 2] * d[2];
    }
    for (int j = 0; j < JDA_NC; ++j) {  /* columns in the order of their paths */
        int i = jda_body[j], lam = jda_parent[i], pj = jda_pred[j], c = jda_coord[j];
        const double *Rl = lam < 0 ? I3 : W->R + 9 * lam, *R = W->R + 9 * i, *o = W->o + 3 * i;
        const double *JR = L + 40 * JDA_P + 6 * jda_lcol[j], *JT = JR + 3;
        double *S = W->S + 6 * j, w[3], ut[3];
        for (int r = 0; r < 3; ++r) {
            w[r] = R[3 * r] * JR[0] + R[3 * r + 1] * JR[1] + R[3 * r + 2] * JR[2];
            ut[r] = Rl[3 * r] * JT[0] + Rl[3 * r + 1] * JT[1] + Rl[3 * r + 2] * JT[2];
        }
        jda_cross3(o, w, S + 3);
        for (int r = 0; r < 3; ++r) { S[r] = w[r]; S[3 + r] += ut[r]; }
        const double *vp = pj < 0 ? z6 : W->v + 6 * pj;
        double *v = W->v + 6 * j, qd = yd[c];
        for (int r = 0; r < 6; ++r) v[r] = vp[r] + S[r] * qd;
        jda_crm(v, S, W->pd + 6 * j);                       /* ψ̇ = v × S */
    }
    for (int i = 0; i < JDA_P; ++i) {  /* each body: I, I v, B about the origin */
        const double *b = L + 40 * i, m = b[24], *com = b + 25, *In = b + 28;
        const double *R = W->R + 9 * i, *o = W->o + 3 * i;
        int vc = jda_vcol[i];  /* the last column on the body's path (-1: the base) */
        const double *v = vc < 0 ? z6 : W->v + 6 * vc;
        double *Ib = W->Ib + 13 * i, *BC = W->BC + 12 * i, *Iv = W->Iv + 6 * i;
        double c[3], SI[9];
        for (int r = 0; r < 3; ++r) c[r] = o[r] + R[3 * r] * com[0] + R[3 * r + 1] * com[1] + R[3 * r + 2] * com[2];
        const double Is[9] = {In[0], In[1], In[2], In[1], In[3], In[4], In[2], In[4], In[5]};
        for (int r = 0; r < 3; ++r)
            for (int s = 0; s < 3; ++s)
                SI[3 * r + s] = R[3 * r] * Is[s] + R[3 * r + 1] * Is[3 + s] + R[3 * r + 2] * Is[6 + s];
        double c2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
        for (int r = 0; r < 3; ++r)
            for (int s = 0; s < 3; ++s)
                Ib[3 * r + s] = SI[3 * r] * R[3 * s] + SI[3 * r + 1] * R[3 * s + 1]
                                + SI[3 * r + 2] * R[3 * s + 2] + m * ((r == s ? c2 : 0.0) - c[r] * c[s]);
        for (int r = 0; r < 3; ++r) Ib[9 + r] = m * c[r];
        Ib[12] = m;
        jda_inertia(Ib, v, Iv);
        /* B x = −I (v × x) + x ×* (I v) + v ×* (I x) = [[B11, 0], [−2[h_f]×, 0]] x with
           (I v) = (h_m, h_f), W = [ω]×, H = [h]×, U = [u]×:
           B11 = W Ī − Ī W − (H U + U H) − [h_m]× */
        const double *w = v, *uu = v + 3, *h = Ib + 9;
        double Wm[9] = {0, -w[2], w[1], w[2], 0, -w[0], -w[1], w[0], 0};
        double Hm[9] = {0, -h[2], h[1], h[2], 0, -h[0], -h[1], h[0], 0};
        double Um[9] = {0, -uu[2], uu[1], uu[2], 0, -uu[0], -uu[1], uu[0], 0};
        for (int r = 0; r < 3; ++r)
            for (int s = 0; s < 3; ++s) {
                double t2 = 0.0;
                for (int k = 0; k < 3; ++k)
                    t2 += Wm[3 * r + k] * Ib[3 * k + s] - Ib[3 * r + k] * Wm[3 * k + s]
                          - Hm[3 * r + k] * Um[3 * k + s] - Um[3 * r + k] * Hm[3 * k + s];
                BC[3 * r + s] = t2;
            }
        BC[1] += Iv[2]; BC[2] -= Iv[1]; BC[3] -= Iv[2];
        BC[5] += Iv[0]; BC[6] += Iv[1]; BC[7] -= Iv[0];    /* − [h_m]× */
        for (int r = 0; r < 3; ++r) BC[9 + r] = Iv[3 + r];
        for (int r = 0; r < 13; ++r) W->IC[13 * i + r] = Ib[r];
    }
    for (int i = JDA_P - 1; i >= 0; --i) {  /* sums over the sub-trees */
        int lam = jda_parent[i];
        if (lam < 0) continue;
        for (int r = 0; r < 13; ++r) W->IC[13 * lam + r] += W->IC[13 * i + r];
        for (int r = 0; r < 12; ++r) W->BC[12 * lam + r] += W->BC[12 * i + r];
    }
}

/* for ÿ: accelerations, the bodies' forces f = I a + v ×* I v and their sums F, tau; with
   derivs also ψ̈ and per column A = I^C S, Bt = B^Cᵀ S, G, H */
static void jda_dynamics(const double *yd, const double *ydd, jda_work *W, int derivs,
                         double *tau) {
    static const double z6[6] = {0, 0, 0, 0, 0, 0};
    const double *g = W->K;
    const double a0[6] = {0, 0, 0, -g[0], -g[1], -g[2]};
    for (int j = 0; j < JDA_NC; ++j) {
        int pj = jda_pred[j], c = jda_coord[j];
        const double *S = W->S + 6 * j, *v = W->v + 6 * j, *pd = W->pd + 6 * j;
        const double *ap = pj < 0 ? a0 : W->a + 6 * pj;
        double *a = W->a + 6 * j, qd = yd[c];
        for (int r = 0; r < 6; ++r) a[r] = ap[r] + S[r] * ydd[c] + pd[r] * qd;
        if (derivs) {
            double *pdd = W->pdd + 6 * j, vxs[6];
            jda_crm(a, S, pdd);
            jda_crm(v, pd, vxs);
            for (int r = 0; r < 6; ++r) pdd[r] += vxs[r];   /* ψ̈ = a × S + v × ψ̇ */
        }
    }
    for (int i = 0; i < JDA_P; ++i) {
        int vc = jda_vcol[i];
        const double *v = vc < 0 ? z6 : W->v + 6 * vc, *a = vc < 0 ? a0 : W->a + 6 * vc;
        double Ia[6], vf[6], *F = W->F + 6 * i;
        jda_inertia(W->Ib + 13 * i, a, Ia);
        jda_crf(v, W->Iv + 6 * i, vf);
        for (int r = 0; r < 6; ++r) F[r] = Ia[r] + vf[r];
    }
    for (int i = JDA_P - 1; i >= 0; --i) {
        int lam = jda_parent[i];
        if (lam >= 0) for (int r = 0; r < 6; ++r) W->F[6 * lam + r] += W->F[6 * i + r];
    }
    for (int r = 0; r < JDA_F; ++r) tau[r] = -W->K[3 + r];  /* − the generalized forces */
    for (int j = 0; j < JDA_NC; ++j) {
        int i = jda_body[j];
        const double *S = W->S + 6 * j, *IC = W->IC + 13 * i, *F = W->F + 6 * i;
        tau[jda_coord[j]] += jda_dot6(S, F);
        if (!derivs) continue;
        const double *BC = W->BC + 12 * i, *pd = W->pd + 6 * j, *pdd = W->pdd + 6 * j;
        double *A = W->A + 6 * j, *Bt = W->Bt + 6 * j, *G = W->G + 6 * j, *H = W->H + 6 * j;
        double t1[6], t2[6], t3[6];
        jda_inertia(IC, S, A);
        jda_btx(BC, S, Bt);
        jda_crf(S, F, t1);
        jda_inertia(IC, pdd, t2);
        jda_bx(BC, pd, t3);
        for (int r = 0; r < 6; ++r) G[r] = t1[r] + t2[r] + t3[r];
        jda_inertia(IC, pd, t1);
        jda_bx(BC, S, t2);
        for (int r = 0; r < 6; ++r) H[r] = 2.0 * t1[r] + t2[r];
    }
}

/* M from the composite inertias: M_jk = S_k·(I^C S_j) for k before j on j's path */
static void jda_mass(const jda_work *W, double *M) {
    for (long r = 0; r < (long)JDA_F * JDA_F; ++r) M[r] = 0.0;
    for (int j = 0; j < JDA_NC; ++j) {
        double A[6];
        jda_inertia(W->IC + 13 * jda_body[j], W->S + 6 * j, A);
        int cj = jda_coord[j];
        for (int k = j; k >= 0; k = jda_pred[k]) {
            double m = jda_dot6(W->S + 6 * k, A);
            int ck = jda_coord[k];
            M[(long)cj * JDA_F + ck] = m;
            M[(long)ck * JDA_F + cj] = m;
        }
    }
}

/* tau (f), tau_y, tau_yd (f×f), tau_u (f×nu) at ÿ; W holds the pass with derivs */
static int jda_inverse(const double *yd, const double *ydd, double *tau, double *tau_y,
                       double *tau_yd, double *tau_u, jda_work *W) {
    jda_dynamics(yd, ydd, W, 1, tau);
    for (long r = 0; r < (long)JDA_F * JDA_F; ++r) { tau_y[r] = 0.0; tau_yd[r] = 0.0; }
    for (int k = 0; k < JDA_NC; ++k) {
        int ck = jda_coord[k];
        const double *Ak = W->A + 6 * k, *Btk = W->Bt + 6 * k;
        const double *Gk = W->G + 6 * k, *Hk = W->H + 6 * k;
        /* j at or before k on k's path: ∂τ_k/∂y_j and ∂τ_j/∂y_k */
        for (int j = k; j >= 0; j = jda_pred[j]) {
            int cj = jda_coord[j];
            const double *Sj = W->S + 6 * j, *pdj = W->pd + 6 * j, *pddj = W->pdd + 6 * j;
            tau_y[(long)ck * JDA_F + cj] = jda_dot6(Ak, pddj) + jda_dot6(Btk, pdj);
            tau_yd[(long)ck * JDA_F + cj] = 2.0 * jda_dot6(Ak, pdj) + jda_dot6(Btk, Sj);
            if (j != k) {
                tau_y[(long)cj * JDA_F + ck] = jda_dot6(Sj, Gk);
                tau_yd[(long)cj * JDA_F + ck] = jda_dot6(Sj, Hk);
            }
        }
    }
    /* the generalized forces of the inputs: τ_u = −∂q/∂u */
    for (long r = 0; r < (long)JDA_F * JDA_NU; ++r) tau_u[r] = -W->K[3 + JDA_F + r];
    for (int r = 0; r < JDA_F; ++r) if (!isfinite(tau[r])) return 2;
    return 0;
}

/* ---- the driver (the same entry points as derivative_engine.h's) ---- */
#define JDD_F JDA_F
#define JDD_NU JDA_NU

#define JDD_WORK ((long)(sizeof(jda_work) / sizeof(double)) + 1 + 3L * JDA_F * JDA_F \
                  + (long)JDA_F * (2 * JDA_F + JDA_NU) + JDA_F)

static int jdd_inverse_with(const double *y, const double *yd, const double *ydd, double t,
                            const double *p, const double *u, double *out, double *work) {
    const long F = JDA_F, FF = (long)JDA_F * JDA_F;
    jda_work *W = (jda_work *)work;
    jda_geometry(y, yd, t, p, u, W);
    int status = jda_inverse(yd, ydd, out, out + F, out + F + FF, out + F + 2 * FF, W);
    jda_mass(W, out + F + 2 * FF + F * JDA_NU);
    return status;
}

/* M = LᵀL with the sparsity of the tree (Featherstone's LTL: no fill-in where the columns'
   parents come first): row j of H holds L_jk for k at or above j on j's path, in the order of
   the columns; 0, or 1 where M is not positive definite, 2 where not finite */
static int jda_ltl(const double *M, double *H) {
    double dmax = 0.0;
    for (int j = 0; j < JDA_NC; ++j) {
        int cj = jda_coord[j];
        dmax = fmax(dmax, fabs(M[(long)cj * JDA_F + cj]));
        for (int k = j; k >= 0; k = jda_pred[k]) H[(long)j * JDA_NC + k] = M[(long)cj * JDA_F + jda_coord[k]];
    }
    for (int k = JDA_NC - 1; k >= 0; --k) {
        double d = H[(long)k * JDA_NC + k];
        if (!(d > 1e-13 * dmax)) return isfinite(d) ? 1 : 2;
        d = sqrt(d);
        H[(long)k * JDA_NC + k] = d;
        for (int i = jda_pred[k]; i >= 0; i = jda_pred[i]) H[(long)k * JDA_NC + i] /= d;
        for (int i = jda_pred[k]; i >= 0; i = jda_pred[i])
            for (int j = i; j >= 0; j = jda_pred[j])
                H[(long)i * JDA_NC + j] -= H[(long)k * JDA_NC + i] * H[(long)k * JDA_NC + j];
    }
    return 0;
}

/* X = M⁻¹ X for `cols` right-hand sides (rows in the order of the columns): Lᵀ z = x, L x = z */
static void jda_ltl_solve(const double *H, double *X, int cols) {
    for (int i = JDA_NC - 1; i >= 0; --i) {
        double *xi = X + (long)i * cols, li = 1.0 / H[(long)i * JDA_NC + i];
        for (int c = 0; c < cols; ++c) xi[c] *= li;
        for (int j = jda_pred[i]; j >= 0; j = jda_pred[j]) {
            double l = H[(long)i * JDA_NC + j];
            double *xj = X + (long)j * cols;
            for (int c = 0; c < cols; ++c) xj[c] -= l * xi[c];
        }
    }
    for (int i = 0; i < JDA_NC; ++i) {
        double *xi = X + (long)i * cols;
        for (int j = jda_pred[i]; j >= 0; j = jda_pred[j]) {
            double l = H[(long)i * JDA_NC + j];
            const double *xj = X + (long)j * cols;
            for (int c = 0; c < cols; ++c) xi[c] -= l * xj[c];
        }
        double li = 1.0 / H[(long)i * JDA_NC + i];
        for (int c = 0; c < cols; ++c) xi[c] *= li;
    }
}

static int jdd_forward_with(const double *y, const double *yd, double t, const double *p,
                            const double *u, double *out, double *work) {
    const long F = JDA_F, FF = (long)JDA_F * JDA_F, NC = 2 * JDA_F + JDA_NU;
    jda_work *W = (jda_work *)work;
    double *M = work + sizeof(jda_work) / sizeof(double) + 1, *H = M + FF, *G = H + FF;
    double *tau = G + F * NC, *ydd = out;
    for (long i = 0; i < F; ++i) ydd[i] = 0.0;
    jda_geometry(y, yd, t, p, u, W);
    jda_dynamics(yd, ydd, W, 0, tau);                   /* k − q at ÿ = 0 */
    jda_mass(W, M);
    int status = jda_ltl(M, H);
    if (status) return status;
    for (int j = 0; j < JDA_NC; ++j) G[j] = -tau[jda_coord[j]];
    jda_ltl_solve(H, G, 1);
    for (int j = 0; j < JDA_NC; ++j) ydd[jda_coord[j]] = G[j];
    double *ty = out + F, *tyd = out + F + FF, *tu = out + F + 2 * FF;
    status = jda_inverse(yd, ydd, tau, ty, tyd, tu, W);
    if (status) return status;
    for (int j = 0; j < JDA_NC; ++j) {  /* −[τ_y τ_ẏ τ_u], rows in the order of the columns */
        long i = jda_coord[j];
        double *g = G + (long)j * NC;
        for (long k = 0; k < F; ++k) { g[k] = -ty[i * F + k]; g[F + k] = -tyd[i * F + k]; }
        for (long k = 0; k < JDA_NU; ++k) g[2 * F + k] = -tu[i * JDA_NU + k];
    }
    jda_ltl_solve(H, G, (int)NC);
    for (int j = 0; j < JDA_NC; ++j) {
        long i = jda_coord[j];
        const double *g = G + (long)j * NC;
        for (long k = 0; k < F; ++k) { ty[i * F + k] = g[k]; tyd[i * F + k] = g[F + k]; }
        for (long k = 0; k < JDA_NU; ++k) tu[i * JDA_NU + k] = g[2 * F + k];
    }
    for (long a = 0; a < F + 2 * FF + F * JDA_NU; ++a) if (!isfinite(out[a])) return 2;
    return 0;
}
