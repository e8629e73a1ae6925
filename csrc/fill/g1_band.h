/* The G1 fill's banded solve for many spokes (internal to fill/; fill/g1_band.c). */
#ifndef CCN_FILL_G1_BAND_H
#define CCN_FILL_G1_BAND_H

#include "fill/g1_types.h"

#include <stdint.h>

/* The system of the banded solve (many spokes): the unknowns permuted (perm) along the fan, so
 * that all but the border -- the poles that close the cycle -- lie in a band of half-width kd
 * (lower band storage, column-major, for dpbtrf); E (nb x nd, column-major) the band's coupling
 * to the border, D (nd x nd) the border's own block. */
typedef struct {
    int32_t n, nb, nd, kd, ld;
    int32_t *perm;
    double *ab, *E, *D;
} ccn__g1_band;

void ccn__g1_band_add(ccn__g1_band *b, int32_t v, int32_t v2, double e);
int ccn__g1_band_setup(ccn__g1_band *b, int32_t (*idx)[CCN_FILL_G1_POLES][CCN_FILL_G1_POLES], int32_t nfan, int32_t n, const ccn__g1_row *C,
                       int32_t m);
void ccn__g1_band_free(ccn__g1_band *b);
int ccn__g1_least_energy_banded(int32_t m, int32_t n, const ccn__g1_row *C, const double *R, ccn__g1_band *b,
                                const double *H, double *del);

#endif
