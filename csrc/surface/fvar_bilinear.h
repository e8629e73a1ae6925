/* Face-varying mode ALL written down (internal; surface/fvar_bilinear.c). */
#ifndef CCN_SURFACE_FVAR_BILINEAR_H
#define CCN_SURFACE_FVAR_BILINEAR_H

#include "surface/fvar_builder.h"
#include "surface/fvar_rows.h"

/* Mode ALL, L >= 1: the rows of every output value (s->nout set; the builder numbered, its
 * firstL the outputs' first fan corners), made final over the caller's values. */
ccn_status ccn__fvar_bilinear_rows(const ccn_plan *p, const ccn__fvar_builder *c,
                                   ccn__fvar_stencils *s, ccn_error *err);

#endif
