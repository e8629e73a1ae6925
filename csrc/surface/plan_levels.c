/* The refinement levels a plan keeps: every level's topology and prepared rules. */
#include "surface/plan_levels.h"

#include "base/error.h"

/* Builds levels 1..R (topology and prepared rules); lev[0] exists. */
ccn_status ccn__plan_build_levels(ccn_plan *p, int32_t R, ccn_error *err) {
    ccn_mesh **lev = realloc(p->lev, sizeof(ccn_mesh *) * ((size_t)R + 1));
    if (lev) p->lev = lev;
    ccn__level *prep = realloc(p->prep, sizeof(ccn__level) * (size_t)(R ? R : 1));
    if (prep) p->prep = prep;
    if (!lev || !prep) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
    int pinned = p->opts.boundary_corners == CCN_CORNERS_PINNED;
    for (int32_t l = p->R; l < R; l++) {
        ccn__level *same = p->hint && p->hint->R > l ? &p->hint->prep[l] : NULL;
        ccn_status st = ccn__level_prepare_like(&p->prep[l], p->lev[l], p->opts.scheme, pinned,
                                                p->opts.crease_method, p->opts.ev_polyhedron,
                                                p->ev_cache, same, err);
        if (st) return st;
        p->prep[l].threads = p->threads;
        p->lev[l + 1] = NULL;
        p->R = l + 1; /* prep[l] is owned from here on */
        ccn_mesh *like = p->hint && p->hint->R > l ? p->hint->lev[l + 1] : NULL;
        st = ccn__level_topology_like(&p->prep[l], like, &p->lev[l + 1], err);
        if (st) { p->R = l; ccn__level_free(&p->prep[l]); return st; }
        if (like) ccn__level_tabulate_like(&p->prep[l], &p->hint->prep[l]);
    }
    return CCN_OK;
}
