
typedef struct { double R[9], o[3], w[3], v[3], al[3], a[3]; } jd_frame;

static inline void jd_mv(const double *A, const double *x, double *r) {
    r[0] = A[0] * x[0] + A[1] * x[1] + A[2] * x[2];
    r[1] = A[3] * x[0] + A[4] * x[1] + A[5] * x[2];
    r[2] = A[6] * x[0] + A[7] * x[1] + A[8] * x[2];
}
static inline void jd_mtv(const double *A, const double *x, double *r) {
    r[0] = A[0] * x[0] + A[3] * x[1] + A[6] * x[2];
    r[1] = A[1] * x[0] + A[4] * x[1] + A[7] * x[2];
    r[2] = A[2] * x[0] + A[5] * x[1] + A[8] * x[2];
}
static inline void jd_cross(const double *a, const double *b, double *r) {
    double r0 = a[1] * b[2] - a[2] * b[1], r1 = a[2] * b[0] - a[0] * b[2];
    double r2 = a[0] * b[1] - a[1] * b[0];
    r[0] = r0; r[1] = r1; r[2] = r2;
}
static inline double jd_dot6(const double *a, const double *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4] + a[5] * b[5];
}
/* composite inertia (Ī 9, h 3, m) times a twist (w, u): (Ī·w + h × u, m·u + w × h) */
static inline void jd_inertia_twist(const double *I, const double *V, double *F) {
    double t[3];
    jd_mv(I, V, F);
    jd_cross(I + 9, V + 3, t);
    F[0] += t[0]; F[1] += t[1]; F[2] += t[2];
    jd_cross(V, I + 9, t);
    F[3] = I[12] * V[3] + t[0]; F[4] = I[12] * V[4] + t[1]; F[5] = I[12] * V[5] + t[2];
}

/* everything but the projection: frames, twist columns V (6 per column), composite inertias
   Ic (13 per body), composite wrenches of q_c (Bc) and q_e (Wc), per body also the centre of
   mass acceleration, Euler term and applied force rows for the full output. Its arrays by
   type, name and length, as an X-macro: JD_ARRAY makes each an array of its length here, and
   a pointer into one allocation in the runtime-sized engine (runtime_head.h, whose
   JD_RT_FIELD adds the sizes and tables it reads) */
#ifndef JD_ARRAY
#define JD_ARRAY(type, name, n) type name[n];
#define JD_RT_FIELD
#endif
#if JD_ABA  /* each body's own q_e wrench (own_only: Ic and Bc stay each body's own) */
#define JD_WORK_ABA(JD_X) JD_X(double, Wb, 6 * JD_P)
#else
#define JD_WORK_ABA(JD_X)
#endif
#define JD_WORK_ARRAYS(JD_X) \
    JD_X(jd_frame, fr, JD_P) JD_X(double, V, 6 * JD_NC) \
    JD_X(double, Ic, 13 * JD_P) JD_X(double, Bc, 6 * JD_P) JD_X(double, Wc, 6 * JD_P) \
    JD_X(double, c, 3 * JD_P) JD_X(double, qc, 6 * JD_P) JD_WORK_ABA(JD_X)
typedef struct { JD_WORK_ARRAYS(JD_ARRAY) JD_RT_FIELD } jd_work;

/* own_only (the articulated bodies): Ic and Bc stay each body's own and only Wc is summed
   (for the power ẏᵀq), with the own Wc kept in Wb */
