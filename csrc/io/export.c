/* ccn_plan_export (public): the plan's finite surface as STEP or IGES (EXPORT_DESIGN.md).
 *
 *   1. evaluate the plan; its patches with their places (surface/patch_set.h);
 *   2. packs (packs.c): maximal rectangles of regular cage quads, then of the strict patch-level
 *      faces left, each one B-spline face (unpacked: each regular cage quad alone);
 *   3. the plan's other patches (bicubic around caps, bi-5 rings and caps) one face each;
 *   4. holes (faces the plan has no patch for): refined deeper and closed (fill.c);
 *   5. topology from the places (export_topo.c); G1 deviation measured on the model: the
 *      normals of both faces at 8 inner points of every shared segment (segments on infinitely
 *      sharp cage edges, C0 by design, counted apart with their smallest and largest angle);
 *   6. the STEP or IGES writer through the caller's callback.
 */
#include "io/export_model.h"
#include "io/export_topo.h"
#include "io/face_merge.h"
#include "io/fill.h"
#include "io/knot_removal.h"
#include "io/packs.h"

#include "base/error.h"
#include "base/vec3.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define CCN_EXPORT_DEFAULT_FILL_LEVELS 6
#define CCN_EXPORT_MAX_FILL_LEVELS 12

/* ---- the plan's patches ------------------------------------------------------------ */

typedef struct {
    ccn__patch_place pl; /* points -> into pts */
    size_t off;
} rec;

typedef struct {
    rec *r;
    size_t n, cap;
    double *pts;
    size_t npts, cap_pts;
    int oom;
} rec_list;

static void collect(void *user, const ccn__patch_place *p) {
    rec_list *l = user;
    if (l->oom) return;
    size_t np = p->points ? 3 * (size_t)(p->degree + 1) * (size_t)(p->degree + 1) : 0;
    if (l->n == l->cap) {
        size_t c = l->cap ? 2 * l->cap : 1024;
        rec *q = realloc(l->r, sizeof *q * c);
        if (!q) { l->oom = 1; return; }
        l->r = q;
        l->cap = c;
    }
    if (l->npts + np > l->cap_pts) {
        size_t c = 2 * (l->npts + np) + 4096;
        double *q = realloc(l->pts, sizeof *q * c);
        if (!q) { l->oom = 1; return; }
        l->pts = q;
        l->cap_pts = c;
    }
    rec *r = &l->r[l->n++];
    r->pl = *p;
    r->off = l->npts;
    if (np) memcpy(l->pts + l->npts, p->points, sizeof(double) * np);
    l->npts += np;
}

typedef struct { const ccn_mesh *const *lev; int32_t level; } place_ctx;

static void place_level(void *ctx, int32_t face, ccn__xplace *out) {
    const place_ctx *c = ctx;
    ccn__xplace_of(c->lev, c->level, face, out);
}

/* ---- validation -------------------------------------------------------------------- */

static ccn_status check_opts(const ccn_export_options *o, ccn_error *err) {
    if (o->format != CCN_EXPORT_STEP && o->format != CCN_EXPORT_IGES)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1,
                         "unknown export format %d (0 = STEP, 1 = IGES)", (int)o->format);
    if (o->flags & ~(uint32_t)CCN_EXPORT_UNPACKED)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "unknown export flags 0x%x",
                         (unsigned)(o->flags & ~(uint32_t)CCN_EXPORT_UNPACKED));
    if (isnan(o->tolerance) || isinf(o->tolerance))
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "tolerance must be finite");
    if (o->fill_levels < 0 || o->fill_levels > CCN_EXPORT_MAX_FILL_LEVELS)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "fill_levels must be in [0, %d], got %d",
                         CCN_EXPORT_MAX_FILL_LEVELS, (int)o->fill_levels);
    const char *strs[2] = {o->name, o->timestamp};
    for (int k = 0; k < 2; k++)
        for (const char *c = strs[k]; c && *c; c++)
            if (*c < 32 || *c > 126 || *c == '\'' || *c == '\\' || c - strs[k] >= 200)
                return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1,
                                 "the %s must be printable ASCII (at most 200 characters) without "
                                 "quotes or backslashes", k ? "timestamp" : "name");
    if (o->timestamp) { /* YYYY-MM-DDThh:mm:ss */
        const char *t = o->timestamp, *pat = "dddd-dd-ddTdd:dd:dd";
        int ok = strlen(t) == strlen(pat);
        for (size_t i = 0; ok && pat[i]; i++)
            ok = pat[i] == 'd' ? t[i] >= '0' && t[i] <= '9' : t[i] == pat[i];
        if (!ok)
            return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1,
                             "timestamp '%.40s' is not YYYY-MM-DDThh:mm:ss", t);
    }
    return CCN_OK;
}

