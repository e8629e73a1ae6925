/* ccn_refine (public): `levels` levels of refinement of a cage, one refine/level.c step each,
 * in a unit box around the cage (ccn__normalize) so huge coordinates cannot overflow and far ones
 * keep their precision. Catmull-Clark runs on a
 * copy of the cage with every interval 1. ccn_fvar_refine: a face-varying channel through the
 * same levels (refine/fvar.c), the vertex mesh's topology refined alongside (its intervals and
 * creases are the channel's). */
#include "refine/fvar.h"
#include "refine/level.h"

#include "base/error.h"
#include "base/parallel.h"
#include "topology/mesh.h"

#include <math.h>
#include <string.h>

static ccn_status refine_level(const ccn_mesh *m, const ccn_options *o, ccn__ev_cache *cache,
                               ccn_mesh **out, ccn_error *err) {
    ccn__level c;
    ccn_status st = ccn__level_prepare_ev(&c, m, o->scheme, o->boundary_corners == CCN_CORNERS_PINNED,
                                          o->crease_method, o->ev_polyhedron, cache, err);
    int threads = ccn__thread_count(o->threads);
    if (st) return st;
    c.threads = threads;
    st = ccn__level_topology(&c, out, err);
    if (!st) ccn__level_points(&c, (*out)->pos);
    ccn__level_free(&c);
    return st;
}

static ccn_mesh *mesh_clone(const ccn_mesh *m) {
    ccn_mesh *r = ccn__mesh_alloc(m->nv, m->nf, m->nh, m->ne);
    if (!r) return NULL;
    memcpy(r->pos, m->pos, sizeof(double) * 3 * (size_t)m->nv);
    memcpy(r->fstart, m->fstart, sizeof(int32_t) * ((size_t)m->nf + 1));
    memcpy(r->hvert, m->hvert, sizeof(int32_t) * (size_t)m->nh);
    memcpy(r->htwin, m->htwin, sizeof(int32_t) * (size_t)m->nh);
    memcpy(r->hedge, m->hedge, sizeof(int32_t) * (size_t)m->nh);
    memcpy(r->hface, m->hface, sizeof(int32_t) * (size_t)m->nh);
    memcpy(r->everts, m->everts, sizeof(int32_t) * 2 * (size_t)m->ne);
    memcpy(r->eknot, m->eknot, sizeof(double) * (size_t)m->ne);
    memcpy(r->vfan_start, m->vfan_start, sizeof(int32_t) * ((size_t)m->nv + 1));
    memcpy(r->vfan, m->vfan, sizeof(int32_t) * (size_t)m->nh);
    memcpy(r->hfanpos, m->hfanpos, sizeof(int32_t) * (size_t)m->nh);
    memcpy(r->vlast_edge, m->vlast_edge, sizeof(int32_t) * (size_t)m->nv);
    memcpy(r->vboundary, m->vboundary, (size_t)m->nv);
    if (m->esharp) {
        if (ccn__mesh_alloc_sharpness(r)) { ccn_mesh_destroy(r); return NULL; }
        memcpy(r->esharp, m->esharp, sizeof(float) * (size_t)m->ne);
        memcpy(r->vsharp, m->vsharp, sizeof(float) * (size_t)m->nv);
    }
    if (m->vrep) { /* a split cage: its representatives, welded again */
        r->vrep = malloc(sizeof(int32_t) * (size_t)(m->nv ? m->nv : 1));
        if (!r->vrep) { ccn_mesh_destroy(r); return NULL; }
        memcpy(r->vrep, m->vrep, sizeof(int32_t) * (size_t)m->nv);
        if (ccn__mesh_weld(r)) { ccn_mesh_destroy(r); return NULL; }
    }
    r->knot_scale = m->knot_scale;
    r->info = m->info;
    return r;
}

/* Catmull-Clark ignores intervals: a copy of the cage with every interval 1. */
static ccn_mesh *uniform_copy(const ccn_mesh *m) {
    ccn_mesh *r = mesh_clone(m);
    if (!r) return NULL;
    for (int32_t e = 0; e < r->ne; e++) r->eknot[e] = 1.0;
    r->knot_scale = 1.0;
    return r;
}