static void jd_recursion(const double *L, const double *yd, jd_work *W, int own_only) {
    static const double I3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, Z[3] = {0, 0, 0};
    for (int i = 0; i < JD_P; ++i) {
        const double *b = L + i * JD_BODY;
        const double *A = b, *d = b + 9, *wb = b + 12, *vb = b + 15, *abr = b + 18, *abl = b + 21;
        const double m = b[24], *com = b + 25, *In = b + 28, *fe = b + 34, *le = b + 37;
        int lam = jd_parent[i];
        const double *Rl = lam < 0 ? I3 : W->fr[lam].R, *ol = lam < 0 ? Z : W->fr[lam].o;
        const double *wl = lam < 0 ? Z : W->fr[lam].w, *vl = lam < 0 ? Z : W->fr[lam].v;
        const double *all = lam < 0 ? Z : W->fr[lam].al, *al = lam < 0 ? Z : W->fr[lam].a;
        jd_frame *F = &W->fr[i];
        /* S_i = S_λ A_i, r_O,i = r_O,λ + S_λ d_i */
        for (int r = 0; r < 3; ++r)
            for (int s = 0; s < 3; ++s)
                F->R[3 * r + s] = Rl[3 * r] * A[s] + Rl[3 * r + 1] * A[3 + s] + Rl[3 * r + 2] * A[6 + s];
        double dw[3], rho[3], dd[3], rhow[3], ddw[3], t1[3], t2[3];
        jd_mv(Rl, d, dw);
        for (int a = 0; a < 3; ++a) { F->o[a] = ol[a] + dw[a]; rho[a] = wb[a]; dd[a] = vb[a]; }
        /* relative velocities from the joint's columns */
        const double *cl = L + JD_COLS + 6 * jd_col_start[i];
        for (int c = jd_col_start[i]; c < jd_col_start[i + 1]; ++c, cl += 6) {
            double s = yd[jd_col_coord[c]];
            for (int a = 0; a < 3; ++a) { rho[a] += cl[a] * s; dd[a] += cl[3 + a] * s; }
        }
        jd_mv(F->R, rho, rhow);
        jd_mv(Rl, dd, ddw);
        /* ω_i, v_i (origin), and the accelerations at ÿ = 0 */
        jd_cross(wl, dw, t1);
        jd_cross(wl, rhow, t2);
        for (int a = 0; a < 3; ++a) {
            F->w[a] = wl[a] + rhow[a];
            F->v[a] = vl[a] + t1[a] + ddw[a];
            F->al[a] = all[a] + t2[a];
        }
        jd_mv(F->R, abr, t2);
        for (int a = 0; a < 3; ++a) F->al[a] += t2[a];
        double acc[3];
        jd_cross(all, dw, acc);
        jd_cross(wl, t1, t2);  /* ω_λ × (ω_λ × d) */
        for (int a = 0; a < 3; ++a) acc[a] += t2[a];
        jd_cross(wl, ddw, t2);
        jd_mv(Rl, abl, t1);
        for (int a = 0; a < 3; ++a) F->a[a] = al[a] + acc[a] + 2.0 * t2[a] + t1[a];
        /* twist columns about the origin: w = S_i J_R, u = S_λ J_T + r_O × w */
        cl = L + JD_COLS + 6 * jd_col_start[i];
        for (int c = jd_col_start[i]; c < jd_col_start[i + 1]; ++c, cl += 6) {
            double *V = W->V + 6 * c;
            jd_mv(F->R, cl, V);
            jd_mv(Rl, cl + 3, V + 3);
            jd_cross(F->o, V, t1);
            for (int a = 0; a < 3; ++a) V[3 + a] += t1[a];
        }
        /* centre of mass and the body's rows of q_c: m ā, I ᾱ + ω × I ω (body frame) */
        double cw[3], *cc = W->c + 3 * i, ac[3], wB[3], aB[3], Iw[3], tau[3];
        jd_mv(F->R, com, cw);
        for (int a = 0; a < 3; ++a) cc[a] = F->o[a] + cw[a];
        jd_cross(F->al, cw, ac);
        jd_cross(F->w, cw, t1);
        jd_cross(F->w, t1, t2);
        for (int a = 0; a < 3; ++a) ac[a] += F->a[a] + t2[a];
        jd_mtv(F->R, F->w, wB);
        jd_mtv(F->R, F->al, aB);
        const double Is[9] = {In[0], In[1], In[2], In[1], In[3], In[4], In[2], In[4], In[5]};
        jd_mv(Is, wB, Iw);
        jd_mv(Is, aB, tau);
        jd_cross(wB, Iw, t1);
        for (int a = 0; a < 3; ++a) { tau[a] += t1[a]; W->qc[6 * i + a] = m * ac[a]; W->qc[6 * i + 3 + a] = tau[a]; }
        /* wrenches about the origin: (c × F + S τ, F) */
        double *B = W->Bc + 6 * i, *Wr = W->Wc + 6 * i;
        for (int a = 0; a < 3; ++a) { B[3 + a] = m * ac[a]; Wr[3 + a] = fe[a]; }
        jd_cross(cc, B + 3, B);
        jd_mv(F->R, tau, t1);
        for (int a = 0; a < 3; ++a) B[a] += t1[a];
        jd_cross(cc, fe, Wr);
        jd_mv(F->R, le, t1);
        for (int a = 0; a < 3; ++a) Wr[a] += t1[a];
        /* spatial inertia about the origin: Ī = S I Sᵀ + m(|c|² E − c cᵀ), h = m c, m */
        double *Ic = W->Ic + 13 * i, SI[9];
        for (int r = 0; r < 3; ++r)
            for (int s = 0; s < 3; ++s)
                SI[3 * r + s] = F->R[3 * r] * Is[s] + F->R[3 * r + 1] * Is[3 + s] + F->R[3 * r + 2] * Is[6 + s];
        double c2 = cc[0] * cc[0] + cc[1] * cc[1] + cc[2] * cc[2];
        for (int r = 0; r < 3; ++r)
            for (int s = 0; s < 3; ++s)
                Ic[3 * r + s] = SI[3 * r] * F->R[3 * s] + SI[3 * r + 1] * F->R[3 * s + 1]
                                + SI[3 * r + 2] * F->R[3 * s + 2]
                                + m * ((r == s ? c2 : 0.0) - cc[r] * cc[s]);
        for (int a = 0; a < 3; ++a) Ic[9 + a] = m * cc[a];
        Ic[12] = m;
    }
#if JD_ABA
    if (own_only) {
        for (int a = 0; a < 6 * JD_P; ++a) W->Wb[a] = W->Wc[a];
        for (int i = JD_P - 1; i >= 0; --i) {
            int lam = jd_parent[i];
            if (lam >= 0) for (int a = 0; a < 6; ++a) W->Wc[6 * lam + a] += W->Wc[6 * i + a];
        }
        return;
    }
#else
    (void)own_only;
#endif
    /* composite bodies: sums over each sub-tree, children before parents */
    for (int i = JD_P - 1; i >= 0; --i) {
        int lam = jd_parent[i];
        if (lam < 0) continue;
        for (int a = 0; a < 13; ++a) W->Ic[13 * lam + a] += W->Ic[13 * i + a];
        for (int a = 0; a < 6; ++a) {
            W->Bc[6 * lam + a] += W->Bc[6 * i + a];
            W->Wc[6 * lam + a] += W->Wc[6 * i + a];
        }
    }
}

