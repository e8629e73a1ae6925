/* ccn_refine (public): `levels` levels of refinement of a cage, one refine/level.c step each,
 * in a unit box (ccn__normalize) so huge coordinates cannot overflow. Catmull-Clark runs on a
 * copy of the cage with every interval 1. */
#include "refine/level.h"

#include "base/error.h"
#include "base/parallel.h"
#include "topology/mesh.h"

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

ccn_status ccn_refine(const ccn_mesh *in, int32_t levels, const ccn_options *opts,
                      ccn_mesh **out, ccn_error *err) {
    ccn__ok(err);
    if (!in || !out) return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "mesh or out is NULL");
    *out = NULL;
    ccn_options o = {0};
    if (opts) o = *opts;
    if (o.crease_method < CCN_CREASE_UNIFORM || o.crease_method > CCN_CREASE_CHAIKIN)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "unknown crease_method %d",
                         (int)o.crease_method);
    if (levels < 0 || levels > 16)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1,
                         "levels must be in [0, 16], got %d", (int)levels);
    if (o.scheme < CCN_SCHEME_EIGEN || o.scheme > CCN_SCHEME_CATMULL_CLARK)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "unknown scheme %d", (int)o.scheme);
    if (o.ev_polyhedron < CCN_POLY_SELECT || o.ev_polyhedron > CCN_POLY_COUNT)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "ev_polyhedron %d outside [0, %d]",
                         (int)o.ev_polyhedron, CCN_POLY_COUNT);
    int64_t corners = in->nh; /* face corners quadruple per level: fail before any work */
    for (int32_t l = 0; l < levels; l++)
        if ((corners *= 4) > INT32_MAX / 8)
            return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1,
                             "%d levels of a %d-corner cage would exceed %d face corners",
                             (int)levels, (int)in->nh, INT32_MAX / 8);
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
