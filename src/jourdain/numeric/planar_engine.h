
/* The recursion of recursive_engine.h for planar systems (numeric/planar_recursion.py): every
   body turns about the inertial z axis and moves in planes z = const (for another plane, its
   axes in cyclic order play x, y and z). Twists (w, ux, uy): the
   angular velocity about z and the velocity of the body point at the inertial origin; wrenches
   (mz, Fx, Fy): the moment about the origin's z axis and the in-plane force; the power of a
   wrench on a twist is w·mz + ux·Fx + uy·Fy. The components across the plane are carried by
   the joints and enter neither M, k, q nor ÿ. A body's inertia about the origin is
   (J, hx, hy, m): J = I_zz + m(cx² + cy²), h = m·c, with c its centre of mass, and acts on a
   twist as [[J, −hy, hx], [−hy, m, 0], [hx, 0, m]]. */

/* per body of the local array: c, s (A's first column), d (2), ω̄z, v̄ (2), ᾱz, ā (2), m,
   com (2), I_zz, f (2), l_z; per column: J_R,z, J_T (2) */
#define JD_PB 17

/* The work's arrays, by type, name and length, as an X-macro: JD_ARRAY makes each an array
   of its length here, and a pointer into one allocation in the runtime-sized engine
   (runtime_head.h, whose JD_RT_FIELD adds the sizes and tables it reads) */
#ifndef JD_ARRAY
#define JD_ARRAY(type, name, n) type name[n];
#define JD_RT_FIELD
#endif
#define JD_PLANE_ARRAYS(JD_X) \
    JD_X(double, c, JD_P) JD_X(double, s, JD_P) JD_X(double, o, 2 * JD_P) JD_X(double, w, JD_P) \
    JD_X(double, v, 2 * JD_P) JD_X(double, al, JD_P) JD_X(double, a, 2 * JD_P) \
    JD_X(double, V, 3 * JD_NC) \
    JD_X(double, I, 4 * JD_P) JD_X(double, B, 3 * JD_P) JD_X(double, Wr, 3 * JD_P) /* own */ \
    JD_X(double, Ic, 4 * JD_P) JD_X(double, Bc, 3 * JD_P) JD_X(double, Wc, 3 * JD_P) /* sub-tree */
typedef struct { JD_PLANE_ARRAYS(JD_ARRAY) JD_RT_FIELD } jd_plane;