/* ---- G1 deviation ------------------------------------------------------------------- */

/* Side parameter range [lo, hi] of segment k of side s of face f (running order). */
static void seg_range(const ccn__cad_model *m, int32_t f, int s, int32_t k, double *a, double *b) {
    double lo, hi;
    ccn__cad_domain(&m->faces[f], s % 2, &lo, &hi);
    int32_t b0 = m->side_breaks_start[4 * f + s], b1 = m->side_breaks_start[4 * f + s + 1];
    double start = s < 2 ? lo : hi, end = s < 2 ? hi : lo;
    *a = k == 0 ? start : m->side_breaks[b0 + k - 1];
    *b = b0 + k == b1 ? end : m->side_breaks[b0 + k];
}

static void side_uv(const ccn__cad_surface *F, int s, double t, double *u, double *v) {
    double u0, u1, v0, v1;
    ccn__cad_domain(F, 0, &u0, &u1);
    ccn__cad_domain(F, 1, &v0, &v1);
    *u = s == 0 || s == 2 ? t : s == 1 ? u1 : u0;
    *v = s == 1 || s == 3 ? t : s == 0 ? v0 : v1;
}

static double normal_angle(const ccn__cad_surface *A, double ua, double va, const ccn__cad_surface *B,
                           double ub, double vb) {
    double p[3], du[3], dv[3], na[3], nb[3], c[3];
    ccn__cad_eval_d(A, ua, va, p, du, dv);
    ccn__cross3(du, dv, na);
    ccn__cad_eval_d(B, ub, vb, p, du, dv);
    ccn__cross3(du, dv, nb);
    ccn__cross3(na, nb, c);
    double s = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    double d = na[0] * nb[0] + na[1] * nb[1] + na[2] * nb[2];
    return atan2(s, d);
}

/* Segment index -> (face, side, k). */
typedef struct { int32_t face; int side; int32_t k; } seg_of;

