/* The per-vertex choice of the eigen polyhedron (internal; rules/eigen_select.c; issue 14,
 * "Eigen rules: the decision").
 *
 * M is built from the paper's spoke lengths. If the vertex's max/min spoke-interval ratio is
 * <= CCN__EV_TRUST_RATIO it is used without checks. Otherwise it is verified -- one face-local
 * maximum of the blending function at level 5 with no EV fallback, and the exact
 * characteristic-map test (spectrum, regular, injective; rules/eigen_fan.c) -- and, if that
 * fails, the candidates of rules/eigen_shape.h are tried in their fixed order; the first that
 * passes is used. If none passes, the paper's M is used and the vertex is counted as outside
 * the G1 range. The choice depends on the normalised interval tuple only (up to rotation and
 * reflection of the spoke order), so a cache (owned by its caller: a plan, one ccn_refine
 * call) keeps it across levels and rebuilds. */
#ifndef CCN_RULES_EIGEN_SELECT_H
#define CCN_RULES_EIGEN_SELECT_H

#include "ccnurbs.h"

#define CCN__EV_TRUST_RATIO 5.0   /* accepted without checks up to this max/min ratio */
#define CCN__EV_SELECT_LEVELS 5   /* the level of the single-maximum check */
#define CCN__EV_SELECT_MAX_VALENCE 64 /* above: the paper's polyhedron, not verified */

typedef struct ccn__ev_cache ccn__ev_cache;

ccn__ev_cache *ccn__ev_cache_create(void);
void ccn__ev_cache_destroy(ccn__ev_cache *c);
/* Entries held (each a verified choice for one interval tuple). */
size_t ccn__ev_cache_count(const ccn__ev_cache *c);

typedef struct {
    int32_t poly;     /* the chosen candidate (CCN_POLY_PAPER.. CCN_POLY_COUNT) */
    int32_t verified; /* candidates verified (0: accepted without checks) */
    int32_t outside;  /* 1: none passed (the paper's is used) */
    int32_t cached;   /* 1: taken from the cache */
} ccn__ev_choice;

/* The choice for n normalised intervals nd (ccn__ev_normalise); cache may be NULL. Returns
 * CCN_OK or CCN_ERR_MEMORY. */
ccn_status ccn__ev_select(int32_t n, const double *nd, ccn__ev_cache *cache, ccn__ev_choice *out);

/* Does M (built with candidate poly for normalised intervals nd, not a fallback) pass the
 * verification? 1 yes, 0 no, -1 out of memory. */
int ccn__ev_verify(int32_t n, const double *nd, int32_t poly);

/* ccn_ev_matrix_polyhedron with a cache (NULL: none). */
ccn_status ccn__ev_matrix_cached(int32_t n, const double *spoke_knots, ccn_scheme scheme,
                                 int32_t polyhedron, ccn__ev_cache *cache, double *M,
                                 ccn_ev_info *info, ccn_error *err);

#endif