static inline double jd_dot3(const double *a, const double *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
/* planar inertia (J, hx, hy, m) times a twist */
static inline void jd_inertia_twist3(const double *I, const double *V, double *F) {
    F[0] = I[0] * V[0] - I[2] * V[1] + I[1] * V[2];
    F[1] = I[3] * V[1] - I[2] * V[0];
    F[2] = I[3] * V[2] + I[1] * V[0];
}

/* own_only (the articulated bodies): only Wc is summed over the sub-trees (for the power
   ẏᵀq); the articulated-body pass reads each body's own I, B, Wr */
static void jd_plane_recursion(const double *L, const double *yd, jd_plane *W, int own_only) {
    for (int i = 0; i < JD_P; ++i) {
        const double *b = L + i * JD_PB;
        const double cA = b[0], sA = b[1], *d = b + 2, *vb = b + 5, *ab = b + 8;
        const double m = b[10], *com = b + 11, Izz = b[13], *fe = b + 14, le = b[16];
        const int lam = jd_parent[i];
        const double cl = lam < 0 ? 1.0 : W->c[lam], sl = lam < 0 ? 0.0 : W->s[lam];
        const double oxl = lam < 0 ? 0.0 : W->o[2 * lam], oyl = lam < 0 ? 0.0 : W->o[2 * lam + 1];
        const double wl = lam < 0 ? 0.0 : W->w[lam], all = lam < 0 ? 0.0 : W->al[lam];
        const double vxl = lam < 0 ? 0.0 : W->v[2 * lam], vyl = lam < 0 ? 0.0 : W->v[2 * lam + 1];
        const double axl = lam < 0 ? 0.0 : W->a[2 * lam], ayl = lam < 0 ? 0.0 : W->a[2 * lam + 1];
        /* S_i = S_λ A_i, r_O,i = r_O,λ + S_λ d_i */
        const double c = cl * cA - sl * sA, s = sl * cA + cl * sA;
        W->c[i] = c; W->s[i] = s;
        const double dwx = cl * d[0] - sl * d[1], dwy = sl * d[0] + cl * d[1];
        const double ox = oxl + dwx, oy = oyl + dwy;
        W->o[2 * i] = ox; W->o[2 * i + 1] = oy;
        /* relative velocities from the joint's columns */
        double rho = b[4], ddx = vb[0], ddy = vb[1];
        const double *cols = L + JD_COLS + 3 * jd_col_start[i];
        for (int k = jd_col_start[i]; k < jd_col_start[i + 1]; ++k, cols += 3) {
            const double q = yd[jd_col_coord[k]];
            rho += cols[0] * q; ddx += cols[1] * q; ddy += cols[2] * q;
        }
        const double ddwx = cl * ddx - sl * ddy, ddwy = sl * ddx + cl * ddy;
        const double w = wl + rho, al = all + b[7];
        W->w[i] = w; W->al[i] = al;
        W->v[2 * i] = vxl - wl * dwy + ddwx;
        W->v[2 * i + 1] = vyl + wl * dwx + ddwy;
        const double abx = cl * ab[0] - sl * ab[1], aby = sl * ab[0] + cl * ab[1];
        const double ax = axl - all * dwy - wl * wl * dwx - 2.0 * wl * ddwy + abx;
        const double ay = ayl + all * dwx - wl * wl * dwy + 2.0 * wl * ddwx + aby;
        W->a[2 * i] = ax; W->a[2 * i + 1] = ay;
        /* twist columns about the origin: w = J_R,z, u = S_λ J_T + r_O × w */
        cols = L + JD_COLS + 3 * jd_col_start[i];
        for (int k = jd_col_start[i]; k < jd_col_start[i + 1]; ++k, cols += 3) {
            double *V = W->V + 3 * k;
            V[0] = cols[0];
            V[1] = cl * cols[1] - sl * cols[2] + oy * cols[0];
            V[2] = sl * cols[1] + cl * cols[2] - ox * cols[0];
        }
        /* centre of mass, its acceleration at ÿ = 0, and the wrenches about the origin of
           q̄^c (m·a_c, I_zz·α) and of the applied forces (f, l_z) */
        const double cwx = c * com[0] - s * com[1], cwy = s * com[0] + c * com[1];
        const double ccx = ox + cwx, ccy = oy + cwy;
        const double acx = ax - al * cwy - w * w * cwx, acy = ay + al * cwx - w * w * cwy;
        double *B = W->B + 3 * i, *Wr = W->Wr + 3 * i, *I = W->I + 4 * i;
        B[1] = m * acx; B[2] = m * acy;
        B[0] = ccx * B[2] - ccy * B[1] + Izz * al;
        Wr[1] = fe[0]; Wr[2] = fe[1];
        Wr[0] = ccx * fe[1] - ccy * fe[0] + le;
        I[0] = Izz + m * (ccx * ccx + ccy * ccy); I[1] = m * ccx; I[2] = m * ccy; I[3] = m;
    }
    for (int a = 0; a < 3 * JD_P; ++a) W->Wc[a] = W->Wr[a];
    if (!own_only) {
        for (int a = 0; a < 4 * JD_P; ++a) W->Ic[a] = W->I[a];
        for (int a = 0; a < 3 * JD_P; ++a) W->Bc[a] = W->B[a];
    }
    for (int i = JD_P - 1; i >= 0; --i) {  /* composite bodies: children before parents */
        const int lam = jd_parent[i];
        if (lam < 0) continue;
        for (int a = 0; a < 3; ++a) W->Wc[3 * lam + a] += W->Wc[3 * i + a];
        if (own_only) continue;
        for (int a = 0; a < 4; ++a) W->Ic[4 * lam + a] += W->Ic[4 * i + a];
        for (int a = 0; a < 3; ++a) W->Bc[3 * lam + a] += W->Bc[3 * i + a];
    }
}

/* M = J̄ᵀM̄J̄, k = J̄ᵀq̄^c, q = J̄ᵀq̄^e from the composite bodies (recursive_engine.h's
   jd_project in planar vectors) */
static void jd_plane_project(const jd_plane *W, double *M, double *k, double *q) {
    for (int a = 0; a < JD_F * JD_F; ++a) M[a] = 0.0;
    for (int a = 0; a < JD_F; ++a) { k[a] = 0.0; q[a] = 0.0; }
    for (int b = 0; b < JD_P; ++b) {
        for (int c = jd_col_start[b]; c < jd_col_start[b + 1]; ++c) {
            const double *V = W->V + 3 * c;
            const int kc = jd_col_coord[c];
            k[kc] += jd_dot3(V, W->Bc + 3 * b);
            q[kc] += jd_dot3(V, W->Wc + 3 * b);
            double Fv[3];
            jd_inertia_twist3(W->Ic + 4 * b, V, Fv);
            for (int a = b; a >= 0; a = jd_parent[a]) {
                const int last = a == b ? c + 1 : jd_col_start[a + 1];
                for (int e = jd_col_start[a]; e < last; ++e) {
                    double val = jd_dot3(W->V + 3 * e, Fv);
                    const int je = jd_col_coord[e];
                    if (je == kc && a != b) val *= 2.0;
                    if (je <= kc) M[je * JD_F + kc] += val; else M[kc * JD_F + je] += val;
                }
            }
        }
    }
    for (int r = 1; r < JD_F; ++r)
        for (int s = 0; s < r; ++s) M[r * JD_F + s] = M[s * JD_F + r];
}

/* the power ẏᵀq of the applied forces (q_j: the columns of coordinate j on the wrenches
   of q̄^e summed over their sub-trees) */
static double jd_plane_power(const jd_plane *W, const double *yd) {
    double w = 0.0;
    for (int b = 0; b < JD_P; ++b)
        for (int c = jd_col_start[b]; c < jd_col_start[b + 1]; ++c)
            w += yd[jd_col_coord[c]] * jd_dot3(W->V + 3 * c, W->Wc + 3 * b);
    return w;
}

#ifndef JD_RUNTIME  /* the entry points; the runtime-sized engine has its own (runtime_engine.h) */
/* the work on the stack when small (JD_PLANE_STACK, as recursive_engine.h's JD_WORK_STACK:
   threads may have small stacks), else on the heap */
void jd_fn(const double *y, const double *yd, double t, const double *p, const double *u,
           double *out) {
    double L[JD_NL > 0 ? JD_NL : 1];
#if JD_PLANE_STACK
    jd_plane work, *W = &work;
#else
    jd_plane *W = (jd_plane *)malloc(sizeof(jd_plane));
    if (!W) { for (long a = 0; a < JD_F * JD_F + 2 * JD_F; ++a) out[a] = NAN; return; }
#endif
    jd_local(y, yd, t, p, u, L);
    jd_plane_recursion(L, yd, W, 0);
    jd_plane_project(W, out, out + JD_F * JD_F, out + JD_F * JD_F + JD_F);
#if !JD_PLANE_STACK
    free(W);
#endif
}
#endif

/* jd_fn_batch: ccode.batch_source, appended by planar_recursion.py */

#if JD_ABA
/* The articulated-body recursion (recursive_engine.h's jd_aba) in planar vectors: the
   articulated inertias are symmetric 3×3 (a00 a01 a02 a11 a12 a22); a joint has at most three
   columns in the plane. Returns 0, 1 (a joint's D not positive definite) or 2 (NaN). */
static inline void jd_sym3_mul(const double *A, const double *x, double *r) {
    r[0] = A[0] * x[0] + A[1] * x[1] + A[2] * x[2];
    r[1] = A[1] * x[0] + A[3] * x[1] + A[4] * x[2];
    r[2] = A[2] * x[0] + A[4] * x[1] + A[5] * x[2];
}

/* D⁻¹ of a symmetric positive definite n×n D (n ≤ 3) by Cholesky; 1 if not positive definite */
static int jd_small_inverse(int n, const double *D, double *Dinv, double scale) {
    double Lc[9] = {0}, Y[9] = {0};
    for (int j = 0; j < n; ++j) {
        double d = D[j * n + j];
        for (int m = 0; m < j; ++m) d -= Lc[j * 3 + m] * Lc[j * 3 + m];
        if (!(d > 1e-13 * scale)) return 1;
        Lc[j * 3 + j] = sqrt(d);
        for (int i = j + 1; i < n; ++i) {
            double t = D[i * n + j];
            for (int m = 0; m < j; ++m) t -= Lc[i * 3 + m] * Lc[j * 3 + m];
            Lc[i * 3 + j] = t / Lc[j * 3 + j];
        }
    }
    for (int c = 0; c < n; ++c)
        for (int i = c; i < n; ++i) {
            double t = i == c ? 1.0 : 0.0;
            for (int m = c; m < i; ++m) t -= Lc[i * 3 + m] * Y[m * 3 + c];
            Y[i * 3 + c] = t / Lc[i * 3 + i];
        }
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            double t = 0.0;
            for (int m = 0; m < n; ++m) t += Y[m * 3 + i] * Y[m * 3 + j];
            Dinv[i * n + j] = t;
        }
    return 0;
}