static void g1_deviation(const ccn__cad_model *m, const ccn__xmodel *xm, const seg_of *so,
                         const uint8_t *crease, int32_t ns, ccn_export_info *inf) {
    double *all = &inf->max_g1_deviation, *fill = &inf->max_fill_g1_deviation;
    *all = *fill = 0;
    for (int32_t j = 0; j < ns; j++) {
        int32_t q = m->adjacency[j];
        if (q < j) continue;
        const ccn__cad_surface *A = &m->faces[so[j].face], *B = &m->faces[so[q].face];
        double a0, a1, b0, b1;
        seg_range(m, so[j].face, so[j].side, so[j].k, &a0, &a1);
        seg_range(m, so[q].face, so[q].side, so[q].k, &b0, &b1);
        double mx = 0;
        for (int i = 0; i < 8; i++) {
            double w = (i + 0.5) / 8, ua, va, ub, vb;
            side_uv(A, so[j].side, a0 + w * (a1 - a0), &ua, &va);
            side_uv(B, so[q].side, b1 + w * (b0 - b1), &ub, &vb);
            double ang = normal_angle(A, ua, va, B, ub, vb);
            if (!(ang <= mx)) mx = ang; /* NaN (a degenerate normal) counts as the worst */
        }
        if (crease[j]) { /* a C0 edge: its angle, apart */
            double mn = INFINITY;
            for (int i = 0; i < 8; i++) {
                double w = (i + 0.5) / 8, ua, va, ub, vb;
                side_uv(A, so[j].side, a0 + w * (a1 - a0), &ua, &va);
                side_uv(B, so[q].side, b1 + w * (b0 - b1), &ub, &vb);
                mn = fmin(mn, normal_angle(A, ua, va, B, ub, vb));
            }
            if (!inf->num_crease_edges++ || mn < inf->min_crease_angle) inf->min_crease_angle = mn;
            if (!(mx <= inf->max_crease_angle)) inf->max_crease_angle = mx;
            continue;
        }
        int isfill = xm->faces[so[j].face].kind == CCN_EXPORT_FACE_FILL ||
                     xm->faces[so[q].face].kind == CCN_EXPORT_FACE_FILL;
        double *dst = isfill ? fill : all;
        if (!(mx <= *dst)) *dst = mx;
    }
}

static int32_t uf_find(int32_t *p, int32_t x) {
    while (p[x] != x) x = p[x] = p[p[x]];
    return x;
}

/* The faces grouped by connected component (stably, components in the order of their first
 * face), from the topology's side breaks bs and adjacency adj: the writers put each component
 * in a shell of its own, and a reader meets the faces shell by shell, so this makes the file's
 * face order (face_fn's) the order a reader sees. 1: reordered (the topology is to be rebuilt),
 * 0: already in order, -1: out of memory. */
static int order_by_shell(ccn__xmodel *xm, const int32_t *bs, const int32_t *adj) {
    int32_t nf = xm->num_faces;
    int32_t *uf = malloc(sizeof(int32_t) * (size_t)nf), *segf = malloc(sizeof(int32_t) * (size_t)(4 * nf + bs[4 * nf]));
    int32_t *comp = malloc(sizeof(int32_t) * (size_t)nf), *count = calloc((size_t)nf + 1, sizeof(int32_t));
    ccn__xface *sorted = malloc(sizeof(ccn__xface) * (size_t)nf);
    int r = -1;
    if (!uf || !segf || !comp || !count || !sorted) goto done;
    for (int32_t f = 0; f < nf; f++) {
        uf[f] = f, comp[f] = -1;
        for (int32_t j = 4 * f + bs[4 * f]; j < 4 * (f + 1) + bs[4 * (f + 1)]; j++) segf[j] = f;
    }
    for (int32_t j = 0; j < 4 * nf + bs[4 * nf]; j++) {
        if (adj[j] < 0) continue;
        int32_t a = uf_find(uf, segf[j]), b = uf_find(uf, segf[adj[j]]);
        if (a != b) uf[a < b ? b : a] = a < b ? a : b;
    }
    int32_t nc = 0, sorted_already = 1;
    for (int32_t f = 0; f < nf; f++) {
        int32_t r = uf_find(uf, f);
        if (comp[r] < 0) comp[r] = nc++;
        comp[f] = comp[r];
        sorted_already &= f == 0 || comp[f] >= comp[f - 1];
    }
    if (!sorted_already) {
        for (int32_t f = 0; f < nf; f++) count[comp[f] + 1]++;
        for (int32_t c = 0; c < nc; c++) count[c + 1] += count[c];
        for (int32_t f = 0; f < nf; f++) sorted[count[comp[f]]++] = xm->faces[f];
        memcpy(xm->faces, sorted, sizeof(ccn__xface) * (size_t)nf);
    }
    r = !sorted_already;
done:
    free(uf); free(segf); free(comp); free(count); free(sorted);
    return r;
}

/* ---- output ------------------------------------------------------------------------ */

