/* The caller's cache of bi-5 operators shared by plans (internal; surface/op_cache.c). */
#ifndef CCN_SURFACE_OP_CACHE_H
#define CCN_SURFACE_OP_CACHE_H

#include "ccnurbs.h"

struct ccn__bi5;

/* The operator for key (valence n, or -n with the exact-surround first ring) with ring speeds
 * sig[0..nsig-1], built on first use; NULL on failure (err filled). Owned by the cache. */
const struct ccn__bi5 *ccn__cache_op(ccn_cache *c, int32_t key, int32_t n, const double *sig,
                                     int32_t nsig, ccn_error *err);

#endif
