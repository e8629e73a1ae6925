/* STEP AP214 writer of the neutral B-rep (cad.h).
 *
 * Entities, leaves first so that every reference points backwards:
 *   CARTESIAN_POINT (one per distinct point: poles shared bit for bit by curves and surfaces
 *   are referenced, not repeated; 2D points of the pcurves likewise), VERTEX_POINT (one per
 *   shared vertex), B_SPLINE_SURFACE_WITH_KNOTS per face,
 *   per shared edge: B_SPLINE_CURVE_WITH_KNOTS (the iso curve of the side segment that defines
 *   it, in increasing parameter, cut to the segment when the side is split), a PCURVE on each
 *   face it bounds (DEFINITIONAL_REPRESENTATION of a degree-1 B-spline: the side's straight
 *   line in the face's domain over the curve's parameters [0, 1]; one per distinct line,
 *   referenced by every PCURVE along it), SURFACE_CURVE (SEAM_CURVE where a
 *   face meets itself), EDGE_CURVE,
 *   per face: an ORIENTED_EDGE per side segment, EDGE_LOOP, FACE_OUTER_BOUND,
 *   ADVANCED_FACE (same_sense .T.: the face normal is Su x Sv),
 *   CLOSED_SHELL + MANIFOLD_SOLID_BREP + ADVANCED_BREP_SHAPE_REPRESENTATION when every side
 *   is shared, else OPEN_SHELL + SHELL_BASED_SURFACE_MODEL +
 *   MANIFOLD_SURFACE_SHAPE_REPRESENTATION,
 *   the representation context (millimetre, radian, steradian, the tolerance as
 *   UNCERTAINTY_MEASURE_WITH_UNIT) and the AP214 product structure (PRODUCT ->
 *   PRODUCT_DEFINITION -> PRODUCT_DEFINITION_SHAPE -> SHAPE_DEFINITION_REPRESENTATION).
 * The pcurves are exact (every edge is an iso line of each face it bounds), so a reader need
 * not project the edges onto the faces: projected to the file's tolerance, on faces 1e-4 of the
 * model in size, an edge lands 1e-3 of the face's range off its side (OpenCASCADE's normals
 * across catmark_car's edges 2.3e-5 rad without pcurves, as close as its faces with them).
 */
#include "io/cad.h"

#include "base/error.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Entities written so far by a key of four 64-bit words: points by their coordinates' bits (a
 * point shared by several curves and surfaces, the boundary poles two faces and their edge
 * share bit for bit, is one CARTESIAN_POINT that all of them reference) and pcurve lines by
 * their end points and parameters (faces with one shape of domain repeat them: one
 * DEFINITIONAL_REPRESENTATION serves every PCURVE along such a line). */
typedef struct {
    uint64_t key[4];
    int32_t id; /* 0: empty */
} ent_slot;

typedef struct {
    ent_slot *tab;
    size_t n, cap; /* cap: a power of two (open addressing) */
    int oom;       /* then: no sharing */
} ent_table;

typedef struct {
    ccn__cad_out o;
    int32_t id; /* last entity id written */
    ent_table pts, lines;
} step_w;

static int32_t ent(step_w *w) {
    w->id++;
    ccn__cad_printf(&w->o, "#%d=", (int)w->id);
    return w->id;
}

static size_t ent_hash(const uint64_t k[4]) {
    uint64_t h = 1469598103934665603ull;
    for (int i = 0; i < 4; i++) h = (h ^ k[i]) * 1099511628211ull, h ^= h >> 31;
    return (size_t)h;
}

static ent_slot *slot_find(ent_slot *tab, size_t cap, const uint64_t k[4]) {
    for (size_t i = ent_hash(k) & (cap - 1);; i = (i + 1) & (cap - 1))
        if (!tab[i].id || !memcmp(tab[i].key, k, sizeof tab[i].key)) return &tab[i];
}

/* The slot of key k: its entity if .id != 0, else where to record it (ent_add); NULL when the
 * table is out of memory. */