static ccn_status check_refine(const ccn_mesh *in, int32_t levels, const ccn_options *o,
                               ccn_error *err) {
    if (o->crease_method < CCN_CREASE_UNIFORM || o->crease_method > CCN_CREASE_CHAIKIN)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "unknown crease_method %d",
                         (int)o->crease_method);
    if (levels < 0 || levels > 16)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1,
                         "levels must be in [0, 16], got %d", (int)levels);
    if (o->scheme < CCN_SCHEME_EIGEN || o->scheme > CCN_SCHEME_CATMULL_CLARK)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "unknown scheme %d", (int)o->scheme);
    if (o->ev_polyhedron < CCN_POLY_SELECT || o->ev_polyhedron > CCN_POLY_COUNT)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "ev_polyhedron %d outside [0, %d]",
                         (int)o->ev_polyhedron, CCN_POLY_COUNT);
    int64_t corners = in->nh; /* face corners quadruple per level: fail before any work */
    for (int32_t l = 0; l < levels; l++)
        if ((corners *= 4) > INT32_MAX / 8)
            return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1,
                             "%d levels of a %d-corner cage would exceed %d face corners",
                             (int)levels, (int)in->nh, INT32_MAX / 8);
    return CCN_OK;
}

ccn_status ccn_refine(const ccn_mesh *in, int32_t levels, const ccn_options *opts,
                      ccn_mesh **out, ccn_error *err) {
    ccn__ok(err);
    if (!in || !out) return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "mesh or out is NULL");
    *out = NULL;
    ccn_options o = {0};
    if (opts) o = *opts;
    ccn_status cst = check_refine(in, levels, &o, err);
    if (cst) return cst;
    ccn_mesh *cur = o.scheme == CCN_SCHEME_CATMULL_CLARK ? uniform_copy(in) : mesh_clone(in);
    if (!cur) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
    double centre[3], scale; /* unit box: huge coordinates cannot overflow */
    ccn__normalize(cur, centre, &scale);
    ccn__ev_cache *cache = ccn__ev_cache_create(); /* the levels share the polyhedron choices */
    if (!cache) { ccn_mesh_destroy(cur); return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory"); }
    for (int32_t l = 0; l < levels; l++) {
        ccn_mesh *next = NULL;
        ccn_status st = refine_level(cur, &o, cache, &next, err);
        ccn_mesh_destroy(cur);
        if (st) { ccn__ev_cache_destroy(cache); return st; }
        cur = next;
    }
    ccn__ev_cache_destroy(cache);
    ccn__denormalize(cur, centre, scale);
    *out = cur;
    return CCN_OK;
}

/* ---- face-varying channels ------------------------------------------------------------ */

struct ccn_fvar {
    ccn_mesh *m;       /* the refined value topology (faces as ccn_refine's output) */
    double *values;    /* width * m->nv */
    int32_t width, level, num_seams, num_sharp;
};

void ccn_fvar_destroy(ccn_fvar *f) {
    if (!f) return;
    ccn_mesh_destroy(f->m);
    free(f->values);
    free(f);
}

/* Values of level f (width w, chunks of 3 through the rules) into next (w * nf->nv). */
static void fvar_points(ccn__level *c, ccn_mesh *m, ccn_mesh *next, const double *vals,
                        int32_t w, double *out) {
    for (int32_t c0 = 0; c0 < w; c0 += 3) {
        for (int32_t v = 0; v < m->nv; v++)
            for (int k = 0; k < 3; k++) m->pos[3 * (size_t)v + k] = c0 + k < w ? vals[(size_t)w * v + c0 + k] : 0.0;
        ccn__level_points(c, next->pos);
        for (int32_t v = 0; v < next->nv; v++)
            for (int k = 0; k < 3 && c0 + k < w; k++) out[(size_t)w * v + c0 + k] = next->pos[3 * (size_t)v + k];
    }
}

