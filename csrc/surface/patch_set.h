/* The finite patch set of a plan with each patch's place (internal; surface/patch_set.c):
 * what the CAD export (io/export.c) needs from the plan, so that only this module reads the
 * plan's internals for it. ccn_plan_patches (public) is built on the same walk. */
#ifndef CCN_SURFACE_PATCH_SET_H
#define CCN_SURFACE_PATCH_SET_H

#include "rules/eigen_select.h"
#include "topology/halfedge.h"

enum {
    CCN__PATCH_STRICT = 0, /* bicubic patch of a strict-regular face: the subdivision limit */
    CCN__PATCH_RING,       /* bicubic patch of a level-K face around a cap: the spline the cap
                              joins C2 (what ccn_plan_evaluate shows there) */
    CCN__PATCH_SURROUND,   /* level-(K+1) strict face around an exact-surround cap */
    CCN__PATCH_CAP_RING,   /* bi-5 ring patch of a cap */
    CCN__PATCH_CAP,        /* bi-5 cap patch */
    CCN__PATCH_HOLE        /* a face the plan has no patch for (degree 0, points NULL) */
};

/* One patch and where it lies: mesh level `level` of the plan, face `face` there, and the
 * patch's parameter rectangle in that face's frame [0,1]^2 (corner k of the face at UNIT[k] =
 * (0,0), (1,0), (1,1), (0,1) in half-edge order): rect[0], rect[1], rect[2] are the face
 * coordinates of the patch's (u,v) = (0,0), (1,0), (0,1) (an affine map; the whole face is
 * {0,0, 1,0, 0,1}). Bicubic patches are their face; cap patches lie in the level-K face of
 * their sector at the ring's Lambda rectangle. */
typedef struct {
    int32_t kind;            /* CCN__PATCH_* */
    int32_t degree;          /* 3 or 5; 0 for a hole */
    int32_t level, face;
    double rect[3][2];
    int32_t cap, sector, ring, part; /* cap patches: cap, sector, ring (nsig = the cap), A/B/C;
                                        -1 otherwise */
    int32_t index;           /* position in ccn_plan_patches' output, -1 for holes */
    const double *points;    /* (degree+1)^2 x 3 in the caller's coordinates, first index along u */
} ccn__patch_place;

typedef void (*ccn__place_fn)(void *user, const ccn__patch_place *p);

/* Every patch of the last ccn_plan_evaluate, in ccn_plan_patches' order, with every face the
 * plan has no patch for (CCN__PATCH_HOLE) reported where ccn_plan_patches counts it. */
ccn_status ccn__plan_patches_placed(const ccn_plan *p, ccn__place_fn fn, void *user);

/* Where bi-5 patch i of a valence-n cap (bi5.h: ring r = i / 3n, part A/B/C = (i / n) % 3,
 * sector s = i % n; the cap of sector s after the rings) lies in its sector's face, whose corner
 * j0 is the EV: hole coordinates (u along spoke s, v along spoke s+1) scaled by the ring's
 * Lambda (ccn__bi5_eval), as the (0,0), (1,0), (0,1) of the patch in the face's [0,1]^2. */
struct ccn__bi5;
void ccn__cap_patch_rect(const struct ccn__bi5 *op, int32_t n, int32_t i, int32_t j0, double rect[3][2]);

/* What a plan exposes to the export: its meshes (lev[0] = the cage, positions of the last
 * evaluate in the unit box: caller coordinates = centre + scale * pos), the patch level
 * (the cap level K, or the deepest level without caps) and the rules. */
typedef struct {
    int32_t num_levels;        /* lev[0 .. num_levels-1] */
    const ccn_mesh *const *lev;
    int32_t patch_level, cap_level; /* cap_level -1: no caps */
    int32_t scheme;            /* ccn_scheme */
    int pinned;                /* boundary_corners == CCN_CORNERS_PINNED */
    double centre[3], scale;
    int32_t crease_method;     /* ccn_crease_method */
    int32_t ev_polyhedron;     /* ccn_options.ev_polyhedron */
    ccn__ev_cache *ev_cache;   /* the plan's eigen polyhedron choices (refinement and limits
                                  elsewhere must make the plan's choice) */
    int guided_caps;           /* options.cap == CCN_CAP_GUIDED_BI5 */
    int32_t output_level;      /* options.levels (the level the plan's output samples) */
} ccn__plan_view;
void ccn__plan_view_get(const ccn_plan *p, ccn__plan_view *v);

#endif