static ent_slot *ent_find(ent_table *t, const uint64_t k[4]) {
    if (!t->oom && 2 * (t->n + 1) > t->cap) {
        size_t cap = t->cap ? 2 * t->cap : 4096;
        ent_slot *tab = calloc(cap, sizeof *tab);
        if (!tab) {
            t->oom = 1;
        } else {
            for (size_t i = 0; i < t->cap; i++)
                if (t->tab[i].id) *slot_find(tab, cap, t->tab[i].key) = t->tab[i];
            free(t->tab);
            t->tab = tab;
            t->cap = cap;
        }
    }
    return t->oom ? NULL : slot_find(t->tab, t->cap, k);
}

static void ent_add(ent_table *t, ent_slot *s, const uint64_t k[4], int32_t id) {
    if (!s) return;
    memcpy(s->key, k, sizeof s->key);
    s->id = id;
    t->n++;
}

/* A CARTESIAN_POINT of dim 3 (p[0..2]) or 2 (p[0..1]: a parameter-space point of a pcurve,
 * kept apart from the 3D points by a NaN third key no coordinate has). */
static int32_t point_dim(step_w *w, const double *p, int dim) {
    uint64_t k[4] = {0, 0, 0, 0};
    memcpy(k, p, sizeof(double) * (size_t)dim);
    if (dim == 2) k[2] = 0x7ff8dead2d2d2d2dull;
    ent_slot *s = ent_find(&w->pts, k);
    if (s && s->id) return s->id;
    char a[32], b[32], c[32];
    int32_t id = ent(w);
    if (dim == 2)
        ccn__cad_printf(&w->o, "CARTESIAN_POINT('',(%s,%s));\n", ccn__cad_real(p[0], a),
                        ccn__cad_real(p[1], b));
    else
        ccn__cad_printf(&w->o, "CARTESIAN_POINT('',(%s,%s,%s));\n", ccn__cad_real(p[0], a),
                        ccn__cad_real(p[1], b), ccn__cad_real(p[2], c));
    ent_add(&w->pts, s, k, id);
    return id;
}

static int32_t point(step_w *w, const double p[3]) { return point_dim(w, p, 3); }

/* Distinct knots and multiplicities of a flat knot vector. */
static void flat_knot_lists(step_w *w, const double *t, int32_t nt) {
    char r[32];
    ccn__cad_puts(&w->o, "(");
    for (int32_t i = 0, first = 1; i < nt; first = 0) {
        int32_t k = i;
        while (k < nt && t[k] == t[i]) k++;
        ccn__cad_printf(&w->o, "%s%d", first ? "" : ",", (int)(k - i));
        i = k;
    }
    ccn__cad_puts(&w->o, "),(");
    for (int32_t i = 0, first = 1; i < nt; first = 0) {
        ccn__cad_printf(&w->o, "%s%s", first ? "" : ",", ccn__cad_real(t[i], r));
        int32_t k = i;
        while (k < nt && t[k] == t[i]) k++;
        i = k;
    }
    ccn__cad_puts(&w->o, ")");
}

/* The id list ids[0..n-1], wrapped every 8 ids. */
static void id_list(step_w *w, const int32_t *ids, int32_t n) {
    ccn__cad_puts(&w->o, "(");
    for (int32_t i = 0; i < n; i++)
        ccn__cad_printf(&w->o, "%s#%d", i ? (i % 8 ? "," : ",\n") : "", (int)ids[i]);
    ccn__cad_puts(&w->o, ")");
}

/* The pcurve of edge e's curve (parameters [c0, c1]) on segment j: the straight line in j's
 * face domain between the ends of the segment that meet the curve's start and end, a degree-1
 * B-spline over the same parameters, so that the curve and the pcurve agree point for point
 * (the writers check the segments are one curve up to an affine change: cad.h). */
