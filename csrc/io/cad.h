/* CAD export: a neutral B-rep description and its STEP / IGES writers (internal).
 *
 * The model is a list of tensor-product B-spline faces, each bounded by the four sides of
 * its parameter domain (untrimmed: the natural boundary), and the topology: which face side
 * is the same edge as which other face side. The writers emit every shared edge and vertex
 * once, so a reader gets one sewn shell without any sewing.
 *
 * Face f's domain is [u0,u1] x [v0,v1] with u0 = t[p], u1 = t[n] of its flat u knot vector
 * t (n poles, degree p; the standard B-spline range, for clamped and unclamped knots alike).
 * Corners: 0 = (u0,v0), 1 = (u1,v0), 2 = (u1,v1), 3 = (u0,v1). Side s runs from corner s to
 * corner s+1 (mod 4): counter-clockwise around the domain, so the face normal Su x Sv and
 * the boundary agree (the outward normal of a closed shell is Su x Sv on every face).
 * Sides may be split into several edges (T-junctions: a packed face next to smaller faces,
 * the rings of a bi-5 cap): side_breaks lists the parameters strictly inside side s of face
 * f where it is split, in the side's running direction. Its segments are numbered face by
 * face, side by side, in running order: segment k of side s of face f has the index
 * seg(f, s, k) = 4f + s + side_breaks_start[4f+s] + k (without breaks: 4f + s).
 * adjacency[seg] = the segment of another (or the same: a seam) face side that is the same
 * edge run in the opposite direction (a consistently oriented shell), -1 on the boundary. The
 * writers check that the two segments are the same curve (same parametrisation up to
 * direction and an affine change) within the tolerance.
 *
 * Numbers are written with 17 significant digits (round-trip exact); the output is a
 * deterministic function of the model (the timestamp is fixed unless given).
 */
#ifndef CCN_IO_CAD_H
#define CCN_IO_CAD_H

#include "ccnurbs.h"

#include <stddef.h>
#include <stdint.h>

#define CCN_CAD_MAX_DEGREE 25 /* OpenCASCADE's limit (Geom_BSplineSurface::MaxDegree) */

/* A polynomial tensor-product B-spline surface. */
typedef struct {
    int32_t degree[2];       /* u, v: 1 .. CCN_CAD_MAX_DEGREE */
    int32_t num_poles[2];    /* control points along u and v (>= degree + 1) */
    int32_t num_knots[2];    /* distinct knot values per direction (>= 2) */
    const double *knots[2];  /* strictly increasing distinct values */
    const int32_t *mults[2]; /* multiplicities, 1 .. degree + 1; sum = num_poles + degree + 1 */
    const double *poles;     /* pole (i, j) at 3 * (i * num_poles[1] + j), i along u */
    /* 1: closed periodic in that direction, written as the standard unclamped form: the last
     * `degree` pole rows repeat the first ones and the flat knot intervals repeat with the
     * period (both checked). IGES marks it periodic, STEP marks it closed. */
    int32_t periodic[2];
} ccn__cad_surface;

typedef struct {
    int32_t num_faces;
    const ccn__cad_surface *faces;
    /* split sides, see above; both NULL: no side is split */
    const int32_t *side_breaks_start; /* 4 * num_faces + 1, [0] = 0, non-decreasing */
    const double *side_breaks;        /* side_breaks_start[4 * num_faces] parameters */
    const int32_t *adjacency;         /* one per segment (4 * num_faces without breaks) */
    const char *name;         /* product / file name (printable ASCII), NULL: "ccnurbs" */
    const char *timestamp;    /* "YYYY-MM-DDThh:mm:ss", NULL: "2000-01-01T00:00:00" */
    double tolerance;         /* model units (mm); <= 0: max(1e-7, 1e-10 * bounding-box size) */
} ccn__cad_model;

/* Output sink: returns 0 on success, non-zero to stop (the writer returns CCN_ERR_IO). */
typedef int (*ccn__cad_write_fn)(void *user, const char *data, size_t len);

/* STEP AP214 (ISO 10303-21), lengths in millimetres. One shell per connected component of
 * faces: when every side is shared, each is a CLOSED_SHELL in its own MANIFOLD_SOLID_BREP
 * (ADVANCED_BREP_SHAPE_REPRESENTATION), otherwise all are in one SHELL_BASED_SURFACE_MODEL
 * (MANIFOLD_SURFACE_SHAPE_REPRESENTATION), OPEN_SHELL or CLOSED_SHELL each. */
ccn_status ccn__step_write(const ccn__cad_model *m, ccn__cad_write_fn fn, void *user,
                           ccn_error *err);
/* IGES 5.3, millimetres: 128 surfaces in the B-rep entities 502 vertex list, 504 edge list,
 * 508 loop, 510 face, one 514 shell per connected component (form 1 closed, 2 open) and, when
 * every side is shared, a 186 manifold solid per shell. */
ccn_status ccn__iges_write(const ccn__cad_model *m, ccn__cad_write_fn fn, void *user,
                           ccn_error *err);

/* ---- shared by the writers (cad.c) -------------------------------------------------- */