/* M = J̄ᵀM̄J̄, k = J̄ᵀq̄^c, q = J̄ᵀq̄^e from the composite bodies */
static void jd_project(const jd_work *W, double *M, double *k, double *q) {
    for (int a = 0; a < JD_F * JD_F; ++a) M[a] = 0.0;
    for (int a = 0; a < JD_F; ++a) { k[a] = 0.0; q[a] = 0.0; }
    for (int b = 0; b < JD_P; ++b) {
        for (int c = jd_col_start[b]; c < jd_col_start[b + 1]; ++c) {
            const double *V = W->V + 6 * c;
            int kc = jd_col_coord[c];
            k[kc] += jd_dot6(V, W->Bc + 6 * b);
            q[kc] += jd_dot6(V, W->Wc + 6 * b);
            double Fv[6];
            jd_inertia_twist(W->Ic + 13 * b, V, Fv);
            /* the upper triangle only, then mirrored: M is exactly symmetric */
            for (int a = b; a >= 0; a = jd_parent[a]) {
                int last = a == b ? c + 1 : jd_col_start[a + 1];
                for (int e = jd_col_start[a]; e < last; ++e) {
                    double val = jd_dot6(W->V + 6 * e, Fv);
                    int je = jd_col_coord[e];
                    if (je == kc && a != b) val *= 2.0;  /* V_a,jᵀI V_b,j and its transpose */
                    if (je <= kc) M[je * JD_F + kc] += val; else M[kc * JD_F + je] += val;
                }
            }
        }
    }
    for (int r = 1; r < JD_F; ++r)
        for (int s = 0; s < r; ++s) M[r * JD_F + s] = M[s * JD_F + r];
}