static int32_t pcurve(step_w *w, const ccn__cad_model *m, const ccn__cad_topo *t, int32_t j,
                      double c0, double c1, int32_t surf, int32_t ctx2d) {
    double a[2], b[2];
    ccn__cad_segment_ends_uv(m, t, j, 1, a, b);
    int32_t pa = point_dim(w, a, 2), pb = point_dim(w, b, 2);
    uint64_t k[4] = {(uint64_t)pa, (uint64_t)pb, 0, 0};
    memcpy(k + 2, &c0, sizeof c0);
    memcpy(k + 3, &c1, sizeof c1);
    ent_slot *s = ent_find(&w->lines, k);
    int32_t rep = s ? s->id : 0;
    if (!rep) {
        char r0[32], r1[32];
        int32_t line = ent(w);
        ccn__cad_printf(&w->o, "B_SPLINE_CURVE_WITH_KNOTS('',1,(#%d,#%d),.POLYLINE_FORM.,.F.,.F.,(2,2),"
                               "(%s,%s),.UNSPECIFIED.);\n", (int)pa, (int)pb, ccn__cad_real(c0, r0),
                        ccn__cad_real(c1, r1));
        rep = ent(w);
        ccn__cad_printf(&w->o, "DEFINITIONAL_REPRESENTATION('',(#%d),#%d);\n", (int)line, (int)ctx2d);
        ent_add(&w->lines, s, k, rep);
    }
    int32_t id = ent(w);
    ccn__cad_printf(&w->o, "PCURVE('',#%d,#%d);\n", (int)surf, (int)rep);
    return id;
}

static int32_t edge_curve(step_w *w, const ccn__cad_model *m, const ccn__cad_topo *t,
                          const int32_t *vert_id, const int32_t *surf_id, int32_t ctx2d,
                          int32_t e, ccn__cad_curve *c, int32_t *ids) {
    int32_t j0 = t->edge_seg[e], j1 = m->adjacency[j0];
    ccn__cad_segment_curve(m, t, j0, c);
    for (int32_t i = 0; i < c->num_poles; i++) ids[i] = point(w, c->poles + 3 * (size_t)i);
    int closed = t->edge_vert[2 * e] == t->edge_vert[2 * e + 1];
    int32_t curve = ent(w);
    ccn__cad_printf(&w->o, "B_SPLINE_CURVE_WITH_KNOTS('',%d,", (int)c->degree);
    id_list(w, ids, c->num_poles);
    ccn__cad_printf(&w->o, ",.UNSPECIFIED.,%s,.F.,", closed ? ".T." : ".F.");
    flat_knot_lists(w, c->knots, c->num_poles + c->degree + 1);
    ccn__cad_puts(&w->o, ",.UNSPECIFIED.);\n");
    double c0 = c->knots[c->degree], c1 = c->knots[c->num_poles];
    int32_t pc[2], npc = 0;
    pc[npc++] = pcurve(w, m, t, j0, c0, c1, surf_id[t->seg_face[j0]], ctx2d);
    if (j1 >= 0) pc[npc++] = pcurve(w, m, t, j1, c0, c1, surf_id[t->seg_face[j1]], ctx2d);
    int seam = j1 >= 0 && t->seg_face[j1] == t->seg_face[j0];
    int32_t sc = ent(w);
    ccn__cad_printf(&w->o, "%s('',#%d,", seam ? "SEAM_CURVE" : "SURFACE_CURVE", (int)curve);
    id_list(w, pc, npc);
    ccn__cad_puts(&w->o, ",.CURVE_3D.);\n");
    int32_t id = ent(w);
    ccn__cad_printf(&w->o, "EDGE_CURVE('',#%d,#%d,#%d,.T.);\n", (int)vert_id[t->edge_vert[2 * e]],
                    (int)vert_id[t->edge_vert[2 * e + 1]], (int)sc);
    return id;
}