typedef struct {
    ccn_write_fn fn;
    void *user;
    int64_t bytes, estimate;
    ccn_progress_fn progress;
    void *puser;
    double next;
} sink;

static int sink_write(void *user, const char *data, size_t len) {
    sink *s = user;
    s->bytes += (int64_t)len;
    if (s->progress && s->estimate > 0) {
        double f = 0.7 + 0.3 * fmin(1.0, (double)s->bytes / (double)s->estimate);
        if (f >= s->next) { s->progress(s->puser, f); s->next = f + 0.01; }
    }
    return s->fn(s->user, data, len);
}

static void progress(const ccn_export_options *o, double f) {
    if (o->progress) o->progress(o->progress_user, f);
}

static void face_map(const ccn_export_options *o, const ccn__xmodel *xm) {
    ccn_export_cell *cells = NULL;
    int32_t cap = 0;
    for (int32_t f = 0; f < xm->num_faces; f++) {
        const ccn__xface *X = &xm->faces[f];
        int32_t nc = X->cells_u * X->cells_v;
        if (nc > cap) {
            ccn_export_cell *c = realloc(cells, sizeof *c * (size_t)nc);
            if (!c) break; /* the map is optional output: stop rather than fail the export */
            cells = c;
            cap = nc;
        }
        for (int32_t i = 0; i < nc; i++) {
            const ccn__xcell *x = &xm->cells[X->cell0 + i];
            cells[i].cage_face = x->pl.cage_face;
            cells[i].sub = x->pl.sub;
            memcpy(cells[i].uv, x->uv, sizeof cells[i].uv);
            memcpy(cells[i].st, x->pl.p, sizeof cells[i].st);
        }
        ccn_export_face ef;
        memset(&ef, 0, sizeof ef);
        ef.index = f;
        ef.kind = X->kind;
        ef.patch = X->patch;
        ef.num_cells = nc;
        ef.cells = cells;
        for (int d = 0; d < 2; d++) {
            ef.degree[d] = X->s.degree[d];
            ef.num_poles[d] = X->s.num_poles[d];
            ef.num_knots[d] = X->s.num_knots[d];
            ef.periodic[d] = X->s.periodic[d];
            ef.knots[d] = X->s.knots[d];
            ef.mults[d] = X->s.mults[d];
        }
        ef.poles = X->s.poles;
        o->face_fn(o->face_user, &ef);
    }
    free(cells);
}

/* ---- the export -------------------------------------------------------------------- */

/* Knots the surface does not need are removed while each face moves by at most this much of
 * its own size (io/knot_removal.c): far below the 1e-12 of the model's size the export keeps to
 * the limit. */
#define KNOT_TOLERANCE 1e-13
/* Faces are merged where their union is C1 to this much of their size (io/face_merge.c: far
 * from both the unions that are C1, which miss by 3e-12 at most, and those that are not). */
#define MERGE_TOLERANCE 1e-10

