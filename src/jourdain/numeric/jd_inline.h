#include <math.h>
#include <stdlib.h>
static inline double jd_sq(double x) { return x * x; }
static inline double jd_cube(double x) { return x * x * x; }
static inline double jd_powi(double x, int n) {
    double r = 1.0; int m = n < 0 ? -n : n;
    while (m) { if (m & 1) r *= x; x *= x; m >>= 1; }
    return n < 0 ? 1.0 / r : r;
}
static inline double jd_sign(double x) { return (double)((x > 0) - (x < 0)); }