static int32_t surface(step_w *w, const ccn__cad_model *m, int32_t fi, int32_t *ids) {
    const ccn__cad_surface *f = &m->faces[fi];
    int32_t nu = f->num_poles[0], nv = f->num_poles[1];
    for (int32_t i = 0; i < nu; i++)
        for (int32_t j = 0; j < nv; j++)
            ids[(size_t)i * nv + j] = point(w, f->poles + 3 * ((size_t)i * nv + j));
    int32_t surf = ent(w);
    ccn__cad_printf(&w->o, "B_SPLINE_SURFACE_WITH_KNOTS('',%d,%d,(", (int)f->degree[0],
                    (int)f->degree[1]);
    for (int32_t i = 0; i < nu; i++) {
        ccn__cad_puts(&w->o, i ? ",\n" : "");
        id_list(w, ids + (size_t)i * nv, nv);
    }
    ccn__cad_printf(&w->o, "),.UNSPECIFIED.,%s,%s,.F.,", f->periodic[0] ? ".T." : ".F.",
                    f->periodic[1] ? ".T." : ".F.");
    ccn__cad_puts(&w->o, "(");
    for (int32_t k = 0; k < f->num_knots[0]; k++)
        ccn__cad_printf(&w->o, "%s%d", k ? "," : "", (int)f->mults[0][k]);
    ccn__cad_puts(&w->o, "),(");
    for (int32_t k = 0; k < f->num_knots[1]; k++)
        ccn__cad_printf(&w->o, "%s%d", k ? "," : "", (int)f->mults[1][k]);
    ccn__cad_puts(&w->o, "),(");
    char r[32];
    for (int32_t k = 0; k < f->num_knots[0]; k++)
        ccn__cad_printf(&w->o, "%s%s", k ? "," : "", ccn__cad_real(f->knots[0][k], r));
    ccn__cad_puts(&w->o, "),(");
    for (int32_t k = 0; k < f->num_knots[1]; k++)
        ccn__cad_printf(&w->o, "%s%s", k ? "," : "", ccn__cad_real(f->knots[1][k], r));
    ccn__cad_puts(&w->o, "),.UNSPECIFIED.);\n");
    return surf;
}

static int32_t face(step_w *w, const ccn__cad_topo *t, const int32_t *edge_id, int32_t surf,
                    int32_t fi, int32_t *ids) {
    int32_t j0 = t->face_seg[fi], nj = t->face_seg[fi + 1] - j0;
    for (int32_t j = j0; j < j0 + nj; j++) {
        ids[j - j0] = ent(w);
        ccn__cad_printf(&w->o, "ORIENTED_EDGE('',*,*,#%d,%s);\n", (int)edge_id[t->seg_edge[j]],
                        t->seg_sense[j] ? ".T." : ".F.");
    }
    int32_t loop = ent(w);
    ccn__cad_puts(&w->o, "EDGE_LOOP('',");
    id_list(w, ids, nj);
    ccn__cad_puts(&w->o, ");\n");
    int32_t bound = ent(w);
    ccn__cad_printf(&w->o, "FACE_OUTER_BOUND('',#%d,.T.);\n", (int)loop);
    int32_t id = ent(w);
    ccn__cad_printf(&w->o, "ADVANCED_FACE('',(#%d),#%d,.T.);\n", (int)bound, (int)surf);
    return id;
}

static void header(step_w *w, const char *name, const char *stamp) {
    ccn__cad_puts(&w->o, "ISO-10303-21;\nHEADER;\n");
    ccn__cad_puts(&w->o, "FILE_DESCRIPTION(('CCNURBS exact limit surface'),'2;1');\n");
    ccn__cad_printf(&w->o, "FILE_NAME('%s','%s',(''),(''),'ccnurbs %d.%d','ccnurbs','');\n", name,
                    stamp, CCN_VERSION_MAJOR, CCN_VERSION_MINOR);
    ccn__cad_puts(&w->o, "FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\n");
    ccn__cad_puts(&w->o, "ENDSEC;\nDATA;\n");
}

