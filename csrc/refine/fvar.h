/* Face-varying channels (UV maps): the value topology as a mesh that refines with the rules
 * of refine/level.c (internal; refine/fvar.c, public ccn_fvar_* in refine/fvar_refine.c). */
#ifndef CCN_REFINE_FVAR_H
#define CCN_REFINE_FVAR_H

#include "refine/level.h"

/* One level of a channel. m has the faces and half-edges of the vertex mesh it belongs to,
 * in the same order (face f, half-edge h of both are the same corner), and one vertex per
 * value span: the faces around a vertex that share a value across edges whose values agree
 * at both ends. Edges whose values differ (seams) are boundary edges of m. Intervals and
 * sharpness of m's edges and vertices are those of the vertex mesh's; the mode's sharp
 * values (OpenSubdiv's FVarLevel value tags) are infinitely sharp vertices of m. */
typedef struct {
    ccn_mesh *m;
    int32_t *vvert;   /* m->nv: the vertex of the vertex mesh each value vertex lies on */
    uint8_t *corner;  /* m->nv: 1 = kept by the mode (corner), whatever the geometry says */
    int32_t *partner; /* m->nv or NULL: dependent sharpness (see ccn__level.partner), -1 none */
    int linear;       /* ccn_fvar_linear */
    int32_t num_seams;   /* level 0: edges of the vertex mesh whose values differ */
} ccn__fvar_level;

/* Level 0 from the vertex mesh vm (a cage) and one value index per half-edge (face corner);
 * value_of (m->nv, malloc'd) receives the caller's value index of each value vertex. pinned:
 * the geometry's valence-2 boundary corners are pinned (ccn_corners). Values must already be
 * in [0, num_values). */
ccn_status ccn__fvar_build(const ccn_mesh *vm, const int32_t *corner_values, int linear,
                           int pinned, ccn__fvar_level *out, int32_t **value_of, ccn_error *err);
/* The rules of one level of f (scheme, crease method, eigen polyhedron option and choice cache
 * as for the vertex mesh; corners by sharpness, so no pinned flag). c->partner points into f. */
ccn_status ccn__fvar_prepare(ccn__level *c, const ccn__fvar_level *f, int scheme,
                             int crease_method, int32_t ev_poly, ccn__ev_cache *cache,
                             ccn_error *err);
/* The next level of f (topology only): vm is f's vertex mesh, vchild vm's next level. */
ccn_status ccn__fvar_child(const ccn__fvar_level *f, const ccn__level *c, const ccn_mesh *vm,
                           const ccn_mesh *vchild, ccn__fvar_level *out, ccn_error *err);
/* Checks a channel given for the cage vm (one index per half-edge): width, mode, indices in
 * range, finite values; the message names the face corner or value. */
ccn_status ccn__fvar_check(const ccn_mesh *vm, const ccn_fvar_channel *ch, ccn_error *err);
/* Number of value vertices kept sharp by the mode (corners). */
int32_t ccn__fvar_num_sharp(const ccn__fvar_level *f);
void ccn__fvar_free(ccn__fvar_level *f);

#endif
