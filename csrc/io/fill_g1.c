/* The CAD export's measure of the fills' G1 and its entry to the G1 fill (io/fill_g1.h; the fill
 * itself: fill/g1_fill.c). */
#include "io/fill_g1.h"

#include "io/cad.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static double angle_between(const double *a, const double *b) {
    double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    return atan2(sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]), a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
}

double ccn__fill_spoke_angle(const double *poles, int32_t deg, const int32_t mu[3], int32_t nfan, int32_t nsp,
                             const uint8_t *smooth, int samples) {
    static const double kn[3] = {0, 1, 2};
    int32_t np = mu[0] + mu[1] + mu[2] - deg - 1; /* poles per direction */
    double worst = 0;
    for (int32_t k = 0; k < nsp; k++) {
        if (!smooth[k]) continue;
        int32_t a = k % nfan, b = (k + nfan - 1) % nfan; /* spoke k: u-axis of a, v-axis of b */
        ccn__cad_surface A = {{deg, deg}, {np, np}, {3, 3}, {kn, kn}, {mu, mu}, poles + 3 * (size_t)np * np * a, {0, 0}};
        ccn__cad_surface B = A;
        B.poles = poles + 3 * (size_t)np * np * b;
        for (int i = 0; i < samples; i++) {
            double t = 2.0 * (i + 0.5) / samples, p[3], du[3], dv[3], na[3], nb[3];
            ccn__cad_eval_d(&A, t, 0, p, du, dv);
            na[0] = du[1] * dv[2] - du[2] * dv[1], na[1] = du[2] * dv[0] - du[0] * dv[2], na[2] = du[0] * dv[1] - du[1] * dv[0];
            ccn__cad_eval_d(&B, 0, t, p, du, dv);
            nb[0] = du[1] * dv[2] - du[2] * dv[1], nb[1] = du[2] * dv[0] - du[0] * dv[2], nb[2] = du[0] * dv[1] - du[1] * dv[0];
            double ang = angle_between(na, nb);
            if (!(ang <= worst)) worst = ang;
        }
    }
    return worst;
}

int ccn__fill_g1(const double (*cs)[5][5][3], int32_t nfan, int32_t nsp, const uint8_t *sharp,
                 const uint8_t *filled, double (*q)[CCN_FILL_G1_POLES][CCN_FILL_G1_POLES][3], double *dev,
                 double *energy) {
    uint8_t *smooth = malloc((size_t)nsp + 1);
    if (!smooth) return -1;
    int r = ccn__fill_g1_solve(cs, nfan, nsp, sharp, filled, NULL, q, smooth, energy);
    static const int32_t MU[3] = {6, 3, 6};
    if (r > 0) *dev = ccn__fill_spoke_angle(&q[0][0][0][0], 5, MU, nfan, nsp, smooth, 16);
    free(smooth);
    return r;
}