/* Context, units, representation and the product structure around the shape item. */
static void trailer(step_w *w, const char *name, int closed, const int32_t *items, int32_t nitems, double tol) {
    char r[32];
    ccn__cad_out *o = &w->o;
    int32_t mm = ent(w);
    ccn__cad_puts(o, "(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.MILLI.,.METRE.));\n");
    int32_t rad = ent(w);
    ccn__cad_puts(o, "(NAMED_UNIT(*)PLANE_ANGLE_UNIT()SI_UNIT($,.RADIAN.));\n");
    int32_t sr = ent(w);
    ccn__cad_puts(o, "(NAMED_UNIT(*)SI_UNIT($,.STERADIAN.)SOLID_ANGLE_UNIT());\n");
    int32_t unc = ent(w);
    ccn__cad_printf(o, "UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(%s),#%d,'distance_accuracy_value',"
                       "'confusion accuracy');\n", ccn__cad_real(tol, r), (int)mm);
    int32_t ctx = ent(w);
    ccn__cad_printf(o, "(GEOMETRIC_REPRESENTATION_CONTEXT(3)GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((#%d))"
                       "GLOBAL_UNIT_ASSIGNED_CONTEXT((#%d,#%d,#%d))REPRESENTATION_CONTEXT('',''));\n",
                    (int)unc, (int)mm, (int)rad, (int)sr);
    double org[3] = {0, 0, 0};
    int32_t p0 = point(w, org);
    int32_t dz = ent(w);
    ccn__cad_puts(o, "DIRECTION('',(0.,0.,1.));\n");
    int32_t dx = ent(w);
    ccn__cad_puts(o, "DIRECTION('',(1.,0.,0.));\n");
    int32_t ax = ent(w);
    ccn__cad_printf(o, "AXIS2_PLACEMENT_3D('',#%d,#%d,#%d);\n", (int)p0, (int)dz, (int)dx);
    int32_t rep = ent(w);
    ccn__cad_printf(o, "%s('%s',(#%d",
                    closed ? "ADVANCED_BREP_SHAPE_REPRESENTATION" : "MANIFOLD_SURFACE_SHAPE_REPRESENTATION",
                    name, (int)ax);
    for (int32_t k = 0; k < nitems; k++) ccn__cad_printf(o, ",%s#%d", k % 8 == 7 ? "\n" : "", (int)items[k]);
    ccn__cad_printf(o, "),#%d);\n", (int)ctx);
    int32_t app = ent(w);
    ccn__cad_puts(o, "APPLICATION_CONTEXT('automotive design');\n");
    ent(w);
    ccn__cad_printf(o, "APPLICATION_PROTOCOL_DEFINITION('international standard','automotive_design',"
                       "2000,#%d);\n", (int)app);
    int32_t pctx = ent(w);
    ccn__cad_printf(o, "PRODUCT_CONTEXT('',#%d,'mechanical');\n", (int)app);
    int32_t prod = ent(w);
    ccn__cad_printf(o, "PRODUCT('%s','%s','',(#%d));\n", name, name, (int)pctx);
    ent(w);
    ccn__cad_printf(o, "PRODUCT_RELATED_PRODUCT_CATEGORY('part',$,(#%d));\n", (int)prod);
    int32_t pdf = ent(w);
    ccn__cad_printf(o, "PRODUCT_DEFINITION_FORMATION('','',#%d);\n", (int)prod);
    int32_t pdc = ent(w);
    ccn__cad_printf(o, "PRODUCT_DEFINITION_CONTEXT('part definition',#%d,'design');\n", (int)app);
    int32_t pd = ent(w);
    ccn__cad_printf(o, "PRODUCT_DEFINITION('design','',#%d,#%d);\n", (int)pdf, (int)pdc);
    int32_t pds = ent(w);
    ccn__cad_printf(o, "PRODUCT_DEFINITION_SHAPE('','',#%d);\n", (int)pd);
    ent(w);
    ccn__cad_printf(o, "SHAPE_DEFINITION_REPRESENTATION(#%d,#%d);\n", (int)pds, (int)rep);
    ccn__cad_puts(o, "ENDSEC;\nEND-ISO-10303-21;\n");
}