static ccn_status build_faces(ccn__xmodel *xm, const ccn__plan_view *v, const rec_list *rl,
                              const ccn_export_options *o, ccn_export_info *inf, ccn_error *err) {
    const ccn_mesh *cage = v->lev[0];
    int32_t lvl = v->patch_level;
    int packed = !(o->flags & CCN_EXPORT_UNPACKED);
    ccn_status st = CCN_OK;
    uint8_t *ok0 = calloc((size_t)cage->nf + 1, 1);
    int32_t *cage_of = malloc(sizeof(int32_t) * (rl->n + 1));
    uint8_t *drop = calloc(rl->n + 1, 1);
    uint8_t *okl = calloc((size_t)v->lev[lvl]->nf + 1, 1);
    int32_t *rec_of = malloc(sizeof(int32_t) * ((size_t)v->lev[lvl]->nf + 1));
    int32_t *holes = malloc(sizeof(int32_t) * (2 * rl->n + 1));
    ccn__pack *pk = NULL;
    int32_t npk = 0;
    if (!ok0 || !cage_of || !drop || !okl || !rec_of || !holes) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (export)");
        goto done;
    }
    /* level-0 packs of regular cage quads */
    for (int32_t f = 0; f < cage->nf; f++) ok0[f] = (uint8_t)ccn__packable(cage, f, v->pinned);
    if ((st = ccn__packs_find(cage, ok0, !packed, &pk, &npk, err))) goto done;
    place_ctx pc0 = {v->lev, 0};
    for (int32_t k = 0; k < npk; k++) {
        if (ccn__pack_face(xm, cage, &pk[k], v->pinned, v->centre, v->scale, CCN_EXPORT_FACE_PACK,
                           place_level, &pc0) < 0) goto oom;
        inf->num_packed_cage_faces += pk[k].a * pk[k].b;
    }
    ccn__packs_free(pk, npk);
    pk = NULL;
    for (size_t i = 0; i < rl->n; i++) {
        ccn__xplace q;
        ccn__xplace_of(v->lev, rl->r[i].pl.level, rl->r[i].pl.face, &q);
        cage_of[i] = q.cage_face;
        drop[i] = ok0[q.cage_face];
    }
    /* packs of the strict patch-level faces left */
    const ccn_mesh *ml = v->lev[lvl];
    for (int32_t f = 0; f < ml->nf; f++) rec_of[f] = -1;
    for (size_t i = 0; i < rl->n; i++)
        if (!drop[i] && rl->r[i].pl.kind == CCN__PATCH_STRICT && rl->r[i].pl.level == lvl) {
            okl[rl->r[i].pl.face] = (uint8_t)packed;
            rec_of[rl->r[i].pl.face] = (int32_t)i;
        }
    if (packed && lvl > 0) {
        if ((st = ccn__packs_find(ml, okl, 0, &pk, &npk, err))) goto done;
        place_ctx pcl = {v->lev, lvl};
        for (int32_t k = 0; k < npk; k++) {
            if (pk[k].a * pk[k].b == 1) { /* a single face: its Bezier patch, not a pack */
                okl[ml->hface[pk[k].cells[0]]] = 0;
                continue;
            }
            if (ccn__pack_face(xm, ml, &pk[k], v->pinned, v->centre, v->scale, CCN_EXPORT_FACE_PACK,
                               place_level, &pcl) < 0) goto oom;
        }
        for (int32_t f = 0; f < ml->nf; f++)
            if (okl[f] && rec_of[f] >= 0) drop[rec_of[f]] = 1;
    }
    /* the plan's other patches; holes by level (the patch level, or one finer around an
     * exact-surround cap) */
    int32_t nh[2] = {0, 0};
    for (size_t i = 0; i < rl->n; i++) {
        const rec *r = &rl->r[i];
        if (drop[i]) continue;
        if (r->pl.kind == CCN__PATCH_HOLE) {
            int k = r->pl.level != lvl;
            holes[k * rl->n + nh[k]++] = r->pl.face;
            continue;
        }
        ccn__xplace q, s;
        ccn__xplace_of(v->lev, r->pl.level, r->pl.face, &q);
        ccn__xplace_sub(&q, (const double(*)[2])r->pl.rect, &s);
        int32_t kind = r->pl.degree == 5 ? CCN_EXPORT_FACE_BI5 : CCN_EXPORT_FACE_BICUBIC;
        int32_t f = ccn__xm_add_bezier(xm, kind, r->pl.degree, rl->pts + r->off, &s);
        if (f < 0) goto oom;
        xm->faces[f].patch = r->pl.index;
    }
    progress(o, 0.3);
    for (int k = 0; k < 2; k++) {
        if (!nh[k]) continue;
        ccn__fill_opts fo = {o->fill_levels ? o->fill_levels : CCN_EXPORT_DEFAULT_FILL_LEVELS, packed, 0, -1};
        if ((st = ccn__fill_holes(xm, v, lvl + k, holes + k * rl->n, nh[k], &fo, err))) goto done;
        inf->num_fills += fo.num_fills;
        if (fo.fill_level > inf->fill_level) inf->fill_level = fo.fill_level;
    }
    if (xm->oom) goto oom;
    goto done;
