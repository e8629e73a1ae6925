/* The CAD export's model under construction (internal; io/export_model.c; used by io/export.c,
 * packs.c, fill.c, export_topo.c): B-spline faces that know where they lie on the cage, so that the topology
 * (which face side is the same edge as which) comes from the mesh hierarchy, not from the
 * geometry (EXPORT_DESIGN.md section 5).
 *
 * Places: every point of the surface is (cage face c, sub, s, t): a cage quad's own frame
 * (sub = -1: corner 0 of c at (0,0), its first half-edge along s, (s,t) in [0,1]^2) or, for a
 * cage face with n != 4 sides, the frame of its level-1 quad at corner `sub` (corner 0 = the
 * cage vertex, corner 1 = the midpoint of the edge of half-edge sub, corner 2 = the face
 * point, corner 3 = the midpoint of the previous edge). Every level-l face and every patch
 * is an axis-parallel dyadic rectangle in one such frame, so places are exact doubles and two
 * faces meet where their places say so, compared exactly.
 */
#ifndef CCN_IO_EXPORT_MODEL_H
#define CCN_IO_EXPORT_MODEL_H

#include "io/cad.h"
#include "surface/patch_set.h"

/* An affine frame: the place of (x,y) = (0,0), (1,0), (0,1) of some [0,1]^2. */
typedef struct {
    int32_t cage_face, sub;
    double p[3][2];
} ccn__xplace;

/* The place of face f of a plan level (walks the corner chain up to the cage). */
void ccn__xplace_of(const ccn_mesh *const *lev, int32_t level, int32_t f, ccn__xplace *out);
/* The place of child j (corner j) of a quad placed at q. */
void ccn__xplace_child(const ccn__xplace *q, int32_t j, ccn__xplace *out);
/* The place of the sub-rectangle r (its (0,0), (1,0), (0,1) in q's [0,1]^2) of q. */
void ccn__xplace_sub(const ccn__xplace *q, const double r[3][2], ccn__xplace *out);
/* q re-framed to start at its corner r (corner r at (0,0), corner r+1 at (1,0)). */
void ccn__xplace_rotate(const ccn__xplace *q, int32_t r, ccn__xplace *out);

/* The part [uv[0],uv[1]] x [uv[2],uv[3]] of a face's parameters lies at place pl. */
typedef struct {
    double uv[4];
    ccn__xplace pl;
} ccn__xcell;

typedef struct {
    ccn__cad_surface s;      /* knots, mults and poles are owned (malloc) */
    int32_t kind;            /* ccn_export_face_kind */
    int32_t patch;           /* ccn_plan_patches index, -1 */
    int32_t fill;            /* fill (hole) id, -1 */
    int32_t merged;          /* made by a merge since the last knot removal (face_merge.h) */
    int32_t cells_u, cells_v, cell0; /* cells_u x cells_v cells (cell (i,j) at cell0 + i + cells_u j):
                                        side 0 of the face runs along cells (i, 0), side 1 along
                                        (cells_u-1, j), ... */
} ccn__xface;

typedef struct {
    ccn__xface *faces;
    int32_t num_faces, cap_faces;
    ccn__xcell *cells;
    int32_t num_cells, cap_cells;
    int oom;
} ccn__xmodel;

void ccn__xm_free(ccn__xmodel *xm);
/* A new face with owned arrays for its poles and flat knots (multiplicities 1); -1 on OOM
 * (xm->oom set). Fill s.knots / s.mults with ccn__xm_set_flat. */
int32_t ccn__xm_add_face(ccn__xmodel *xm, int32_t kind, int32_t du, int32_t dv, int32_t nu,
                         int32_t nv, int32_t cells_u, int32_t cells_v);
/* Sets direction dir of face f from flat knots t (num_poles + degree + 1 values). */
int ccn__xm_set_flat(ccn__xmodel *xm, int32_t f, int dir, const double *t);
/* Direction dir's flat knots of s (num_poles + degree + 1 values) into t. */
void ccn__cad_flat_knots(const ccn__cad_surface *s, int dir, double *t);
/* The diagonal of the bounding box of s's poles; *reach (may be NULL): their largest
 * coordinate's magnitude. */
double ccn__cad_surface_size(const ccn__cad_surface *s, double *reach);
/* Frees s's owned poles, knots and multiplicities (a face of the model) and zeroes s. */
void ccn__xm_free_surface(ccn__cad_surface *s);
/* Maps the domain of every patch face (bicubic, bi-5, fill: their parameters are their
 * construction's own) affinely onto [0, 1]^2, knots and cells alike; the surfaces are unchanged.
 * Faces with the same shape of domain then share their pcurves in the STEP file (io/step.c).
 * Packs and refined pieces keep their knots: the cage's knot intervals (halved per level).
 * A direction whose knots would no longer be distinct keeps its domain. */
void ccn__xm_unit_domains(ccn__xmodel *xm);
/* A Bezier face of degree deg (pts: (deg+1)^2 x 3, first index along u) at place pl. */
int32_t ccn__xm_add_bezier(ccn__xmodel *xm, int32_t kind, int32_t deg, const double *pts,
                           const ccn__xplace *pl);

#endif