#define JD_PLANE_ABA_ARRAYS(JD_X) \
    JD_X(double, IA, 6 * JD_P) JD_X(double, pA, 3 * JD_P) JD_X(double, U, 3 * JD_NC) \
    JD_X(double, Dinv, 9 * JD_P) JD_X(double, uu, JD_NC) JD_X(double, X, 3 * JD_P)
typedef struct { JD_PLANE_ABA_ARRAYS(JD_ARRAY) } jd_plane_aba_work;

static int jd_plane_aba(const jd_plane *W, jd_plane_aba_work *K, double *ydd) {
    double *IA = K->IA, *pA = K->pA, *U = K->U, *Dinv = K->Dinv, *uu = K->uu, *X = K->X;
    double scale = 0.0;
    for (int i = 0; i < JD_P; ++i) {
        const double *I = W->I + 4 * i;
        double *A = IA + 6 * i;
        A[0] = I[0]; A[1] = -I[2]; A[2] = I[1]; A[3] = I[3]; A[4] = 0.0; A[5] = I[3];
        for (int a = 0; a < 3; ++a) pA[3 * i + a] = W->B[3 * i + a] - W->Wr[3 * i + a];
        scale = fmax(scale, fmax(I[0], I[3]));
    }
    for (int i = JD_P - 1; i >= 0; --i) {
        const int c0 = jd_col_start[i], n = jd_col_start[i + 1] - c0, lam = jd_parent[i];
        const double *S = W->V + 3 * c0;
        double *A = IA + 6 * i, *p = pA + 3 * i, *Ui = U + 3 * c0, *ui = uu + c0;
        double *Di = Dinv + 9 * i;
        if (n == 1) {
            jd_sym3_mul(A, S, Ui);
            const double D = jd_dot3(S, Ui);
            if (!(D > 1e-13 * scale)) return isfinite(D) ? 1 : 2;
            Di[0] = 1.0 / D;
            ui[0] = jd_dot3(S, p);
            if (lam < 0) continue;
            double *Ap = IA + 6 * lam, *pp = pA + 3 * lam;
            const double g = Di[0] * ui[0];
            const double e0 = Di[0] * Ui[0], e1 = Di[0] * Ui[1], e2 = Di[0] * Ui[2];
            for (int a = 0; a < 3; ++a) pp[a] += p[a] - Ui[a] * g;
            Ap[0] += A[0] - e0 * Ui[0]; Ap[1] += A[1] - e0 * Ui[1];
            Ap[2] += A[2] - e0 * Ui[2]; Ap[3] += A[3] - e1 * Ui[1];
            Ap[4] += A[4] - e1 * Ui[2]; Ap[5] += A[5] - e2 * Ui[2];
            continue;
        }
        double D[9];
        for (int k = 0; k < n; ++k) { jd_sym3_mul(A, S + 3 * k, Ui + 3 * k); ui[k] = jd_dot3(S + 3 * k, p); }
        for (int k = 0; k < n; ++k)
            for (int l = 0; l < n; ++l) D[k * n + l] = jd_dot3(S + 3 * k, Ui + 3 * l);
        if (n && jd_small_inverse(n, D, Di, scale)) return 1;
        if (lam < 0) continue;
        double *Ap = IA + 6 * lam, *pp = pA + 3 * lam, Du[3] = {0, 0, 0}, E[9] = {0};
        for (int k = 0; k < n; ++k)
            for (int l = 0; l < n; ++l) Du[k] += Di[k * n + l] * ui[l];
        for (int r = 0; r < 3; ++r)  /* E = D⁻¹ Uᵀ, n × 3 */
            for (int k = 0; k < n; ++k)
                for (int l = 0; l < n; ++l) E[3 * k + r] += Di[k * n + l] * Ui[3 * l + r];
        static const int row[6] = {0, 0, 0, 1, 1, 2}, col[6] = {0, 1, 2, 1, 2, 2};
        for (int a = 0; a < 3; ++a) {
            double t = p[a];
            for (int k = 0; k < n; ++k) t -= Ui[3 * k + a] * Du[k];
            pp[a] += t;
        }
        for (int e = 0; e < 6; ++e) {
            double t = A[e];
            for (int k = 0; k < n; ++k) t -= Ui[3 * k + row[e]] * E[3 * k + col[e]];
            Ap[e] += t;
        }
    }
    for (int i = 0; i < JD_P; ++i) {
        const int c0 = jd_col_start[i], n = jd_col_start[i + 1] - c0, lam = jd_parent[i];
        const double *S = W->V + 3 * c0, *Ui = U + 3 * c0, *Di = Dinv + 9 * i;
        double *Xi = X + 3 * i, r[3];
        for (int a = 0; a < 3; ++a) Xi[a] = lam < 0 ? 0.0 : X[3 * lam + a];
        for (int k = 0; k < n; ++k) r[k] = jd_dot3(Ui + 3 * k, Xi) + uu[c0 + k];
        for (int k = 0; k < n; ++k) {
            double t = 0.0;
            for (int l = 0; l < n; ++l) t -= Di[k * n + l] * r[l];
            ydd[jd_col_coord[c0 + k]] = t;
        }
        for (int k = 0; k < n; ++k)
            for (int a = 0; a < 3; ++a) Xi[a] += S[3 * k + a] * ydd[jd_col_coord[c0 + k]];
    }
    for (int i = 0; i < JD_F; ++i) if (!isfinite(ydd[i])) return 2;
    return 0;
}

#ifndef JD_RUNTIME
/* the integrator's right-hand side: ÿ by the articulated bodies, O(f), and the power ẏᵀq of
   the applied forces */
int jd_accel(const double *y, const double *yd, double t, const double *p, const double *u,
             double *ydd, double *power) {
    double L[JD_NL > 0 ? JD_NL : 1];
    typedef struct { jd_plane W; jd_plane_aba_work K; } jd_plane_all;
#if JD_PLANE_STACK
    jd_plane_all work, *A = &work;
#else
    jd_plane_all *A = (jd_plane_all *)malloc(sizeof(jd_plane_all));
    if (!A) return 2;
#endif
    jd_local(y, yd, t, p, u, L);
    jd_plane_recursion(L, yd, &A->W, 1);
    *power = jd_plane_power(&A->W, yd);
    int status = jd_plane_aba(&A->W, &A->K, ydd);
#if !JD_PLANE_STACK
    free(A);
#endif
    return status;
}
#endif
#endif
