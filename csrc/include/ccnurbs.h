/* CCNURBS — non-uniform Catmull-Clark subdivision with G1 extraordinary points.
 *
 * One public header. C11, every symbol prefixed ccn_. Opaque handles, caller-owned
 * buffers, every fallible call returns a ccn_status and fills a ccn_error (may be NULL).
 * No globals: distinct handles may be used from distinct threads.
 */
#ifndef CCNURBS_H
#define CCNURBS_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define CCN_VERSION_MAJOR 0
#define CCN_VERSION_MINOR 1

typedef enum {
    CCN_OK = 0,
    CCN_ERR_ARGUMENT,  /* bad argument: NULL, negative count, NaN/Inf coordinate, ... */
    CCN_ERR_TOPOLOGY,  /* degenerate face, bad index, valence or face size beyond the limit */
    CCN_ERR_KNOTS,     /* knot intervals that cannot be used */
    CCN_ERR_MEMORY,    /* allocation failed or size would overflow */
    CCN_ERR_INTERNAL,  /* a numerical failure the library could not recover from */
    CCN_ERR_IO         /* file or parse error (OBJ reader, CLI) */
} ccn_status;

typedef enum { CCN_SCHEME_EIGEN = 0, CCN_SCHEME_NURSS, CCN_SCHEME_CATMULL_CLARK } ccn_scheme;
/* How extraordinary points are closed: GUIDED_BI5, the guided bi-5 cap where the spoke knot
 * ratios allow it (within 1.05 of each other), the refined limit elsewhere; REFINE, the refined
 * limit everywhere; G1_FILL, the guided bi-5 cap where it is whole and the G1 fill cap beyond it
 * (valence >= 5: a finite surface exactly G1 at every EV whatever the intervals, which the CAD
 * export writes as it is; measured less fair than the refined limit at spoke ratios of 2 and
 * more, docs/caps.md). */
typedef enum { CCN_CAP_GUIDED_BI5 = 0, CCN_CAP_REFINE, CCN_CAP_G1_FILL } ccn_cap;
/* Valence-2 boundary corners: smooth (OpenSubdiv EDGE_ONLY, Blender "All") or pinned
 * (OpenSubdiv EDGE_AND_CORNER, Blender "Keep Corners"). */
typedef enum { CCN_CORNERS_SMOOTH = 0, CCN_CORNERS_PINNED } ccn_corners;
/* How semi-sharp creases decay per level (OpenSubdiv Sdc::Options::CreasingMethod):
 * UNIFORM subtracts 1 (Blender's Subdivision Surface), CHAIKIN averages with the other
 * semi-sharp edges at each end first (0.75 s + 0.25 mean of the others, minus 1). */
typedef enum { CCN_CREASE_UNIFORM = 0, CCN_CREASE_CHAIKIN } ccn_crease_method;

/* Sharpness (OpenSubdiv semantics): 0 = smooth, >= CCN_SHARPNESS_INFINITE = infinitely sharp,
 * in between semi-sharp (sharp for floor(s) levels, then blended, then smooth). */
#define CCN_SHARPNESS_INFINITE 10.0

/* Which kind of element an error names (ccn_error.element_kind). */
typedef enum {
    CCN_ELEM_NONE = 0, CCN_ELEM_VERTEX, CCN_ELEM_EDGE, CCN_ELEM_FACE, CCN_ELEM_LINE,
    CCN_ELEM_VALUE /* a value of a face-varying channel (or of per-vertex data) */
} ccn_element_kind;

/* What failed, for the failures an application can act on (ccn_error.reason): applications
 * key their advice on these, never on the message text. */
typedef enum {
    CCN_REASON_NONE = 0,                /* no failure */
    CCN_REASON_OTHER,                   /* see status and message */
    CCN_REASON_NO_FACES,                /* the cage has no face */
    CCN_REASON_NONFINITE_COORDINATE,    /* a vertex at NaN or Inf (element: the vertex) */
    CCN_REASON_COORDINATE_RANGE,        /* a coordinate beyond +-CCN_COORD_MAX */
    CCN_REASON_NAN_SHARPNESS,           /* a NaN crease (element: the edge or vertex) */
    CCN_REASON_FACE_TOO_FEW_VERTICES,   /* a face of fewer than 3 vertices */
    CCN_REASON_FACE_REPEATS_VERTEX,     /* a face uses a vertex twice */
    CCN_REASON_INDEX_OUT_OF_RANGE,      /* a face names a vertex the cage does not have */
    CCN_REASON_VALENCE_LIMIT,           /* a vertex of more edges than the limit surface supports */
    CCN_REASON_FACE_SIZE_LIMIT,         /* a face of more sides than the limit surface supports */
    CCN_REASON_OUT_OF_MEMORY            /* an allocation failed or the result would be too large */
} ccn_reason;