/* Segments, vertices and edges of a validated model. Segment j lies on side seg_side[j] of
 * face seg_face[j] over the parameters [seg_lo[j], seg_hi[j]] of that side's direction; a
 * face's segments are face_seg[f] .. face_seg[f+1]-1 in loop order, and seg_vert[j] is the
 * vertex where segment j starts (in loop order). Edge e is segment edge_seg[e] (its first
 * appearance, or its twin when only the twin is a whole side); its curve is that segment's
 * iso curve in increasing parameter, from vertex edge_vert[2e] to edge_vert[2e+1]. seg_edge[j]
 * is the edge of each segment and seg_sense[j] = 1 if the segment (in loop order) runs along
 * the edge's curve, 0 against it. */
typedef struct {
    int32_t num_segs, num_verts, num_edges;
    int closed;               /* every segment shared */
    double tolerance, size;   /* effective tolerance; bounding-box diagonal of the poles */
    int32_t *face_seg;        /* num_faces + 1 */
    int32_t *seg_face;        /* num_segs */
    uint8_t *seg_side;        /* num_segs */
    double *seg_lo, *seg_hi;  /* num_segs */
    int32_t *seg_vert;        /* num_segs */
    double *vert_pos;         /* 3 * num_verts */
    int32_t *seg_edge;        /* num_segs */
    uint8_t *seg_sense;       /* num_segs */
    int32_t *edge_seg;        /* num_edges */
    int32_t *edge_vert;       /* 2 * num_edges */
    int32_t num_shells;       /* connected components of faces (through shared segments) */
    int32_t *face_shell;      /* num_faces: shells numbered in the order of their first face */
    uint8_t *shell_closed;    /* num_shells: every segment of the shell's faces shared */
    int32_t *shell_start;     /* num_shells + 1: shell s has faces shell_face[shell_start[s]..] */
    int32_t *shell_face;      /* num_faces: the faces shell by shell, each shell's in face order */
} ccn__cad_topo;

/* Validates the model (every error names the face or side) and builds its topology. */
ccn_status ccn__cad_topo_build(const ccn__cad_model *m, ccn__cad_topo *t, ccn_error *err);
void ccn__cad_topo_free(ccn__cad_topo *t);
/* Is segment j its face's whole side? */
int ccn__cad_whole_side(const ccn__cad_model *m, const ccn__cad_topo *t, int32_t j);

/* The iso curve of side s of a face, in increasing parameter: its degree, the knots of
 * that direction (the caller reads them from the surface: direction (s % 2 == 0 ? u : v))
 * and num_poles[dir] poles into out (3 each). */
void ccn__cad_side_curve(const ccn__cad_surface *f, int s, double *out);

/* A B-spline curve in flat-knot form (knots: num_poles + degree + 1 values). */
typedef struct {
    int32_t degree, num_poles;
    double *knots, *poles;   /* caller-owned, capacity given by ccn__cad_curve_capacity */
    int periodic;            /* the whole side of a periodic direction */
} ccn__cad_curve;
/* Poles needed for any segment curve of face f (knots: + degree + 1). */
int32_t ccn__cad_curve_capacity(const ccn__cad_surface *f);
/* The curve of segment j (increasing parameter): the side's iso curve itself when the
 * segment is the whole side, else that curve cut to [seg_lo, seg_hi] by knot insertion
 * (clamped ends); its parameters mapped affinely onto [0, 1]. */
void ccn__cad_segment_curve(const ccn__cad_model *m, const ccn__cad_topo *t, int32_t j,
                            ccn__cad_curve *out);
/* The ends of segment j in its face's (u, v) domain: a = where its loop use starts, b = where
 * it ends (along = 0), or a = where its edge's curve starts, b = where it ends (along = 1). The
 * straight line between them is the segment's pcurve (every side is an iso line). */
void ccn__cad_segment_ends_uv(const ccn__cad_model *m, const ccn__cad_topo *t, int32_t j, int along,
                              double a[2], double b[2]);
/* Domain [lo, hi] of direction dir (0 = u, 1 = v). */
void ccn__cad_domain(const ccn__cad_surface *f, int dir, double *lo, double *hi);
/* Surface point at (u, v) by de Boor (u, v inside the domain). */
void ccn__cad_eval(const ccn__cad_surface *f, double u, double v, double out[3]);
/* Point and first derivatives at (u, v) (u, v inside the domain; at an inner knot the span
 * above it, at the domain's upper end the last span). */
void ccn__cad_eval_d(const ccn__cad_surface *f, double u, double v, double pos[3], double du[3],
                     double dv[3]);

/* Buffered output through a ccn__cad_write_fn; the first failure sticks. */
typedef struct {
    ccn__cad_write_fn fn;
    void *user;
    size_t len;
    int failed;
    char buf[8192];
} ccn__cad_out;
void ccn__cad_out_init(ccn__cad_out *o, ccn__cad_write_fn fn, void *user);
void ccn__cad_write(ccn__cad_out *o, const char *data, size_t len);
void ccn__cad_puts(ccn__cad_out *o, const char *s);
void ccn__cad_printf(ccn__cad_out *o, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* Flushes; 0 if everything was written. */
int ccn__cad_flush(ccn__cad_out *o);
/* x in the fewest significant digits (at most 17) that read back as x, always with a decimal point and an upper-case exponent
 * ("1.", "-2.5E-07"): valid as a STEP and an IGES real. buf: at least 32 chars. */
const char *ccn__cad_real(double x, char *buf);

#endif
