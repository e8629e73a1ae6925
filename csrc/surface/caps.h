/* The guided bi-5 caps of a plan (internal; surface/caps.c). */
#ifndef CCN_SURFACE_CAPS_H
#define CCN_SURFACE_CAPS_H

#include "surface/plan_types.h"

#define CCN_CAP_MAX_VALENCE 32

void ccn__cap_free(ccn__cap *c);
/* Chooses the cap level K, builds the caps (cap = GUIDED_BI5; else K = -1). */
ccn_status ccn__caps_setup(ccn_plan *p, ccn_error *err);
/* Evaluates the caps and the bicubic ring faces around them into out (after the levels'
 * points and the limit stencils); written (may be NULL) gets 1 at every output vertex written. */
ccn_status ccn__caps_evaluate(ccn_plan *p, ccn_limit_mesh *out, uint8_t *written, ccn_error *err);

/* A guided bi-5 cap with the exact surround (bi5.h [R13], [R14]) for vertex ev of a mesh mK
 * and its refinement mK1, from the meshes alone: the CAD export's holes (io/fill.c), where a
 * cap-level vertex the plan could not cap (a semi-sharp crease still decaying around it) is
 * smooth and isolated a few levels deeper. rings 0: the cap right after the first ring (the
 * holes' default), 1: the plan's further rings too (valence 5 and more; caps.c says why). ops
 * holds the operators, made on first use (CCN_CAP_OPS pointers, NULL at first; free with
 * ccn__cap_ops_free). Returns 1 with *op and patches
 * (ccn__bi5_num_patches(*op) x 36 x 3 doubles, mK's coordinates; caller frees) when ev is a
 * smooth interior EV, isolated by three regular rings, its spokes within the cap's kappa
 * range (no blending with the refined limit; any_kappa: any spoke ratios, the non-uniform
 * construction of bi5.h [R8]-[R13] wherever its tau does not fold, beyond the range with the
 * guide's domain border_exp of [R15]), and the construction succeeds; 0 when it does not
 * qualify; -1 out of memory. */
#define CCN_CAP_OPS (2 * (CCN_CAP_MAX_VALENCE + 1))
int ccn__cap_exact(const ccn_mesh *mK, const ccn_mesh *mK1, int32_t ev, int scheme,
                   int32_t ev_poly, ccn__ev_cache *cache, int pinned, int any_kappa, double border_exp,
                   int rings, struct ccn__bi5 **ops, const struct ccn__bi5 **op, double **patches);
void ccn__cap_ops_free(struct ccn__bi5 **ops);

#endif