#if JD_FULL
/* M_bar, J_bar, q_c, q_e in the row order of jourdain.stages.newton_euler */
static void jd_newton_euler(const double *L, const jd_work *W, double *out) {
    const long n = 6 * JD_P;
    double *Mb = out, *Jb = out + n * n, *qc = Jb + n * JD_F, *qe = qc + n;
    for (long a = 0; a < n * n; ++a) Mb[a] = 0.0;
    for (long a = 0; a < n * JD_F; ++a) Jb[a] = 0.0;
    for (int i = 0; i < JD_P; ++i) {
        const double *b = L + i * JD_BODY, *In = b + 28;
        const double Is[9] = {In[0], In[1], In[2], In[1], In[3], In[4], In[2], In[4], In[5]};
        for (int a = 0; a < 3; ++a) {
            long rT = 3 * i + a, rR = 3 * JD_P + 3 * i + a;
            Mb[rT * n + rT] = b[24];
            for (int s = 0; s < 3; ++s) Mb[rR * n + 3 * JD_P + 3 * i + s] = Is[3 * a + s];
            qc[rT] = W->qc[6 * i + a];
            qc[rR] = W->qc[6 * i + 3 + a];
            qe[rT] = b[34 + a];
            qe[rR] = b[37 + a];
        }
        /* J_T: velocity of the centre of mass u + w × c; J_R: Sᵀ w, summed over the columns
           of every joint above the body */
        const double *cc = W->c + 3 * i, *R = W->fr[i].R;
        for (int a = i; a >= 0; a = jd_parent[a]) {
            for (int e = jd_col_start[a]; e < jd_col_start[a + 1]; ++e) {
                const double *V = W->V + 6 * e;
                int j = jd_col_coord[e];
                double t[3], wB[3];
                jd_cross(V, cc, t);
                jd_mtv(R, V, wB);
                for (int s = 0; s < 3; ++s) {
                    Jb[(3 * i + s) * JD_F + j] += V[3 + s] + t[s];
                    Jb[(3 * JD_P + 3 * i + s) * JD_F + j] += wB[s];
                }
            }
        }
    }
}
#endif

#if JD_QBAR
/* Q̄ (6p×q): each constrained direction (F, T), given in the child frame at its origin, acts
   on the child and, reversed, on the parent; rows as in M̄ (translational inertial, rotational
   in each body's frame about its centre of mass) */
static void jd_distribution(const double *L, const jd_work *W, double *Q) {
    const long n = 6 * JD_P;
    for (long a = 0; a < n * JD_Q; ++a) Q[a] = 0.0;
    for (int i = 0; i < JD_P; ++i) {
        const double *b = L + i * JD_BODY, *A = b, *d = b + 9, *com = b + 25, *R = W->fr[i].R;
        int lam = jd_parent[i];
        for (int k = jd_dir_start[i]; k < jd_dir_start[i + 1]; ++k) {
            const double *F = L + JD_DIRS + 6 * k, *T = F + 3;
            double SF[3], cF[3], AF[3], AT[3], arm[3], aF[3];
            jd_mv(R, F, SF);
            jd_cross(com, F, cF);
            for (int a = 0; a < 3; ++a) {
                Q[(3 * i + a) * JD_Q + k] = SF[a];
                Q[(3 * JD_P + 3 * i + a) * JD_Q + k] = T[a] - cF[a];
            }
            if (lam < 0) continue;
            const double *comp = L + lam * JD_BODY + 25;
            jd_mv(A, F, AF);
            jd_mv(A, T, AT);
            for (int a = 0; a < 3; ++a) arm[a] = d[a] - comp[a];
            jd_cross(arm, AF, aF);
            for (int a = 0; a < 3; ++a) {
                Q[(3 * lam + a) * JD_Q + k] = -SF[a];
                Q[(3 * JD_P + 3 * lam + a) * JD_Q + k] = -(AT[a] + aF[a]);
            }
        }
    }
}
#endif

/* the power ẏᵀq of the applied forces (q_j = Σ over the columns of coordinate j of
   V·(Σ q̄^e as a wrench)) */
