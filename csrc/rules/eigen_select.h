/* The per-vertex choice of the eigen polyhedron (internal; rules/eigen_select.c).
 *
 * M is built from the paper's spoke lengths where the vertex's max/min spoke-interval ratio is
 * <= CCN__EV_TRUST_RATIO. Beyond it, each candidate of rules/eigen_shape.h gets a continuous
 * margin (ccn__ev_margin: the construction's distance from failing, one face-local maximum of
 * the blending function at level 5, the spectrum, the regularity of the characteristic map,
 * each over its band) and the polyhedron is the blend "the first candidate that passes" made
 * continuous (eigen_select.c), so M -- and the surface -- moves continuously with the
 * intervals: no threshold makes it jump. Between CCN__EV_TRUST_RATIO and CCN__EV_VERIFY_RATIO
 * the paper's polyhedron is trusted with a weight falling smoothly from 1 to 0. The choice
 * depends on the normalised interval tuple only (up to rotation and reflection of the spoke
 * order), so a cache (owned by its caller: a plan, one ccn_refine call) keeps it across levels
 * and rebuilds. */
#ifndef CCN_RULES_EIGEN_SELECT_H
#define CCN_RULES_EIGEN_SELECT_H

#include "ccnurbs.h"

#define CCN__EV_TRUST_RATIO 4.0   /* the paper's accepted without checks up to this max/min ratio */
#define CCN__EV_VERIFY_RATIO 5.0  /* ... and fully verified from this one (smooth between) */
/* Margin bands (each margin over its band is >= 1 where the test passes clearly). */
#define CCN__EV_MAXIMA_BAND 0.03
#define CCN__EV_SPECTRUM_BAND 0.03
#define CCN__EV_REGULAR_BAND 0.02
#define CCN__EV_SELECT_LEVELS 5   /* the level of the single-maximum check */
#define CCN__EV_SELECT_MAX_VALENCE 64 /* above: the paper's polyhedron, not verified */

typedef struct ccn__ev_cache ccn__ev_cache;

ccn__ev_cache *ccn__ev_cache_create(void);
void ccn__ev_cache_destroy(ccn__ev_cache *c);
/* Entries held (each a verified choice for one interval tuple). */
size_t ccn__ev_cache_count(const ccn__ev_cache *c);

#include "rules/eigen_shape.h"

typedef struct {
    ccn__poly_blend blend; /* the polyhedron: candidates and weights */
    int32_t poly;     /* the candidate of the largest weight (CCN_POLY_PAPER.. CCN_POLY_COUNT) */
    int32_t verified; /* candidates verified (0: accepted without checks) */
    int32_t outside;  /* 1: half the weight or more on candidates that fail the checks */
    int32_t cached;   /* 1: taken from the cache */
} ccn__ev_choice;

/* The choice for n normalised intervals nd (ccn__ev_normalise); cache may be NULL. Returns
 * CCN_OK or CCN_ERR_MEMORY. */
ccn_status ccn__ev_select(int32_t n, const double *nd, ccn__ev_cache *cache, ccn__ev_choice *out);

/* The continuous margin of candidate poly for normalised intervals nd: the smallest of the
 * construction's margin and the maxima, spectrum and regularity margins over their bands
 * (-1 when the map is not injective or the construction fails); > 0 passes every check,
 * >= 1 clearly. *construction (may be NULL): the construction's margin alone (-1 when it
 * fails). NaN when out of memory. */
double ccn__ev_margin(int32_t n, const double *nd, int32_t poly, double *construction);
/* Does candidate poly pass (margin > 0)? 1 yes, 0 no, -1 out of memory. */
int ccn__ev_verify(int32_t n, const double *nd, int32_t poly);

/* ccn_ev_matrix_polyhedron with a cache (NULL: none). */
ccn_status ccn__ev_matrix_cached(int32_t n, const double *spoke_knots, ccn_scheme scheme,
                                 int32_t polyhedron, ccn__ev_cache *cache, double *M,
                                 ccn_ev_info *info, ccn_error *err);

#endif
