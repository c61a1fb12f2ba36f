/* jourdain, dense linear algebra shared by the kernels of closed systems (loop_c.h) and of
 * general systems (general_c.h): each library's source is the generated code, this, then its
 * kernel (jourdain/loops/compiled.py, general_kernel.py). */
#include <math.h>

/* in place LU with partial pivoting of the r x r row-major A; 1 when singular */
static int jdl_lu(long r, double *A, long *piv) {
    for (long k = 0; k < r; ++k) {
        long p = k;
        double best = fabs(A[k * r + k]);
        for (long i = k + 1; i < r; ++i)
            if (fabs(A[i * r + k]) > best) { best = fabs(A[i * r + k]); p = i; }
        piv[k] = p;
        if (!(best > 0.0)) return 1;
        if (p != k)
            for (long j = 0; j < r; ++j) { double s = A[k * r + j]; A[k * r + j] = A[p * r + j]; A[p * r + j] = s; }
        double inv = 1.0 / A[k * r + k];
        for (long i = k + 1; i < r; ++i) {
            double l = A[i * r + k] *= inv;
            if (l != 0.0)
                for (long j = k + 1; j < r; ++j) A[i * r + j] -= l * A[k * r + j];
        }
    }
    return 0;
}

static void jdl_solve(long r, const double *A, const long *piv, double *b) {
    for (long k = 0; k < r; ++k) if (piv[k] != k) { double s = b[k]; b[k] = b[piv[k]]; b[piv[k]] = s; }
    for (long i = 1; i < r; ++i) { double s = b[i]; for (long k = 0; k < i; ++k) s -= A[i * r + k] * b[k]; b[i] = s; }
    for (long i = r - 1; i >= 0; --i) {
        double s = b[i];
        for (long k = i + 1; k < r; ++k) s -= A[i * r + k] * b[k];
        b[i] = s / A[i * r + i];
    }
}

/* Cholesky in place (lower), refused below 1e-13 of the largest diagonal entry; and its
 * solve (x may be b) */
static int jdl_chol(long n, double *A) {
    double dmax = 0.0;
    for (long i = 0; i < n; ++i) if (fabs(A[i * n + i]) > dmax) dmax = fabs(A[i * n + i]);
    for (long j = 0; j < n; ++j) {
        double d = A[j * n + j];
        for (long k = 0; k < j; ++k) d -= A[j * n + k] * A[j * n + k];
        if (!(d > 1e-13 * dmax)) return 1;
        d = sqrt(d);
        A[j * n + j] = d;
        for (long i = j + 1; i < n; ++i) {
            double a = A[i * n + j];
            for (long k = 0; k < j; ++k) a -= A[i * n + k] * A[j * n + k];
            A[i * n + j] = a / d;
        }
    }
    return 0;
}

static void jdl_chol_solve(long n, const double *C, const double *b, double *x) {
    for (long i = 0; i < n; ++i) {
        double a = b[i];
        for (long k = 0; k < i; ++k) a -= C[i * n + k] * x[k];
        x[i] = a / C[i * n + i];
    }
    for (long i = n - 1; i >= 0; --i) {
        double a = x[i];
        for (long k = i + 1; k < n; ++k) a -= C[k * n + i] * x[k];
        x[i] = a / C[i * n + i];
    }
}
