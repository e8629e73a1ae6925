/* Small 3-vector helpers (internal, header only). */
#ifndef CCN_BASE_VEC3_H
#define CCN_BASE_VEC3_H

#include <math.h>

/* Two doubles in one register (GCC / Clang vector extension; SSE2 on x86-64, NEON on arm64):
 * the x and y components of a sum side by side, each lane computing what the scalar code
 * would (no contraction: -std=c11), so results are bit-identical to the scalar path. */
#if defined(__GNUC__) && !defined(CCN_NO_V2D)
typedef double ccn__v2d __attribute__((vector_size(16)));
#define CCN_V2D 1
#endif

static inline void ccn__cross3(const double a[3], const double b[3], double c[3]) {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

static inline double ccn__dist3(const double a[3], const double b[3]) {
    double x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
    return sqrt(x * x + y * y + z * z);
}

/* Unit normal du x dv; (0,0,1) for degenerate geometry (documented fallback). */
static inline void ccn__unit_normal(const double du[3], const double dv[3], double n[3]) {
    ccn__cross3(du, dv, n);
    double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (l > 0 && isfinite(l)) { n[0] /= l; n[1] /= l; n[2] /= l; }
    else { n[0] = 0; n[1] = 0; n[2] = 1; } /* degenerate cage geometry: documented fallback */
}

#endif
