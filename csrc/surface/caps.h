/* The guided bi-5 caps of a plan (internal; surface/caps.c). */
#ifndef CCN_SURFACE_CAPS_H
#define CCN_SURFACE_CAPS_H

#include "surface/plan_types.h"

void ccn__cap_free(ccn__cap *c);
/* Chooses the cap level K, builds the caps (cap = GUIDED_BI5; else K = -1). */
ccn_status ccn__caps_setup(ccn_plan *p, ccn_error *err);
/* Evaluates the caps and the bicubic ring faces around them into out (after the levels'
 * points and the limit stencils); written (may be NULL) gets 1 at every output vertex written. */
ccn_status ccn__caps_evaluate(ccn_plan *p, ccn_limit_mesh *out, uint8_t *written, ccn_error *err);

#endif