static double jd_power(const jd_work *W, const double *yd) {
    double w = 0.0;
    for (int b = 0; b < JD_P; ++b)
        for (int c = jd_col_start[b]; c < jd_col_start[b + 1]; ++c)
            w += yd[jd_col_coord[c]] * jd_dot6(W->V + 6 * c, W->Wc + 6 * b);
    return w;
}

#ifndef JD_RUNTIME  /* the entry points; the runtime-sized engine has its own (runtime_engine.h) */
void jd_fn(const double *y, const double *yd, double t, const double *p, const double *u,
           double *out) {
    double L[JD_NL > 0 ? JD_NL : 1];
#if JD_WORK_STACK
    jd_work work, *W = &work;
#else
    jd_work *W = (jd_work *)malloc(sizeof(jd_work));
    if (!W) { for (long a = 0; a < JD_SIZE; ++a) out[a] = NAN; return; }
#endif
    jd_local(y, yd, t, p, u, L);
    jd_recursion(L, yd, W, 0);
#if JD_FULL
    jd_newton_euler(L, W, out);
    double *M = out + 36L * JD_P * JD_P + 6L * JD_P * JD_F + 12L * JD_P;
#else
    double *M = out;
#endif
    jd_project(W, M, M + JD_F * JD_F, M + JD_F * JD_F + JD_F);
#if JD_QBAR
    jd_distribution(L, W, M + JD_F * JD_F + 2 * JD_F);
#endif
#if !JD_WORK_STACK
    free(W);
#endif
}
#endif

/* jd_fn_batch: ccode.batch_source, appended by recursive.py */

#if !JD_ABA
/* Joint wrenches for given ÿ (the sub-tree's Newton–Euler equations summed, as RNEA does):
   the wrench the parent transmits to the sub-tree of body b, about the inertial origin,
       T_b = Σ_(i below b) (q̄^c_i + M̄_i a_i(ÿ) − q̄^e_i)
           = B^c_b − W^c_b + I^c_b·P_λ(b) + Σ_(a below b) I^c_a·Z_a,
   with Z_a = Σ_(columns of joint a) V·ÿ and P_b = P_λ(b) + Z_b; written in the child frame
   at the joint point (the child's origin) as (F, T). */
static void jd_wrenches_of(const double *ydd, jd_work *W, double *out) {
    double P[6 * JD_P], Y[6 * JD_P];
    for (int i = 0; i < JD_P; ++i) {
        double Z[6] = {0, 0, 0, 0, 0, 0};
        for (int c = jd_col_start[i]; c < jd_col_start[i + 1]; ++c)
            for (int a = 0; a < 6; ++a) Z[a] += W->V[6 * c + a] * ydd[jd_col_coord[c]];
        int lam = jd_parent[i];
        double Pl[6] = {0, 0, 0, 0, 0, 0};
        if (lam >= 0) for (int a = 0; a < 6; ++a) Pl[a] = P[6 * lam + a];
        for (int a = 0; a < 6; ++a) P[6 * i + a] = Pl[a] + Z[a];
        jd_inertia_twist(W->Ic + 13 * i, Z, Y + 6 * i);
        /* start T_b with B^c − W^c + I^c P_λ; the Y of the sub-tree is added below */
        double IP[6], *T = out + 6 * i;
        jd_inertia_twist(W->Ic + 13 * i, Pl, IP);
        for (int a = 0; a < 6; ++a) T[a] = W->Bc[6 * i + a] - W->Wc[6 * i + a] + IP[a];
    }
    for (int i = JD_P - 1; i >= 0; --i) {
        int lam = jd_parent[i];
        for (int a = 0; a < 6; ++a) out[6 * i + a] += Y[6 * i + a];
        if (lam >= 0) for (int a = 0; a < 6; ++a) Y[6 * lam + a] += Y[6 * i + a];
    }
}

/* LDL_SOLVE */
#endif

#if JD_ABA
/* inverse of a small symmetric positive definite matrix (n ≤ 6) by Cholesky; 0 or 1 (not
   positive definite) */
