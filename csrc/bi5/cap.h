/* The G1 cap of the bi-5 construction (internal; bi5/cap.c). */
#ifndef CCN_BI5_CAP_H
#define CCN_BI5_CAP_H

#include "bi5/bi5_types.h"

/* Cap assembly (SPEC §6.3): gbb (n x 28 x m) the guide, T (n x 36 x m) the last upgraded
 * tensor-border t~^l -> cap (n x 36 x m). kap == NULL: symmetric; else [R9] with the
 * per-sector taus (n x 36). */
ccn_status ccn__bi5_cap(const ccn__bi5 *b, const double *gbb, const double *T, int32_t m,
                        const double *kap, const double complex *taus, double *cap,
                        ccn_error *err);

#endif
