/* The guided bi-5 operator struct, constants and inline helpers shared by csrc/bi5/ (internal;
 * no code of its own). See bi5/bi5.h for the construction and its reconstruction choices. */
#ifndef CCN_BI5_TYPES_H
#define CCN_BI5_TYPES_H

#include "ccnurbs.h"

#include <complex.h>
#define CCN_BI5_I _Complex_I
#undef I /* keep the name I free for the files that include this header */
#include <math.h>
#include <stdint.h>

typedef struct ccn__bi5 ccn__bi5; /* precomputed operator for one valence n and sigma sequence */

#define CCN_BI5_MAXSIG 16
#define CCN_BI5_PI 3.14159265358979323846
#define CCN_BI5_NTRI 28 /* coefficients of a total-degree-6 triangle patch */

struct ccn__bi5 {
    int32_t n, nsig, npar;         /* npar = 12n+10 guide parameters (SPEC §4.2) */
    double c, theta;               /* c = cos(2 pi/n), theta = 2 pi/n */
    double sig[CCN_BI5_MAXSIG], lam[CCN_BI5_MAXSIG], Lam[CCN_BI5_MAXSIG];
    double complex chi_half[16];             /* chi~_{1/2}, 4x4 bi-3, [a*4+b] */
    double complex chi[CCN_BI5_MAXSIG][16];  /* chi~_{sigma_r} */
    double complex tau[36];                  /* symmetric cap reparameterisation (sector 0) */
    double samp0[36 * CCN_BI5_NTRI];         /* fit sampling [. o chi~_{1/2}] (27-mask) */
    double samp[CCN_BI5_MAXSIG][36 * CCN_BI5_NTRI]; /* ring r: [. o Lambda_r chi~_{sigma_r}] */
    double scap[36 * CCN_BI5_NTRI];          /* cap: [. o Lambda_l tau] at 4 corners */
    double *gpar;   /* (28n) x npar, row-major: guide parameters -> BB coefficients */
    double *qr;     /* QR of the design matrix J (27n x (npar-1)), column-major */
    double *qtau;   /* npar-1 Householder scalars */
    double *s0;     /* 27n: the sampled border of parameter 0 (b_600) */
    double *qr1;    /* QR of J without parameters 1, 2 (b_510, b_501): 27n x (npar-3) */
    double *qtau1;  /* its npar-3 Householder scalars */
    double *s12;    /* 2 x 27n: the sampled borders of parameters 1 and 2 */
    double *stencil;/* (3 nsig + 1)*36 rows (sector 0) x (6n+2) columns, row-major; column
                     * 6n+1 is the weight of the centre point b_600 */
    double *stencilF; /* the same with the guide's b_510, b_501 given ([R14]): 6n+4 columns,
                       * the last two their weights */
    double *w12;    /* 2 x (6n+2): b_510, b_501 of the plain fit (sector 0) from net and centre */
};

/* omega^k = exp(2 pi i k / n). */
static inline double complex ccn__bi5_omega(int32_t n, int32_t k) {
    double a = 2.0 * CCN_BI5_PI * (double)k / (double)n;
    return cos(a) + sin(a) * CCN_BI5_I;
}
/* The 27-coefficient tensor-border mask (SPEC §1.3): i >= 3 or j >= 3. */
static inline int ccn__bi5_in_mask(int32_t i, int32_t j) { return i >= 3 || j >= 3; }

/* d += w a (m columns). */
static inline void ccn__bi5_axpy(double *d, double w, const double *a, int32_t m) {
    for (int32_t c = 0; c < m; c++) d[c] += w * a[c];
}

#endif