static int jd_spd_inverse(int n, const double *D, double *Dinv, double scale) {
    double Lc[36], Y[36];
    for (int j = 0; j < n; ++j) {
        double d = D[j * n + j];
        for (int m = 0; m < j; ++m) d -= Lc[j * n + m] * Lc[j * n + m];
        if (!(d > 1e-13 * scale)) return 1;
        Lc[j * n + j] = sqrt(d);
        for (int i = j + 1; i < n; ++i) {
            double t = D[i * n + j];
            for (int m = 0; m < j; ++m) t -= Lc[i * n + m] * Lc[j * n + m];
            Lc[i * n + j] = t / Lc[j * n + j];
        }
    }
    for (int c = 0; c < n; ++c) {  /* columns of L⁻¹, then Dinv = L⁻ᵀ L⁻¹ */
        for (int i = 0; i < n; ++i) {
            double t = i == c ? 1.0 : 0.0;
            for (int m = 0; m < i; ++m) t -= Lc[i * n + m] * Y[m * n + c];
            Y[i * n + c] = i < c ? 0.0 : t / Lc[i * n + i];
        }
    }
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            double t = 0.0;
            for (int m = 0; m < n; ++m) t += Y[m * n + i] * Y[m * n + j];
            Dinv[i * n + j] = t;
        }
    return 0;
}

/* The articulated-body recursion (Featherstone), about the inertial origin in inertial
   components, for trees whose coordinates each belong to one joint. With X_i = Σ_(a above or
   at i) S_a·ÿ_a, the wrench a joint transmits is f_i = I^A_i·X_i + p^A_i; its free directions
   carry none (S_iᵀ·f_i = 0), which gives ÿ_i = −D_i⁻¹(U_iᵀ·X_λ + S_iᵀ·p^A_i), D = SᵀI^A S,
   U = I^A S, and the parent gains I^A − U D⁻¹ Uᵀ and p^A − U D⁻¹ Sᵀp^A. Body wrenches start
   from q̄^c − q̄^e at ÿ = 0 (B − W). O(f) per state; ÿ and every joint wrench. */
#define JD_ABA_ARRAYS(JD_X) \
    JD_X(double, IA, 36 * JD_P) JD_X(double, pA, 6 * JD_P) JD_X(double, U, 36 * JD_P) \
    JD_X(double, Dinv, 36 * JD_P) JD_X(double, u, 6 * JD_P) JD_X(double, X, 6 * JD_P)
typedef struct { JD_ABA_ARRAYS(JD_ARRAY) } jd_aba_work;