ccn_status ccn_fvar_refine(const ccn_mesh *in, const ccn_fvar_channel *ch, int32_t levels,
                           const ccn_options *opts, ccn_fvar **out, ccn_error *err) {
    ccn__ok(err);
    if (!in || !out) return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "mesh or out is NULL");
    *out = NULL;
    ccn_options o = {0};
    if (opts) o = *opts;
    ccn_status st = check_refine(in, levels, &o, err);
    if (!st) st = ccn__fvar_check(in, ch, err);
    if (st) return st;
    int pinned = o.boundary_corners == CCN_CORNERS_PINNED, w = ch->width;
    ccn_fvar *r = calloc(1, sizeof *r);
    ccn_mesh *cur = o.scheme == CCN_SCHEME_CATMULL_CLARK ? uniform_copy(in) : mesh_clone(in);
    ccn__fvar_level fl, fn;
    memset(&fl, 0, sizeof fl);
    memset(&fn, 0, sizeof fn);
    int32_t *value_of = NULL;
    double *vals = NULL;
    ccn__ev_cache *cache = ccn__ev_cache_create(); /* the levels share the polyhedron choices */
    if (!r || !cur || !cache) { st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory"); goto done; }
    if ((st = ccn__fvar_build(cur, ch->indices, ch->linear, pinned, &fl, &value_of, err))) goto done;
    r->width = w;
    r->num_seams = fl.num_seams;
    /* an exact power-of-two scale keeps huge values finite, as the unit box does for positions */
    double big = 0.0;
    for (int64_t i = 0; i < (int64_t)w * ch->num_values; i++) big = fmax(big, fabs(ch->values[i]));
    int e = big > 0 ? ilogb(big) + 1 : 0;
    e = e < -1000 ? -1000 : e > 1000 ? 1000 : e;
    vals = malloc(sizeof(double) * (size_t)w * (size_t)fl.m->nv);
    if (!vals) { st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory"); goto done; }
    for (int32_t v = 0; v < fl.m->nv; v++)
        for (int32_t k = 0; k < w; k++)
            vals[(size_t)w * v + k] = ldexp(ch->values[(size_t)w * value_of[v] + k], -e);
    int threads = ccn__thread_count(o.threads);
    for (int32_t l = 0; l < levels && !st; l++) {
        ccn__level vc, fc;
        ccn_mesh *vnext = NULL;
        double *nv = NULL;
        if ((st = ccn__level_prepare_ev(&vc, cur, o.scheme, pinned, o.crease_method, o.ev_polyhedron,
                                        cache, err)))
            break;
        st = ccn__level_topology(&vc, &vnext, err);
        ccn__level_free(&vc);
        if (!st && !(st = ccn__fvar_prepare(&fc, &fl, o.scheme, o.crease_method, o.ev_polyhedron, cache, err))) {
            fc.threads = threads;
            st = ccn__fvar_child(&fl, &fc, cur, vnext, &fn, err);
            if (!st && !(nv = malloc(sizeof(double) * (size_t)w * (size_t)fn.m->nv)))
                st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
            if (!st) fvar_points(&fc, fl.m, fn.m, vals, w, nv);
            ccn__level_free(&fc);
        }
        ccn_mesh_destroy(cur);
        cur = vnext;
        if (st) { free(nv); break; }
        ccn__fvar_free(&fl);
        fl = fn;
        memset(&fn, 0, sizeof fn);
        free(vals);
        vals = nv;
    }
    if (st) goto done;
    for (size_t i = 0; i < (size_t)w * (size_t)fl.m->nv; i++) vals[i] = ldexp(vals[i], e);
    r->level = levels;
    r->num_sharp = ccn__fvar_num_sharp(&fl);
    r->m = fl.m;
    fl.m = NULL;
    r->values = vals;
    vals = NULL;
    *out = r;
    r = NULL;
done:
    ccn__fvar_free(&fl);
    ccn__fvar_free(&fn);
    ccn_mesh_destroy(cur);
    free(value_of);
    free(vals);
    ccn__ev_cache_destroy(cache);
    ccn_fvar_destroy(r);
    return st;
}

ccn_status ccn_fvar_get_info(const ccn_fvar *f, ccn_fvar_info *info) {
    if (!f || !info) return CCN_ERR_ARGUMENT;
    info->width = f->width;
    info->level = f->level;
    info->num_values = f->m->nv;
    info->num_face_verts = f->m->nh;
    info->num_seam_edges = f->num_seams;
    info->num_sharp_values = f->num_sharp;
    return CCN_OK;
}

ccn_status ccn_fvar_copy(const ccn_fvar *f, double *values, int32_t *face_values) {
    if (!f) return CCN_ERR_ARGUMENT;
    if (values) memcpy(values, f->values, sizeof(double) * (size_t)f->width * (size_t)f->m->nv);
    if (face_values) memcpy(face_values, f->m->hvert, sizeof(int32_t) * (size_t)f->m->nh);
    return CCN_OK;
}
