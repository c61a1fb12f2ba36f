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