static int jd_aba(const jd_work *W, jd_aba_work *A, double *ydd, double *wrench) {
    double scale = 0.0;
    for (int i = 0; i < JD_P; ++i) {
        const double *Ib = W->Ic + 13 * i, *h = Ib + 9;
        double *IA = A->IA + 36 * i;
        /* [[Ī, h̃], [−h̃, m E]]: twist (w, u) -> wrench (moment, force) */
        double H[9] = {0, -h[2], h[1], h[2], 0, -h[0], -h[1], h[0], 0};
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) {
                IA[6 * r + c] = Ib[3 * r + c];
                IA[6 * r + 3 + c] = H[3 * r + c];
                IA[6 * (3 + r) + c] = -H[3 * r + c];
                IA[6 * (3 + r) + 3 + c] = r == c ? Ib[12] : 0.0;
            }
        for (int a = 0; a < 6; ++a) A->pA[6 * i + a] = W->Bc[6 * i + a] - W->Wb[6 * i + a];
        scale = fmax(scale, fmax(Ib[12], fmax(Ib[0], fmax(Ib[4], Ib[8]))));
    }
    for (int i = JD_P - 1; i >= 0; --i) {
        int c0 = jd_col_start[i], n = jd_col_start[i + 1] - c0, lam = jd_parent[i];
        const double *S = W->V + 6 * c0;  /* column k at S + 6k */
        double *IA = A->IA + 36 * i, *pA = A->pA + 6 * i, *U = A->U + 36 * i;
        double *Dinv = A->Dinv + 36 * i, *u = A->u + 6 * i, D[36];
        if (n == 1) {  /* one column: D a number, the updates symmetric */
            for (int r = 0; r < 6; ++r) U[r] = jd_dot6(IA + 6 * r, S);
            const double d = jd_dot6(S, U);
            if (!(d > 1e-13 * scale)) return 1;
            Dinv[0] = 1.0 / d;
            u[0] = jd_dot6(S, pA);
            if (lam < 0) continue;
            double *IAp = A->IA + 36 * lam, *pAp = A->pA + 6 * lam;
            const double g = Dinv[0] * u[0];
            for (int r = 0; r < 6; ++r) {
                pAp[r] += pA[r] - U[r] * g;
                const double e = Dinv[0] * U[r];
                IAp[7 * r] += IA[7 * r] - e * U[r];
                for (int c = r + 1; c < 6; ++c) {
                    const double v = IA[6 * r + c] - e * U[c];
                    IAp[6 * r + c] += v;
                    IAp[6 * c + r] += v;
                }
            }
            continue;
        }
        for (int k = 0; k < n; ++k)
            for (int r = 0; r < 6; ++r) {
                double t = 0.0;
                for (int c = 0; c < 6; ++c) t += IA[6 * r + c] * S[6 * k + c];
                U[6 * k + r] = t;
            }
        for (int k = 0; k < n; ++k) {
            u[k] = jd_dot6(S + 6 * k, pA);
            for (int l = 0; l < n; ++l) D[k * n + l] = jd_dot6(S + 6 * k, U + 6 * l);
        }
        if (n && jd_spd_inverse(n, D, Dinv, scale)) return 1;
        if (lam < 0) continue;
        double *IAp = A->IA + 36 * lam, *pAp = A->pA + 6 * lam, Du[6];
        for (int k = 0; k < n; ++k) {
            Du[k] = 0.0;
            for (int l = 0; l < n; ++l) Du[k] += Dinv[k * n + l] * u[l];
        }
        double E[36];  /* E = D⁻¹ Uᵀ (n × 6): the update is then U E, symmetric */
        for (int k = 0; k < n; ++k)
            for (int c = 0; c < 6; ++c) {
                double t = 0.0;
                for (int l = 0; l < n; ++l) t += Dinv[k * n + l] * U[6 * l + c];
                E[6 * k + c] = t;
            }
        for (int r = 0; r < 6; ++r) {
            double t = pA[r];
            for (int k = 0; k < n; ++k) t -= U[6 * k + r] * Du[k];
            pAp[r] += t;
            for (int c = r; c < 6; ++c) {
                double s = IA[6 * r + c];
                for (int k = 0; k < n; ++k) s -= U[6 * k + r] * E[6 * k + c];
                IAp[6 * r + c] += s;
                if (c > r) IAp[6 * c + r] += s;
            }
        }
    }
    for (int i = 0; i < JD_P; ++i) {
        int c0 = jd_col_start[i], n = jd_col_start[i + 1] - c0, lam = jd_parent[i];
        const double *S = W->V + 6 * c0, *U = A->U + 36 * i, *Dinv = A->Dinv + 36 * i;
        const double *u = A->u + 6 * i;
        double *X = A->X + 6 * i, r[6];
        for (int a = 0; a < 6; ++a) X[a] = lam < 0 ? 0.0 : A->X[6 * lam + a];
        if (n == 1 && !wrench) {
            const double a1 = -Dinv[0] * (jd_dot6(U, X) + u[0]);
            ydd[jd_col_coord[c0]] = a1;
            for (int a = 0; a < 6; ++a) X[a] += S[a] * a1;
            continue;
        }
        for (int k = 0; k < n; ++k) r[k] = jd_dot6(U + 6 * k, X) + u[k];
        for (int k = 0; k < n; ++k) {
            double t = 0.0;
            for (int l = 0; l < n; ++l) t -= Dinv[k * n + l] * r[l];
            ydd[jd_col_coord[c0 + k]] = t;
        }
        for (int k = 0; k < n; ++k)
            for (int a = 0; a < 6; ++a) X[a] += S[6 * k + a] * ydd[jd_col_coord[c0 + k]];
        if (wrench) {
            const double *IA = A->IA + 36 * i;
            for (int a = 0; a < 6; ++a) {
                double t = A->pA[6 * i + a];
                for (int c = 0; c < 6; ++c) t += IA[6 * a + c] * X[c];
                wrench[6 * i + a] = t;
            }
        }
    }
    for (int i = 0; i < JD_F; ++i) if (!isfinite(ydd[i])) return 2;
    return 0;
}
#endif

