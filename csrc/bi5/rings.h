/* The rings of the bi-5 construction (internal; bi5/rings.c). */
#ifndef CCN_BI5_RINGS_H
#define CCN_BI5_RINGS_H

#include "bi5/bi5_types.h"

/* C2-rule across every spoke (SPEC §2.4; NU ratio kap[s] for spoke e_s, NULL = 1, SPEC §9.3)
 * on n tensor-borders T (n x 36 x m). */
void ccn__bi5_c2_rule(int32_t n, const double *kap, int32_t m, double *T);
/* t_CC of every sector (SPEC §2.1; knots [R8]), bicubic tensor-borders p (n x 16 x m) from the
 * c-net X ((6n+1) x m), spoke intervals d (NULL: uniform). */
void ccn__bi5_tcc(int32_t n, const double *X, const double *d, int32_t m, double *p);
/* Raises bicubic tensor-borders p (n x 16 x m, [a*4+b], p_00 unused) to bi-5 on the mask:
 * T (n x 36 x m), zero elsewhere (SPEC §2.2). */
void ccn__bi5_raise_border(int32_t n, const double *p, int32_t m, double *T);
/* T (n x 36 x m) = sector s's sampling matrix samp + s * sstride (36 x 28; sstride 0: one for
 * every sector) applied to the guide gbb (n x 28 x m). */
void ccn__bi5_sample_border(int32_t n, const double *samp, size_t sstride, const double *gbb, int32_t m,
                            double *T);
/* Patches A, B, C (36 x m each) of one sector from the outer border To (level r-1) and the
 * inner border Ti (level r) (SPEC §2.5, §5 step 4). */
void ccn__bi5_ring_sector(const double *To, const double *Ti, double sigma, int32_t m,
                          double *A, double *B, double *C);
/* Ring 0 of a sector with sigma = 1/2 from the 4 exact surround pieces P ([R13]). */
void ccn__bi5_ring_sector_pieces(const double *P, const double *Ti, int32_t m, double *A, double *B,
                                 double *C);
/* The guide's least-squares target from the surround pieces ([R13]): T (n x 36 x 3); -1 if the
 * fit fails. */
int ccn__bi5_pieces_target(int32_t n, const double *pieces, double *T);

#endif
