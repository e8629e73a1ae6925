/* Internal structures shared by the library's translation units (not installed). */
#ifndef CCN_INTERNAL_H
#define CCN_INTERNAL_H

#include "ccnurbs.h"

#include <stdint.h>
#include <stdlib.h>

/* Half-edge mesh. Face f owns the half-edges fstart[f] .. fstart[f+1]-1 in boundary order
 * (counter-clockwise seen from outside); half-edge h runs from hvert[h] to hvert[next(h)].
 * Edges are numbered in order of first appearance when walking faces and their half-edges
 * (level 0) or by the refinement rule documented in refine.c (levels >= 1). */
struct ccn_mesh {
    int32_t nv, nf, ne, nh;
    double *pos;     /* 3 * nv */
    int32_t *fstart; /* nf + 1 */
    int32_t *hvert;  /* nh: origin vertex */
    int32_t *htwin;  /* nh: opposite half-edge, -1 on the boundary */
    int32_t *hedge;  /* nh: edge index */
    int32_t *hface;  /* nh: face index */
    int32_t *everts; /* 2 * ne */
    double *eknot;   /* ne: ring interval, normalised so the largest is 1 */
    double knot_scale; /* eknot * knot_scale = interval in the caller's units */
    /* Vertex fans: the outgoing half-edges of vertex v in counter-clockwise order are
     * vfan[vfan_start[v] .. vfan_start[v+1]-1]. A boundary vertex's fan starts with the
     * outgoing boundary half-edge; its last edge (incoming boundary) is vlast_edge[v]. */
    int32_t *vfan_start; /* nv + 1 */
    int32_t *vfan;       /* nh */
    int32_t *hfanpos;    /* nh: position of h in its origin vertex's fan */
    int32_t *vlast_edge; /* nv: incoming boundary edge of a boundary vertex, else -1 */
    uint8_t *vboundary;  /* nv */
    ccn_mesh_info info;
};

/* ---- error.c ---- */
ccn_status ccn__fail(ccn_error *err, ccn_status st, int32_t kind, int32_t element,
                     const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;
void ccn__ok(ccn_error *err);

/* ---- mesh.c ---- */
ccn_mesh *ccn__mesh_alloc(int32_t nv, int32_t nf, int32_t nh, int32_t ne);
/* Builds vfan / hfanpos / vboundary / valence info from hvert/htwin/fstart. Returns 0 on
 * success, or the index + 1 of a vertex whose faces form more than one fan (non-manifold). */
int32_t ccn__mesh_build_fans(ccn_mesh *m);
void ccn__mesh_update_info(ccn_mesh *m);
/* Affine normalisation of positions to a unit box (the rules are affine-invariant). */
void ccn__normalize(ccn_mesh *m, double centre[3], double *scale);
void ccn__denormalize(ccn_mesh *m, const double centre[3], double scale);

static inline int32_t ccn__next(const ccn_mesh *m, int32_t h) {
    int32_t f = m->hface[h];
    return h + 1 < m->fstart[f + 1] ? h + 1 : m->fstart[f];
}
static inline int32_t ccn__prev(const ccn_mesh *m, int32_t h) {
    int32_t f = m->hface[h];
    return h > m->fstart[f] ? h - 1 : m->fstart[f + 1] - 1;
}
static inline int32_t ccn__fsize(const ccn_mesh *m, int32_t f) {
    return m->fstart[f + 1] - m->fstart[f];
}
static inline int32_t ccn__valence(const ccn_mesh *m, int32_t v) {
    return m->vfan_start[v + 1] - m->vfan_start[v] + (m->vboundary[v] ? 1 : 0);
}
/* Edge k (0 <= k < valence) of v's fan, counter-clockwise. */
static inline int32_t ccn__fan_edge(const ccn_mesh *m, int32_t v, int32_t k) {
    int32_t nfan = m->vfan_start[v + 1] - m->vfan_start[v];
    return k < nfan ? m->hedge[m->vfan[m->vfan_start[v] + k]] : m->vlast_edge[v];
}

/* ---- knots.c ---- */
/* Resolves ring intervals from per-edge candidate values (<= 0 / non-finite = unset) and
 * normalises them (largest = 1, clamped to >= 1e-6). Writes m->eknot, m->knot_scale and the
 * ring counts in m->info. `source` (may be NULL) tags each edge's value with the identity of
 * where it came from; a ring's value is the mean over distinct sources (NULL: over edges). */
ccn_status ccn__resolve_rings(ccn_mesh *m, const double *edge_values, const int32_t *source,
                              ccn_error *err);

#define CCN_KNOT_MIN_RATIO 1e-6
#define CCN_COORD_MAX 1e300 /* larger |coordinates| are rejected: results must stay finite */
#define CCN_EV_MATRIX_MAX_VALENCE 1024 /* above: NURSS rules (memory grows as valence^2) */

/* ---- refine.c: one refinement level, split so a plan can re-run only the points ---- */
typedef struct {
    const ccn_mesh *m;   /* the level's topology, intervals and (input) positions */
    int pinned, red;     /* red: eigen matrices at the EVs */
    int threads;         /* for ccn__level_points (set by the owner; default 1) */
    int32_t *erep;       /* a half-edge per edge */
    int32_t nev, *ev_list;
    double *M;           /* concatenated EV matrices ((2n+1)^2 each) */
    size_t *Moff;
    double *H;           /* scratch: 3*ne curve edge points */
    int32_t fallbacks;
} ccn__level;
ccn_status ccn__level_prepare(ccn__level *c, const ccn_mesh *m, int scheme, int pinned,
                              ccn_error *err);
/* Points of the next level from c->m->pos into out (3*(nf+ne+nv)). */
void ccn__level_points(const ccn__level *c, double *out);
/* Next-level points around the listed vertices only (see refine.c). */
void ccn__level_points_subset(const ccn__level *c, const int32_t *verts, int32_t nverts,
                              double *out);
/* Topology and intervals of the next level (positions uninitialised). */
ccn_status ccn__level_topology(const ccn__level *c, ccn_mesh **out, ccn_error *err);
void ccn__level_free(ccn__level *c);

#endif