typedef struct {
    ccn_status status;
    int32_t element_kind; /* ccn_element_kind */
    int32_t element;      /* 0-based index of the offending element, -1 if none */
    char message[256];    /* human-readable, names the element ("face 12 has ...") */
    int32_t reason;       /* ccn_reason */
    int32_t element_verts[2]; /* an edge element's two vertices, else -1 -1 */
} ccn_error;

/* A polygon soup cage. Knot intervals and creases are given per edge, an edge being identified
 * by its two vertex indices (edge_verts). Knot values <= 0, NaN or Inf mean "unset" (1).
 * Sharpness (edge_creases, vertex_creases): OpenSubdiv's, >= 0; <= 0 is smooth, values >= 10
 * (and +Inf) are infinitely sharp; NaN is a CCN_ERR_ARGUMENT naming the edge or vertex. Where
 * an edge is listed twice, a later unset knot (<= 0) or smooth crease (<= 0) does not replace
 * an earlier value. */
typedef struct {
    int32_t num_verts, num_faces, num_edges;
    const double *positions;   /* 3 * num_verts */
    const int32_t *face_sizes; /* num_faces */
    const int32_t *face_verts; /* sum(face_sizes) */
    const int32_t *edge_verts; /* 2 * num_edges, may be NULL (then num_edges = 0) */
    const double *edge_knots;  /* num_edges, NULL = all unset (interval 1) */
    const double *edge_creases;/* num_edges edge sharpness, may be NULL (all smooth) */
    const double *vertex_creases; /* num_verts vertex sharpness (corners), may be NULL */
} ccn_cage;

typedef struct ccn_plan ccn_plan;   /* opaque: topology, intervals, options, precomputed data */
typedef struct ccn_cache ccn_cache; /* opaque: what plans can share (ccn_cache_create) */

typedef struct {
    ccn_scheme scheme;        /* default EIGEN */
    ccn_cap cap;              /* default GUIDED_BI5 */
    int32_t levels;           /* refinement levels / samples 2^levels per cage-face side */
    int32_t boundary_corners; /* ccn_corners, default SMOOTH */
    int32_t threads;          /* 0 = default */
    int32_t crease_method;    /* ccn_crease_method, default UNIFORM */
    int32_t ev_polyhedron;    /* scheme EIGEN: CCN_POLY_SELECT (default, the per-vertex choice
                                 of ccn_ev_matrix); a fixed candidate CCN_POLY_PAPER.. is
                                 EXPERIMENTAL (research) */
    ccn_cache *cache;         /* ccn_plan_create: operators shared between plans, NULL = the
                                 plan's own (other calls ignore it) */
    ccn_plan *previous;       /* ccn_plan_create: the plan this one replaces after an edit,
                                 NULL = none; consumed (see ccn_plan_create) */
} ccn_options;

/* ---- control meshes ------------------------------------------------------------ */

typedef struct ccn_mesh ccn_mesh; /* opaque: a validated polygon mesh with ring intervals */

typedef struct {
    int32_t num_verts, num_faces, num_edges;
    int32_t num_face_verts;      /* sum of face sizes */
    int32_t num_boundary_edges;
    int32_t num_rings;           /* edge rings (quads only link edges into rings) */
    int32_t num_ring_conflicts;  /* rings whose given edge values disagreed */
    int32_t num_ignored_verts;   /* isolated vertices dropped from the cage */
    int32_t num_ignored_edges;   /* loose edges (given in edge_verts, in no face) ignored */
    int32_t num_extraordinary;   /* interior vertices of valence != 4 */
    int32_t max_valence;
    int32_t num_ev_fallbacks;    /* EVs that fell back from eigen to NURSS rules (refine) */
    int32_t level;               /* refinement level of this mesh (0 = cage) */
    int32_t num_sharp_edges;     /* edges with sharpness > 0 (boundary edges not counted) */
    int32_t num_sharp_vertices;  /* vertices with sharpness > 0 */
} ccn_mesh_info;

/* Builds and validates a cage. Vertex indices of the resulting mesh are those of the cage
 * (isolated vertices keep their slot but are counted in num_ignored_verts). */
ccn_status ccn_mesh_create(const ccn_cage *cage, ccn_mesh **out, ccn_error *err);
void ccn_mesh_destroy(ccn_mesh *mesh);
ccn_status ccn_mesh_get_info(const ccn_mesh *mesh, ccn_mesh_info *info);
/* Copies the mesh into caller-owned arrays; any pointer may be NULL.
 * positions: 3*num_verts, face_sizes: num_faces, face_verts: num_face_verts,
 * edge_verts: 2*num_edges, edge_knots: num_edges (the resolved ring interval). */
