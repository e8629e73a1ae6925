/* One refinement level, split so that a plan can re-run only the point arithmetic
 * (internal; refine/level.c). */
#ifndef CCN_REFINE_LEVEL_H
#define CCN_REFINE_LEVEL_H

#include "rules/eigen_select.h"
#include "topology/halfedge.h"

#include <stddef.h>

#define CCN_EV_MATRIX_MAX_VALENCE 1024 /* above: NURSS rules (memory grows as valence^2) */
/* Level 0: M is blended with the NURSS step as max |log(e_i / d_i)| goes from 0 to this. */
#define CCN__LEVEL0_BAND 0.5

typedef struct {
    const ccn_mesh *m;   /* the level's topology, intervals and (input) positions */
    int pinned, red;     /* red: eigen matrices at the EVs */
    int crease_method;   /* ccn_crease_method (creased meshes only) */
    int threads;         /* for ccn__level_points (set by the owner; default 1) */
    int32_t *erep;       /* a half-edge per edge */
    int32_t nev, *ev_list;
    double *ev_w;        /* per listed EV: the weight of its M against the rules' own points
                            (1 but at level 0, where e_i nears d_i: refine/level.c) */
    double *M;           /* concatenated EV matrices ((2n+1)^2 each) */
    size_t *Moff;
    double *H;           /* scratch: 3*ne curve edge points */
    int32_t fallbacks;
    int32_t nbig;        /* EVs above CCN_EV_MATRIX_MAX_VALENCE (NURSS rules; in fallbacks) */
    /* Face-varying channels (refine/fvar.c), else NULL: vertex v's rule (smooth, crease or
     * corner, and the fractional weight where it changes) follows the sharpness of vertex
     * partner[v] >= 0 (OpenSubdiv's dependent sharpness), its crease along its own edges. */
    const int32_t *partner;
    ccn__ev_cache *ev_cache; /* the owner's cache of eigen polyhedron choices (may be NULL) */
    int32_t ev_poly;     /* ccn_options.ev_polyhedron */
    int32_t ev_verified, ev_outside; /* EVs of this level verified / outside the G1 range */
    /* The rules' weights, tabulated by the first ccn__level_points, or for the listed elements
     * by ccn__level_points_lists (they depend on topology and intervals only): quad face (s, t), edge (curve weight and
     * the two transverse intervals), interior vertex ((n-3)/n, 3/(n sum)) and its fan's
     * (m_i, f_i) at the fan's half-edge positions; on a creased mesh tvs[v] says which
     * vertices' (smooth) rule is in tv / th. NULL: computed per call. tab_sub: the elements
     * of ccn__level_points_subset's list, by ccn__level_tabulate_subset. */
    int tab_tried, tab_full, tab_sub;
    double *tf, *te, *tv, *th;
    uint8_t *tvs, *tmask; /* tmask: faces, edges, vertices tabulated (lists: a part) */
} ccn__level;
ccn_status ccn__level_prepare(ccn__level *c, const ccn_mesh *m, int scheme, int pinned,
                              int crease_method, ccn_error *err);
/* ccn__level_prepare with the eigen polyhedron option and the owner's choice cache. */
ccn_status ccn__level_prepare_ev(ccn__level *c, const ccn_mesh *m, int scheme, int pinned,
                                 int crease_method, int32_t ev_poly, ccn__ev_cache *cache,
                                 ccn_error *err);
/* ccn__level_prepare_ev for a level of the same topology and sharpness as like's (an earlier
 * plan's, a plan made with options.previous; may be NULL): its edge representatives are taken over (moved: NULL
 * in like) and, from level 1 on, its EV list copied (both topology only); the EV matrices are
 * made anew (they read the intervals). */
ccn_status ccn__level_prepare_like(ccn__level *c, const ccn_mesh *m, int scheme, int pinned,
                                   int crease_method, int32_t ev_poly, ccn__ev_cache *cache,
                                   ccn__level *like, ccn_error *err);
/* Points of the next level from c->m->pos into out (3*(nf+ne+nv)). */
void ccn__level_points(ccn__level *c, double *out);
/* Next-level points around the listed vertices only (see refine/level.c); with the tables of
 * ccn__level_tabulate_subset (made once, for the same list) where it ran. */
void ccn__level_points_subset(const ccn__level *c, const int32_t *verts, int32_t nverts,
                              double *out);
void ccn__level_tabulate_subset(ccn__level *c, const int32_t *verts, int32_t nverts);
/* The tables of q (the same topology, other intervals: an earlier plan's level, evaluated)
 * for the elements whose rules read no changed interval (ccn_plan_create with options.previous). */
void ccn__level_tabulate_like(ccn__level *c, const ccn__level *q);
/* The next-level points of the listed faces, edges and vertices only (each once; every EV's
 * red points too). A point is right when the old points its rule reads are. */
void ccn__level_points_lists(ccn__level *c, const int32_t *faces, int32_t nfaces,
                             const int32_t *edges, int32_t nedges, const int32_t *verts,
                             int32_t nverts, double *out);
/* Topology and intervals of the next level (positions uninitialised). */
ccn_status ccn__level_topology(const ccn__level *c, ccn_mesh **out, ccn_error *err);
/* The same, with the child topology taken from `like`, the child of a mesh with c->m's
 * topology (an earlier plan's level, given up: its topology arrays move into *out and are
 * NULL in like afterwards; its sizes, intervals and counts stay). Only the intervals,
 * sharpness and counts are made. */
ccn_status ccn__level_topology_like(const ccn__level *c, ccn_mesh *like, ccn_mesh **out,
                                    ccn_error *err);
void ccn__level_free(ccn__level *c);

#endif