#ifndef JD_RUNTIME  /* the joint wrenches and the entry points (not in the runtime-sized engine) */
/* a wrench about the inertial origin (moment, force) in body i's frame at its origin (F, T) */
static void jd_to_joint_frames(const jd_work *W, double *wrench) {
    for (int i = 0; i < JD_P; ++i) {
        double *T = wrench + 6 * i, m[3], oF[3], Fc[3], mc[3];
        const double *R = W->fr[i].R, *o = W->fr[i].o;
        jd_cross(o, T + 3, oF);
        for (int a = 0; a < 3; ++a) m[a] = T[a] - oF[a];
        jd_mtv(R, T + 3, Fc);
        jd_mtv(R, m, mc);
        for (int a = 0; a < 3; ++a) { T[a] = Fc[a]; T[3 + a] = mc[a]; }
    }
}

/* per state: ÿ (f) and the joint wrenches (6p) of the forward dynamics (the articulated-body
   recursion where every coordinate belongs to one joint, else LDLᵀ of the projected M and the
   sub-tree sums); returns 0, 1 (M not positive definite) or 2 (NaN) */
/* the work of the recursion at a state, on the heap with ``extra`` bytes after it (W + 1) */
static jd_work *jd_at_state(const double *y, const double *yd, double t, const double *p,
                            const double *u, size_t extra) {
    double L[JD_NL > 0 ? JD_NL : 1];
    jd_work *W = (jd_work *)malloc(sizeof(jd_work) + extra);
    if (!W) return NULL;
    jd_local(y, yd, t, p, u, L);
    jd_recursion(L, yd, W, JD_ABA);
    return W;
}

int jd_dynamics(const double *y, const double *yd, double t, const double *p, const double *u,
                double *ydd, double *wrench) {
#if JD_ABA
    jd_work *W = jd_at_state(y, yd, t, p, u, sizeof(jd_aba_work));
    if (!W) return 2;
    int status = jd_aba(W, (jd_aba_work *)(W + 1), ydd, wrench);
    if (status == 0) jd_to_joint_frames(W, wrench);
#else
    /* after the work: M, k, q and the factor of M */
    jd_work *W = jd_at_state(y, yd, t, p, u, sizeof(double) * (2 * JD_F * JD_F + 2 * JD_F));
    if (!W) return 2;
    double *Mkq = (double *)(W + 1), *Lf = Mkq + JD_F * JD_F + 2 * JD_F;
    jd_project(W, Mkq, Mkq + JD_F * JD_F, Mkq + JD_F * JD_F + JD_F);
    int status = jd_solve_mkq(Mkq, Mkq + JD_F * JD_F, Mkq + JD_F * JD_F + JD_F, ydd, Lf);
    if (status == 0) {
        jd_wrenches_of(ydd, W, wrench);
        jd_to_joint_frames(W, wrench);
    }
#endif
    free(W);
    return status;
}

long jd_dynamics_batch(long n, long f, const double *y, const double *yd, const double *t,
                       const double *p, long p_stride, const double *u, long u_stride,
                       double *ydd, double *wrench) {
    for (long i = 0; i < n; ++i)
        if (jd_dynamics(y + i * f, yd + i * f, t[i], p + i * p_stride, u + i * u_stride,
                        ydd + i * JD_F, wrench + i * 6 * JD_P) != 0) return i;
    return -1;
}

#if defined(JD_ACCEL_ABA) && JD_ABA
/* the integrator's right-hand side by the articulated-body recursion: ÿ, and the power ẏᵀq of
   the applied forces (q_j = Σ over the columns of coordinate j of V·(Σ q̄^e as a wrench)) */
int jd_accel(const double *y, const double *yd, double t, const double *p, const double *u,
             double *ydd, double *power) {
    jd_work *W = jd_at_state(y, yd, t, p, u, sizeof(jd_aba_work));
    if (!W) return 2;
    *power = jd_power(W, yd);
    int status = jd_aba(W, (jd_aba_work *)(W + 1), ydd, NULL);
    free(W);
    return status;
}
#endif
#endif