ccn_status ccn_mesh_copy(const ccn_mesh *mesh, double *positions, int32_t *face_sizes,
                         int32_t *face_verts, int32_t *edge_verts, double *edge_knots);
/* Sharpness of the mesh's edges (num_edges, edge order of ccn_mesh_copy) and vertices
 * (num_verts) at its level (refined creases decay); any pointer may be NULL. */
ccn_status ccn_mesh_get_creases(const ccn_mesh *mesh, double *edge_sharpness, double *vertex_sharpness);
/* Replaces the vertex positions (3*num_verts) keeping topology and intervals. */
ccn_status ccn_mesh_set_positions(ccn_mesh *mesh, const double *positions, ccn_error *err);

/* `levels` levels of refinement. Vertex order of each level: face points (face order),
 * edge points (edge order), vertex points (vertex order); faces: each old face's sub-quads
 * in corner order. Level 0 -> 1 splits non-quads. */
ccn_status ccn_refine(const ccn_mesh *in, int32_t levels, const ccn_options *opts,
                      ccn_mesh **out, ccn_error *err);

/* ---- face-varying data (UV maps): OpenSubdiv's face-varying channels --------------- */

/* How face-varying values are interpolated where they are discontinuous (seams) and at the
 * mesh boundary: OpenSubdiv's Sdc::Options::FVarLinearInterpolation, same numbers (the OBJ tag
 * `t facevaryinginterpolateboundary`), Blender's UV Smooth names in brackets. OpenSubdiv's
 * default is ALL. */
typedef enum {
    CCN_FVAR_LINEAR_NONE = 0,      /* smooth everywhere, seams are smooth boundaries ("All") */
    CCN_FVAR_LINEAR_CORNERS_ONLY,  /* sharpen corners ("Keep Corners") */
    CCN_FVAR_LINEAR_CORNERS_PLUS1, /* and junctions of 3+ values ("Keep Corners, Junctions") */
    CCN_FVAR_LINEAR_CORNERS_PLUS2, /* and darts, corners of 2 values ("..., Concave") */
    CCN_FVAR_LINEAR_BOUNDARIES,    /* linear along seams and boundaries ("Keep Boundaries",
                                      what a new Subdivision Surface modifier gets) */
    CCN_FVAR_LINEAR_ALL            /* bilinear everywhere ("None") */
} ccn_fvar_linear;

/* A face-varying channel of a cage: a value index per face corner (cage face order,
 * sum(face_sizes) entries) into `values` (width doubles each). Faces that share an edge and
 * give it the same values at both ends are smooth across it; elsewhere the edge is a seam.
 * Inside a chart values refine with the same rules, intervals and creases as positions; on
 * seams and boundaries with the mode's boundary rules and the seam edges' intervals. */
typedef struct {
    int32_t width;          /* doubles per value, 1..CCN_FVAR_MAX_WIDTH */
    int32_t num_values;
    const double *values;   /* width * num_values, finite */
    const int32_t *indices; /* one per face corner, in [0, num_values) */
    int32_t linear;         /* ccn_fvar_linear */
} ccn_fvar_channel;
#define CCN_FVAR_MAX_WIDTH 64

typedef struct ccn_fvar ccn_fvar; /* opaque: a refined face-varying channel */
typedef struct {
    int32_t width;
    int32_t level;
    int32_t num_values;      /* distinct refined values */
    int32_t num_face_verts;  /* face corners of the refined mesh (its value indices) */
    int32_t num_seam_edges;  /* cage edges whose values differ between their faces */
    int32_t num_sharp_values;/* values the mode keeps sharp (corners) at this level */
} ccn_fvar_info;

/* The channel after `levels` levels of ccn_refine of `cage` with the same options: the faces
 * and corners of ccn_refine's output, in its order. */
ccn_status ccn_fvar_refine(const ccn_mesh *cage, const ccn_fvar_channel *channel,
                           int32_t levels, const ccn_options *opts, ccn_fvar **out,
                           ccn_error *err);
ccn_status ccn_fvar_get_info(const ccn_fvar *fvar, ccn_fvar_info *info);
/* values: width * num_values; face_values: num_face_verts value indices; either may be NULL. */
ccn_status ccn_fvar_copy(const ccn_fvar *fvar, double *values, int32_t *face_values);
void ccn_fvar_destroy(ccn_fvar *fvar);

/* ---- extraordinary-vertex refinement matrix (Li, Finnigan, Sederberg 2016) ------ */