oom:
    st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (export faces)");
done:
    ccn__packs_free(pk, npk);
    free(ok0); free(cage_of); free(drop); free(okl); free(rec_of); free(holes);
    return st;
}

ccn_status ccn_plan_export(ccn_plan *plan, const double *positions, const ccn_export_options *opts,
                           ccn_write_fn fn, void *user, ccn_export_info *info, ccn_error *err) {
    ccn__ok(err);
    ccn_export_info inf;
    memset(&inf, 0, sizeof inf);
    inf.fill_level = -1;
    if (info) *info = inf;
    if (!plan) return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "plan is NULL");
    if (!fn) return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "write callback is NULL");
    ccn_export_options o;
    memset(&o, 0, sizeof o);
    if (opts) o = *opts;
    ccn_status st = check_opts(&o, err);
    if (st) return st;
    ccn_sizes sz;
    ccn_plan_get_sizes(plan, &sz);
    ccn_plan_stats ps;
    ccn_plan_get_stats(plan, &ps);
    if (ps.num_caps_deferred > 0) /* no caps at L <= K; fills there would be needless */
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1,
                         "the plan (output level %d) has no bi-5 caps for its %d extraordinary vertices: "
                         "none is built below the output level; export a plan with more levels (%d or more)",
                         (int)ps.levels, (int)ps.num_caps_deferred, (int)ps.levels + 1);
    ccn_limit_mesh lm = {.positions = malloc(sizeof(double) * 3 * (size_t)(sz.num_verts ? sz.num_verts : 1))};
    if (!lm.positions) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (export)");
    st = ccn_plan_evaluate(plan, positions, &lm, err);
    free(lm.positions);
    if (st) return st;
    progress(&o, 0.05);
    ccn__plan_view v;
    ccn__plan_view_get(plan, &v);
    rec_list rl;
    memset(&rl, 0, sizeof rl);
    ccn__xmodel xm;
    memset(&xm, 0, sizeof xm);
    int32_t *bs = NULL, *adj = NULL;
    double *br = NULL;
    uint8_t *crease = NULL;
    seg_of *so = NULL;
    ccn__cad_topo topo;
    memset(&topo, 0, sizeof topo);
    if ((st = ccn__plan_patches_placed(plan, collect, &rl))) {
        st = ccn__fail(err, st, CCN_ELEM_NONE, -1, "out of memory (patches)");
        goto done;
    }
    if (rl.oom) { st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (patches)"); goto done; }
    progress(&o, 0.15);
    if ((st = build_faces(&xm, &v, &rl, &o, &inf, err))) goto done;
    if (!(o.flags & CCN_EXPORT_UNPACKED)) { /* fewer faces and knots, the same surface */
        int64_t merged;
        /* equal sides first, then, with the knots no face needs removed, sides made equal */
        for (int unify = 0; unify < 2; unify++) {
            if ((st = ccn__xm_merge_faces(&xm, v.lev[0], MERGE_TOLERANCE, unify, &merged, err))) goto done;
            if (ccn__xm_remove_knots(&xm, KNOT_TOLERANCE, unify) < 0) {
                st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (knot removal)");
                goto done;
            }
        }
    }
    ccn__xm_unit_domains(&xm); /* patches on [0, 1]^2: shared pcurves */
    if (xm.num_faces == 0) {
        st = ccn__fail(err, CCN_ERR_TOPOLOGY, CCN_ELEM_NONE, -1, "the cage has no surface to export");
        goto done;
    }
    if ((st = ccn__xtopo_build(&xm, v.lev[0], &bs, &br, &adj, &crease, err))) goto done;
    int reordered = order_by_shell(&xm, bs, adj);
    if (reordered < 0) { st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (export shells)"); goto done; }
    if (reordered) { /* the sides' numbering follows the faces */
        free(bs); free(br); free(adj); free(crease);
        bs = adj = NULL, br = NULL, crease = NULL;
        if ((st = ccn__xtopo_build(&xm, v.lev[0], &bs, &br, &adj, &crease, err))) goto done;
    }
    if (o.face_fn) face_map(&o, &xm);
    progress(&o, 0.6);
    ccn__cad_surface *faces = malloc(sizeof *faces * (size_t)xm.num_faces);
    if (!faces) { st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (export)"); goto done; }
    for (int32_t f = 0; f < xm.num_faces; f++) faces[f] = xm.faces[f].s;
    ccn__cad_model m = {xm.num_faces, faces, bs, br, adj, o.name, o.timestamp, o.tolerance};
    if ((st = ccn__cad_topo_build(&m, &topo, err))) {
        /* the writer's check names its own faces; the user needs the cage's */
        if (st == CCN_ERR_TOPOLOGY && err && err->element_kind == CCN_ELEM_FACE && err->element >= 0 &&
            err->element < xm.num_faces) {
            int32_t cf = xm.cells[xm.faces[err->element].cell0].pl.cage_face;
            ccn__fail(err, st, CCN_ELEM_FACE, cf,
                      "the surface over cage face %d does not close into a B-rep: two of its pieces do not "
                      "meet along one curve, as where the surface folds onto itself (two faces back to "
                      "back); nothing written", (int)cf);
        }
        free(faces);
        goto done;
    }
    int32_t ns = topo.num_segs;
    so = malloc(sizeof *so * (size_t)ns);
    if (!so) { free(faces); st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (export)"); goto done; }
    int64_t estimate = 0;
    for (int32_t f = 0; f < xm.num_faces; f++) {
        for (int s = 0; s < 4; s++)
            for (int32_t k = 0; k <= bs[4 * f + s + 1] - bs[4 * f + s]; k++) {
                int32_t j = 4 * f + s + bs[4 * f + s] + k;
                so[j].face = f; so[j].side = s; so[j].k = k;
            }
        const ccn__xface *X = &xm.faces[f];
        inf.num_packs += X->kind == CCN_EXPORT_FACE_PACK;
        inf.num_bicubic += X->kind == CCN_EXPORT_FACE_BICUBIC;
        inf.num_bi5 += X->kind == CCN_EXPORT_FACE_BI5;
        inf.num_refined += X->kind == CCN_EXPORT_FACE_REFINED;
        inf.num_fill_faces += X->kind == CCN_EXPORT_FACE_FILL;
        estimate += 700 + 75 * (int64_t)X->s.num_poles[0] * X->s.num_poles[1];
    }
    for (int32_t j = 0; j < ns; j++) inf.num_boundary_edges += adj[j] < 0;
    inf.num_shells = topo.num_shells;
    g1_deviation(&m, &xm, so, crease, ns, &inf);
    inf.num_faces = xm.num_faces;
    inf.num_edges = topo.num_edges;
    inf.num_vertices = topo.num_verts;
    inf.closed = topo.closed;
    inf.size = topo.size;
    progress(&o, 0.7);
    sink sk = {fn, user, 0, estimate, o.progress, o.progress_user, 0.7};
    st = o.format == CCN_EXPORT_IGES ? ccn__iges_write(&m, sink_write, &sk, err)
                                     : ccn__step_write(&m, sink_write, &sk, err);
    inf.bytes = sk.bytes;
    free(faces);
    if (!st) progress(&o, 1.0);
done:
    ccn__cad_topo_free(&topo);
    ccn__xm_free(&xm);
    free(rl.r); free(rl.pts); free(bs); free(br); free(adj); free(crease); free(so);
    if (info) *info = inf;
    return st;
}
