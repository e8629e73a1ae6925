/* Exact limit position and tangent planes of a vertex from its stationary 1-ring subdivision
 * matrix (internal; surface/ring_limit.c). For the vertices the closed-form stencils of
 * surface/limit.c do not cover: crease, corner and dart vertices, interior valence 2,
 * boundary vertices that are not regular (smooth corners, boundary EVs), and every vertex
 * whose edges or itself still carry a semi-sharp value at the output level. */
#ifndef CCN_SURFACE_RING_LIMIT_H
#define CCN_SURFACE_RING_LIMIT_H

#include "rules/eigen_select.h"
#include "topology/halfedge.h"

#define CCN_RING_MAX_VALENCE 256
#define CCN_RING_MAX_PTS (2 * CCN_RING_MAX_VALENCE + 1)

/* The limit of vertex v of level l, as stencils over its child 1-ring at level l+1 in the
 * level-(l+1) numbering (face point of face f -> f, edge point of edge e -> nf + e, vertex
 * point of v -> nf + ne + v): position weights, and one tangent pair per sector (the fan
 * faces between two consecutive sharp edges; one sector when fewer than two edges are sharp),
 * oriented so that wu x wv points along the outward normal of the sector's faces. */
typedef struct {
    int32_t npts;                   /* 1 + n + faces */
    int32_t pts[CCN_RING_MAX_PTS];  /* level-(l+1) indices */
    double wp[CCN_RING_MAX_PTS];
    int32_t nsec;
    int32_t sec_face0[CCN_RING_MAX_VALENCE]; /* fan position of the sector's first face */
    int32_t sec_nface[CCN_RING_MAX_VALENCE]; /* its number of faces (consecutive, mod n) */
    double *wu, *wv;                /* nsec x npts (ccn__ring_work owns them) */
} ccn__ring_limit;

typedef struct ccn__ring_work ccn__ring_work; /* scratch and a cache of solved 1-rings */
ccn__ring_work *ccn__ring_work_create(void);
void ccn__ring_work_destroy(ccn__ring_work *w);
/* The eigen polyhedron option (ccn_options.ev_polyhedron) and the owner's cache of polyhedron
 * choices used by the EV limits computed with w (default: the choice, no cache). */
void ccn__ring_work_set_ev(ccn__ring_work *w, int32_t ev_poly, ccn__ev_cache *cache);
void ccn__ring_work_ev(const ccn__ring_work *w, int32_t *ev_poly, ccn__ev_cache **cache);

/* Fills out for vertex v of mesh m (valence <= CCN_RING_MAX_VALENCE, not isolated). The
 * rules are the refinement's own (refine/level.c run on a synthetic 1-ring mesh), so the
 * result is exact for whatever the scheme, intervals and sharpness make of the 1-ring. */
ccn_status ccn__ring_limit_eval(const ccn_mesh *m, int32_t v, int scheme, int pinned,
                                int crease_method, ccn__ring_work *w, ccn__ring_limit *out,
                                ccn_error *err);
/* The same with v's sharpness one level finer given (child_vs >= 0) instead of its own:
 * face-varying values whose rule follows another value's sharpness (refine/fvar.h). */
ccn_status ccn__ring_limit_eval_vs(const ccn_mesh *m, int32_t v, int scheme, int pinned,
                                   int crease_method, float child_vs, ccn__ring_work *w,
                                   ccn__ring_limit *out, ccn_error *err);

#endif