typedef struct {
    double lambda;    /* subdominant eigenvalue, eq (15) */
    double T0[2];     /* translation of the eigen polyhedron, eq (28) */
    int32_t fallback; /* 1 if the eigen rules failed and NURSS rules were used */
    double residual;  /* max |M P0 - lambda P0 - 1 T0| on the eigen polyhedron */
    int32_t polyhedron; /* EIGEN without fallback: the eigen polyhedron M is built from
                           (CCN_POLY_PAPER..CCN_POLY_COUNT); 0 otherwise */
    int32_t verified;   /* candidates the per-vertex choice verified (0: accepted unchecked) */
    int32_t outside_g1; /* 1: half the weight or more on candidates that fail the verification
                           (their eigen rules used unchecked; the NURSS rules where no candidate's
                           construction works): outside the range where G1 is verified */
} ccn_ev_info;

/* EXPERIMENTAL (research; may change without notice): the fixed eigen-polyhedron candidates,
 * for `ccnurbs experiment` and studies of the rules. Applications use CCN_POLY_SELECT (the
 * default, 0 in ccn_options) and ccn_ev_matrix.
 * Eigen polyhedra (scheme EIGEN; the list with reasons: csrc/rules/eigen_shape.h):
 * CCN_POLY_PAPER = Li 2016 section 5's spoke lengths; 2..11 = l_i^(1-e) d_i^e with
 * e = 0.1, 0.2, -0.1, 0.05, -0.05, 0.15, -0.2, 0.3, -0.3, 0.4; 12 = lengths in the ratio of the
 * transverse Greville abscissae (least squares); 13..28 = interval-dependent sector angles. */
#define CCN_POLY_SELECT 0
#define CCN_POLY_PAPER 1
#define CCN_POLY_COUNT 28

/* M ((2n+1) x (2n+1), row-major; rows F_0..F_{n-1}, E_0..E_{n-1}, V) for valence n >= 3
 * and spoke intervals d[0..n-1] > 0. info may be NULL. Scheme EIGEN: the per-vertex choice of
 * the eigen polyhedron (README "Eigen rules"): the paper's if max/min d <= 4, else a blend of
 * the candidates weighted by continuous margins of the single-maximum (level 5) and
 * characteristic-map checks (a few ms per candidate verified), so M is continuous in d;
 * info->polyhedron is the candidate of the largest weight, info->outside_g1 = 1 when half the
 * weight or more is on a paper's polyhedron that fails the checks. */
ccn_status ccn_ev_matrix(int32_t n, const double *spoke_knots, ccn_scheme scheme, double *M,
                         ccn_ev_info *info, ccn_error *err);

/* EXPERIMENTAL (research; may change without notice): ccn_ev_matrix with a given
 * polyhedron, CCN_POLY_SELECT (= ccn_ev_matrix) or a fixed candidate 1..CCN_POLY_COUNT (no
 * verification). */
ccn_status ccn_ev_matrix_polyhedron(int32_t n, const double *spoke_knots, ccn_scheme scheme,
                                    int32_t polyhedron, double *M, ccn_ev_info *info,
                                    ccn_error *err);

/* ---- limit surface: plan once, evaluate many times ------------------------------ */


/* The sizes of a plan's output buffers (ccn_plan_get_sizes). */
typedef struct {
    int32_t num_verts;        /* output mesh vertices */
    int32_t num_faces;        /* output mesh faces (all quads) */
    int32_t num_cage_verts;   /* length/3 of the positions ccn_plan_evaluate expects */
    int32_t num_edges;        /* output mesh edges (those of its faces) */
} ccn_sizes;

/* What a plan is made of (ccn_plan_get_stats): its levels, the cage's extraordinary vertices
 * and how they are treated, its sharp features, what the cage reader set aside. */
typedef struct {
    int32_t levels;           /* effective output level (>= 1 when the cage has non-quads) */
    int32_t refine_levels;    /* internal refinement depth */
    int32_t num_extraordinary;/* interior EVs of the cage after the first split */
    int32_t num_caps;         /* EVs closed by a finite cap (guided bi-5, G1 fill or their blend) */
    int32_t num_cap_fallbacks;/* EVs that use the refined limit instead of a cap */
    int32_t num_caps_deferred;/* cap EVs (bi-5) with no cap built because the output level is not
                                 above the cap level (they would change no output sample); the
                                 finite patch set (ccn_plan_patches, ccn_plan_export) needs them:
                                 a plan one level finer builds them */
    int32_t num_ev_fallbacks; /* EVs whose eigen rules fell back to NURSS */
    int32_t num_ev_verified;  /* EVs whose eigen polyhedron was verified (spoke ratio > 4) */
    int32_t num_ev_outside_g1;/* of those, EVs no candidate polyhedron passed (used unchecked) */
    int32_t num_ring_conflicts, num_ignored_verts, num_ignored_edges; /* as ccn_mesh_info */
    int32_t num_sharp_edges;  /* cage edges with sharpness > 0 */
    int32_t num_sharp_vertices;
    int32_t num_sharp_corners;/* output vertices whose faces see more than one tangent plane
                                 (creases, corners): corner_normals differ from normals */
} ccn_plan_stats;