ccn_status ccn__step_write(const ccn__cad_model *m, ccn__cad_write_fn fn, void *user,
                           ccn_error *err) {
    if (!fn) return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "write callback is NULL");
    ccn__cad_topo t;
    ccn_status st = ccn__cad_topo_build(m, &t, err);
    if (st) return st;
    int32_t maxp = 0;
    size_t maxids = 1; /* a face's poles, or its side segments */
    for (int32_t f = 0; f < m->num_faces; f++) {
        int32_t c = ccn__cad_curve_capacity(&m->faces[f]);
        maxp = c > maxp ? c : maxp;
        size_t np = (size_t)m->faces[f].num_poles[0] * (size_t)m->faces[f].num_poles[1];
        size_t ns = (size_t)(t.face_seg[f + 1] - t.face_seg[f]);
        maxids = np > maxids ? np : maxids;
        maxids = ns > maxids ? ns : maxids;
    }
    maxids = (size_t)maxp > maxids ? (size_t)maxp : maxids;
    maxids = (size_t)t.num_shells > maxids ? (size_t)t.num_shells : maxids; /* the solids */
    int32_t *vert_id = malloc(sizeof(int32_t) * (size_t)t.num_verts);
    int32_t *edge_id = malloc(sizeof(int32_t) * (size_t)t.num_edges);
    int32_t *face_id = malloc(sizeof(int32_t) * (size_t)m->num_faces);
    int32_t *surf_id = malloc(sizeof(int32_t) * (size_t)m->num_faces);
    int32_t *shell_id = malloc(sizeof(int32_t) * (size_t)t.num_shells);
    double *scratch = malloc(sizeof(double) * (4 * (size_t)maxp + CCN_CAD_MAX_DEGREE + 1));
    int32_t *ids = malloc(sizeof(int32_t) * maxids);
    step_w *w = calloc(1, sizeof *w);
    if (!vert_id || !edge_id || !face_id || !surf_id || !shell_id || !scratch || !ids || !w) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
        goto done;
    }
    ccn__cad_out_init(&w->o, fn, user);
    w->id = 0;
    const char *name = m->name ? m->name : "ccnurbs";
    header(w, name, m->timestamp ? m->timestamp : "2000-01-01T00:00:00");
    for (int32_t v = 0; v < t.num_verts; v++) {
        int32_t p = point(w, t.vert_pos + 3 * (size_t)v);
        vert_id[v] = ent(w);
        ccn__cad_printf(&w->o, "VERTEX_POINT('',#%d);\n", (int)p);
    }
    ccn__cad_curve c = {0, 0, scratch + 3 * (size_t)maxp, scratch, 0}; /* poles, then knots */
    for (int32_t f = 0; f < m->num_faces; f++) surf_id[f] = surface(w, m, f, ids);
    int32_t ctx2d = ent(w);
    ccn__cad_puts(&w->o, "(GEOMETRIC_REPRESENTATION_CONTEXT(2)PARAMETRIC_REPRESENTATION_CONTEXT()"
                         "REPRESENTATION_CONTEXT('2D SPACE',''));\n");
    for (int32_t e = 0; e < t.num_edges; e++)
        edge_id[e] = edge_curve(w, m, &t, vert_id, surf_id, ctx2d, e, &c, ids);
    for (int32_t f = 0; f < m->num_faces; f++) face_id[f] = face(w, &t, edge_id, surf_id[f], f, ids);
    /* one shell per connected component; closed: a solid each, else one surface model */
    for (int32_t sh = 0; sh < t.num_shells; sh++) {
        shell_id[sh] = ent(w);
        ccn__cad_printf(&w->o, "%s('',(", t.shell_closed[sh] ? "CLOSED_SHELL" : "OPEN_SHELL");
        for (int32_t k = t.shell_start[sh]; k < t.shell_start[sh + 1]; k++) {
            int32_t i = k - t.shell_start[sh];
            ccn__cad_printf(&w->o, "%s#%d", i ? (i % 8 ? "," : ",\n") : "", (int)face_id[t.shell_face[k]]);
        }
        ccn__cad_puts(&w->o, "));\n");
    }
    int32_t nitems = 0;
    if (t.closed)
        for (int32_t sh = 0; sh < t.num_shells; sh++) {
            ids[nitems++] = ent(w);
            if (t.num_shells == 1) ccn__cad_printf(&w->o, "MANIFOLD_SOLID_BREP('%s',#%d);\n", name, (int)shell_id[sh]);
            else ccn__cad_printf(&w->o, "MANIFOLD_SOLID_BREP('%s %d',#%d);\n", name, (int)sh + 1, (int)shell_id[sh]);
        }
    else {
        ids[nitems++] = ent(w);
        ccn__cad_printf(&w->o, "SHELL_BASED_SURFACE_MODEL('%s',(", name);
        for (int32_t sh = 0; sh < t.num_shells; sh++)
            ccn__cad_printf(&w->o, "%s#%d", sh ? (sh % 8 ? "," : ",\n") : "", (int)shell_id[sh]);
        ccn__cad_puts(&w->o, "));\n");
    }
    trailer(w, name, t.closed, ids, nitems, t.tolerance);
    if (ccn__cad_flush(&w->o))
        st = ccn__fail(err, CCN_ERR_IO, CCN_ELEM_NONE, -1, "writing the STEP file failed");
done:
    if (w) free(w->pts.tab), free(w->lines.tab);
    free(vert_id); free(edge_id); free(face_id); free(surf_id); free(shell_id); free(scratch); free(ids); free(w);
    ccn__cad_topo_free(&t);
    return st;
}