/* Caller-owned output buffers; sizes from ccn_plan_get_sizes. */
typedef struct {
    double *positions;    /* 3 * num_verts (required) */
    double *normals;      /* 3 * num_verts unit normals, may be NULL */
    int32_t *face_verts;  /* 4 * num_faces, counter-clockwise, may be NULL */
    int32_t *face_origin; /* num_faces: index of the cage face it lies on, may be NULL */
    double *corner_normals; /* 3 * 4 * num_faces: the unit normal of each face at each of its
                               corners, may be NULL. Equal to the vertex normal except on
                               sharp creases and corners, where each face gets the normal
                               of its own side (the vertex normal is then their mean). */
    int32_t *corner_edge_origin; /* 4 * num_faces: the edge from corner k to corner k+1 lies
                               on the edge of cage face face_origin that starts at cage face
                               corner j (this array holds the index of that corner in the
                               cage's face_verts, so its edge is face_verts[j] -> the face's next
                               corner), or -1 inside the cage face; may be NULL. Carries
                               creases, seams and sharp marks over to the limit mesh. */
    int32_t *edge_verts;  /* 2 * num_edges: the output edges' vertices (in the order the faces
                             first use them), may be NULL */
    int32_t *corner_edges;/* 4 * num_faces: the edge from corner k to corner k+1 of each face,
                             an index into edge_verts; may be NULL */
    double *curvatures;   /* 2 * num_verts principal curvatures k1 >= k2 of the limit surface,
                             positive where it bends away from its normal (a sphere with
                             outward normals: 1/r), may be NULL (then nothing is computed).
                             NaN is a flag, not a number: at an extraordinary vertex of the
                             refined limit the curvature is unbounded; on creases and corners,
                             boundary curves of smooth corners and boundary EVs, caps and the
                             bicubic faces around them it is not computed */
    double *curvature_dirs; /* 3 * num_verts unit direction of k1 (that of k2 is the normal
                             cross it), NaN where the curvature is; may be NULL */
} ccn_limit_mesh;

/* Output topology: the level-L refinement of the cage, i.e. every cage quad sampled on a
 * (2^L+1)^2 grid of its parameter domain (each quad of a split n-gon on (2^(L-1)+1)^2),
 * shared samples along edges: watertight, no duplicate vertices. Positions are exact limit
 * positions (cap = REFINE) or the guided bi-5 surface in the EV holes (cap = GUIDED_BI5);
 * normals are exact (from derivatives). */
ccn_status ccn_plan_create(const ccn_cage *cage, const ccn_options *opts, ccn_plan **out,
                           ccn_error *err);
/* The plan's two optional inputs, in its options (as OpenSubdiv's Bfr carries its cache):
 *  - opts->cache: the guided bi-5 operator of each valence, built once (~0.4 s at valence 32,
 *    a few ms at 3-8) and shared: identical output. Owned by the caller; thread-safe (plans may
 *    be created with one cache from several threads); the plan borrows it, so destroy the cache
 *    after every plan created with it.
 *  - opts->previous: the plan made for the cage before an edit, typically of its knot
 *    intervals (an interval edit). Where the cage's topology (faces, edges), creases and options
 *    (but threads) equal previous's, the levels' and output mesh's topology move over (no copy,
 *    no new memory), and the limit stencils, rule weights and cap parameters (taus) that read no
 *    changed interval (compared in the caller's units) are copied; everything else is made
 *    anew. The output is byte-identical to a plan made without it (intervals are normalised by
 *    powers of two, so the copies are exact). Otherwise previous is only freed. previous is
 *    destroyed by the call whatever it returns: do not use or destroy it afterwards (clear the
 *    options' pointer). Face-varying channels are not carried over: add them to the new plan. */
ccn_status ccn_cache_create(ccn_cache **out, ccn_error *err);
void ccn_cache_destroy(ccn_cache *cache);
ccn_status ccn_plan_get_sizes(const ccn_plan *plan, ccn_sizes *sizes);
ccn_status ccn_plan_get_stats(const ccn_plan *plan, ccn_plan_stats *stats);

/* The extraordinary points of the output surface (interior smooth vertices of valence != 4 of
 * the output level) and how each is made: CCN_EV_CAPPED, the guided bi-5 cap (G1, bounded
 * curvature); CCN_EV_FILLED, the G1 fill cap (G1, bounded curvature: spoke knot ratios beyond
 * the bi-5 cap's range, valence 5 and more); CCN_EV_CAP_BLENDED, the bi-5 cap blended with the
 * fill cap (or, at valence 3, with the refined limit) at the end of the bi-5 cap's range of knot
 * ratios; CCN_EV_REFINED, the refined limit (no cap: valence 3 beyond the bi-5 cap's range,
 * cap = REFINE, a cap that would fold, or an output level not above the cap level): its
 * curvature is unbounded there. Call with NULL arrays for *num, then with arrays of *num
 * entries: output vertex indices and ccn_ev_surface values (either may be NULL). CCN_OK, or
 * CCN_ERR_ARGUMENT (no plan or num), CCN_ERR_MEMORY. */
typedef enum { CCN_EV_CAPPED = 0, CCN_EV_CAP_BLENDED, CCN_EV_REFINED, CCN_EV_FILLED } ccn_ev_surface;
ccn_status ccn_plan_get_evs(const ccn_plan *plan, int32_t *num, int32_t *out_vertex,
                            int32_t *surface);
/* positions: 3 * num_cage_verts, or NULL for the cage's own positions. Topology outputs
 * (face_verts, face_origin) are the same on every call. */
ccn_status ccn_plan_evaluate(ccn_plan *plan, const double *positions, ccn_limit_mesh *out,
                             ccn_error *err);
/* ccn_plan_evaluate for the first evaluation of a plan made with options.previous: when out
 * names the arrays the last evaluation of prev wrote (the same positions, normals and
 * corner_normals pointers, their contents untouched since) and the cage positions are those of
 * that evaluation (an interval edit), only the output values the edit changed are computed and
 * written, the rest of out is kept; the result is byte-identical to ccn_plan_evaluate's. In
 * every other case (another buffer, other positions, prev never evaluated, a plan not
 * recreated, a later call) it is ccn_plan_evaluate. */
ccn_status ccn_plan_evaluate_changed(ccn_plan *plan, const double *positions, ccn_limit_mesh *out,
                                     ccn_error *err);
void ccn_plan_destroy(ccn_plan *plan);

/* Face-varying channels on the plan's output: ccn_plan_add_fvar refines the channel's value
 * topology with the plan's levels and composes its exact limit stencils into weights over the
 * channel's values, so each evaluation of new values (same indices) is one sparse product, no
 * rebuild. The output values are limit values at the output vertices
 * (per value vertex: the corners of faces meeting at an output vertex on one side of a seam
 * share one value); face_values gives each output face corner (4 * num_faces, the order of
 * ccn_limit_mesh.face_verts) its value. In guided-cap holes the values are the exact limit of
 * the refinement (the geometry there is the bi-5 cap). */
typedef struct {
    int32_t width;
    int32_t num_values;       /* output values */
    int32_t num_cage_values;  /* the channel's num_values (the length ccn_plan_evaluate_fvar reads) */
    int32_t num_seam_edges;   /* cage edges that are seams of this channel */
    int32_t num_sharp_values; /* output values the mode keeps sharp */
} ccn_fvar_sizes;
/* Adds a channel; *channel receives its index (0, 1, ...). */
ccn_status ccn_plan_add_fvar(ccn_plan *plan, const ccn_fvar_channel *ch, int32_t *channel,
                             ccn_error *err);
ccn_status ccn_plan_get_fvar_sizes(const ccn_plan *plan, int32_t channel, ccn_fvar_sizes *sizes);
/* values: width * num_cage_values, or NULL for the values given to ccn_plan_add_fvar;
 * out_values: width * num_values (required); face_values: 4 * num_faces, may be NULL. Like
 * ccn_plan_evaluate, one call at a time per plan (a channel over a high-valence n-gon runs
 * the plan's kept value levels). */
ccn_status ccn_plan_evaluate_fvar(ccn_plan *plan, int32_t channel, const double *values,
                                  double *out_values, int32_t *face_values, ccn_error *err);
/* Per-vertex data (colours, weights, any float attribute): width doubles per cage vertex
 * (1..CCN_FVAR_MAX_WIDTH), interpolated by the rules of the positions (their exact limit, in
 * cap holes too) through the same plan; out: width * num_verts, in output vertex order. */
ccn_status ccn_plan_evaluate_vertex_data(ccn_plan *plan, int32_t width, const double *data,
                                         double *out, ccn_error *err);

/* The finite patch set for the positions of the last ccn_plan_evaluate (call it first):
 * bicubic patches of the regular faces of the cap level (or of the deepest level without
 * caps) and the bi-5 rings and caps. fn receives the degree (3 or 5), (degree+1)^2 control
 * points (3 doubles each, first index along u) and the cage face the patch lies on.
 * Faces that are neither (irregular faces refined to the limit) are counted in *skipped. */
typedef void (*ccn_patch_fn)(void *user, int32_t degree, const double *points,
                             int32_t cage_face);
ccn_status ccn_plan_patches(const ccn_plan *plan, ccn_patch_fn fn, void *user,
                            int32_t *skipped);

/* ---- OBJ ------------------------------------------------------------------------ */

/* Parsed OBJ: `v`, `f`, and the comment statements other readers skip (1-based indices):
 *   # knot i j d      edge i-j has knot interval d
 *   # crease i j s    edge i-j has sharpness s (OpenSubdiv's; 10 = infinitely sharp)
 *   # corner i s      vertex i has sharpness s
 * and OpenSubdiv's shape tags (0-based indices, regression/shapes): `t crease`, `t corner`,
 * `t interpolateboundary`, `t creasemethod`, `t facevaryinginterpolateboundary`; other tags
 * are ignored with a warning (ccn_obj_get_warning). */
typedef struct ccn_obj ccn_obj;
ccn_status ccn_obj_parse(const char *text, size_t len, ccn_obj **out, ccn_error *err);
void ccn_obj_destroy(ccn_obj *obj);
/* A view of the parsed data as a cage (valid while obj lives). */
ccn_status ccn_obj_get_cage(const ccn_obj *obj, ccn_cage *cage);
/* Options the file's tags ask for; -1 where the file has no such tag. */
typedef struct {
    int32_t boundary_corners; /* t interpolateboundary: 1 (EDGE_AND_CORNER) -> PINNED,
                                 2 (EDGE_ONLY) and 0 (NONE) -> SMOOTH */
    int32_t boundary_none;    /* 1 if the tag was 0 (NONE: OpenSubdiv makes the boundary faces
                                 holes; here they are kept, refined as EDGE_ONLY) */
    int32_t crease_method;    /* t creasemethod normal|chaikin -> ccn_crease_method */
    int32_t fvar_boundary;    /* t facevaryinginterpolateboundary 0..5 */
} ccn_obj_tags;
ccn_status ccn_obj_get_tags(const ccn_obj *obj, ccn_obj_tags *tags);
/* The file's UV map (`vt u [v [w]]` lines, `f v/vt` corners) as a face-varying channel view
 * (valid while obj lives): width = the most components a `vt` line has, linear = the
 * facevaryinginterpolateboundary tag or ALL. num_values = 0 and NULL arrays when the file has
 * no `vt` or a face without texture indices (then a warning says so). */
ccn_status ccn_obj_get_fvar(const ccn_obj *obj, ccn_fvar_channel *channel);
/* Statements the reader skipped with a reason (unknown tags): count and text. */
int32_t ccn_obj_get_num_warnings(const ccn_obj *obj);
const char *ccn_obj_get_warning(const ccn_obj *obj, int32_t i);

const char *ccn_status_name(ccn_status s);

/* ---- CAD export: the exact surface as STEP or IGES ---------------------------------- */

typedef enum { CCN_EXPORT_STEP = 0, CCN_EXPORT_IGES = 1 } ccn_export_format;
/* ccn_export_options.flags: no packing (every regular cage quad and every patch its own face) */
#define CCN_EXPORT_UNPACKED 1u

typedef enum {
    CCN_EXPORT_FACE_PACK = 0, /* bicubic B-spline of a rectangle of regular faces, knots = the
                                 ring intervals (periodic where the rectangle closes) */
    CCN_EXPORT_FACE_BICUBIC,  /* one bicubic patch of the plan (faces around extraordinary points) */
    CCN_EXPORT_FACE_BI5,      /* a degree-5 ring or cap patch of a guided bi-5 cap */
    CCN_EXPORT_FACE_REFINED,  /* exact bicubic pieces of a hole refined below the plan's level */
    CCN_EXPORT_FACE_FILL      /* the approximate faces that close a hole (counted fallbacks) */
} ccn_export_face_kind;

/* Where part of an exported face lies: its parameters [uv[0],uv[1]] x [uv[2],uv[3]] map
 * affinely onto cage face cage_face (sub = -1: a quad, local (s,t) in [0,1]^2 with corner 0 at
 * (0,0) and its first half-edge along s) or onto the level-1 quad at corner `sub` of a cage
 * face with n != 4 sides (corner 0 = the cage vertex, 1 = midpoint of the edge of that corner's
 * half-edge, 2 = the face point, 3 = midpoint of the previous edge). st[0], st[1], st[2] are the
 * local coordinates at (u0,v0), (u1,v0) and (u0,v1). */
typedef struct {
    int32_t cage_face, sub;
    double uv[4];
    double st[3][2];
} ccn_export_cell;

/* One exported face: where it lies and its polynomial B-spline surface as written (valid
 * during the call). Its domain is [t_p, t_n] per direction of the flat knot vector t (n
 * poles, degree p); periodic: the last p pole rows repeat the first ones (closed). */
typedef struct {
    int32_t index;   /* face number in the file's shell order, from 0 */
    int32_t kind;    /* ccn_export_face_kind */
    int32_t patch;   /* index in ccn_plan_patches' output, -1 if the face is none of them */
    int32_t num_cells;
    const ccn_export_cell *cells;
    int32_t degree[2], num_poles[2], num_knots[2], periodic[2]; /* u, v */
    const double *knots[2];  /* distinct values, increasing */
    const int32_t *mults[2]; /* their multiplicities */
    const double *poles;     /* num_poles[0] x num_poles[1] x 3, first index along u */
} ccn_export_face;
typedef void (*ccn_export_face_fn)(void *user, const ccn_export_face *face);
/* Output sink: returns 0 on success, non-zero to stop (the export returns CCN_ERR_IO). */
typedef int (*ccn_write_fn)(void *user, const char *data, size_t len);
/* Progress in [0, 1]. */
typedef void (*ccn_progress_fn)(void *user, double fraction);

typedef struct {
    int32_t format;          /* ccn_export_format */
    uint32_t flags;          /* CCN_EXPORT_UNPACKED */
    const char *name;        /* product name: printable ASCII without quotes, NULL = "ccnurbs" */
    const char *timestamp;   /* "YYYY-MM-DDThh:mm:ss", NULL = fixed (byte-identical output) */
    double tolerance;        /* model units (mm); <= 0: max(1e-7, 1e-10 x size) */
    int32_t fill_levels;     /* levels refined below the patch level around holes, 1..12;
                                0 = default (6) */
    ccn_export_face_fn face_fn; /* optional: called once per face, in file order */
    void *face_user;
    ccn_progress_fn progress;   /* optional */
    void *progress_user;
} ccn_export_options;

typedef struct {
    int32_t num_faces;
    int32_t num_packs, num_bicubic, num_bi5, num_refined, num_fill_faces; /* by kind */
    int32_t num_packed_cage_faces; /* cage quads inside level-0 packs */
    int32_t num_fills;       /* holes closed by fill faces: irregular vertices without cap */
    int32_t fill_level;      /* mesh level of the deepest fill faces, or of caps closing holes
                              * in their place (-1: none; smooth valence-2 vertices' fills lie
                              * fewer levels down, see docs/cad-export.md) */
    int32_t num_edges, num_vertices, num_shells, num_boundary_edges;
    int32_t closed;          /* every edge shared by two face sides: a closed shell (solid) */
    double max_g1_deviation;      /* rad: largest normal angle across shared edges, fills and
                                     creases excluded */
    double max_fill_g1_deviation; /* rad: the same across edges of fill faces (0 without fills) */
    double size;             /* bounding-box diagonal of the poles */
    int64_t bytes;           /* written */
    /* creases: edges on infinitely sharp cage edges, where faces meet C0 (shared edge, normals
     * differ); they are not in max_g1_deviation / max_fill_g1_deviation */
    int32_t num_crease_edges;
    double min_crease_angle, max_crease_angle; /* rad: normal angle across them (0 without) */
} ccn_export_info;

/* Evaluates the plan at positions (3 * num_cage_verts, NULL = the cage's own, as
 * ccn_plan_evaluate) and writes its finite surface as STEP AP214 or IGES 5.3 through fn: one
 * B-spline face per maximal rectangle of regular cage quads (ring intervals as knots), the
 * plan's bicubic patches and bi-5 rings and caps around extraordinary points, and where the
 * plan has no patch (cap fallbacks, smooth boundary corners, boundary EVs) the exact pieces
 * of a deeper local refinement closed by fill faces, whose G1 deviation is measured. Faces
 * share their edges, one shell per connected part of the cage, in the file part by part (closed
 * cages: a solid per part). opts NULL = defaults; info may be
 * NULL. Nothing is written if the status is not CCN_OK before output starts. A bi-5 plan
 * whose caps were not built (ccn_plan_stats.num_caps_deferred > 0: output level not above the cap
 * level) is CCN_ERR_ARGUMENT: create it with more levels. */
ccn_status ccn_plan_export(ccn_plan *plan, const double *positions, const ccn_export_options *opts,
                           ccn_write_fn fn, void *user, ccn_export_info *info, ccn_error *err);

#ifdef __cplusplus
}
#endif
#endif
