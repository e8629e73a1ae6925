/* A plan with a cache of bi-5 operators, and the plan that replaces prev after an edit:
 * ccn_plan_create with options.cache and options.previous (prev is consumed), for the tests,
 * the fuzzer and the bench, which make many of both. */
#ifndef CCN_TESTS_PLAN_WITH_H
#define CCN_TESTS_PLAN_WITH_H

#include "ccnurbs.h"

#include <stddef.h>

static inline ccn_status plan_cached(const ccn_cage *c, const ccn_options *o, ccn_cache *cache,
                                     ccn_plan **out, ccn_error *err) {
    ccn_options q = {0};
    if (o) q = *o;
    q.cache = cache, q.previous = NULL;
    return ccn_plan_create(c, &q, out, err);
}

static inline ccn_status plan_recreate(ccn_plan *prev, const ccn_cage *c, const ccn_options *o,
                                       ccn_cache *cache, ccn_plan **out, ccn_error *err) {
    ccn_options q = {0};
    if (o) q = *o;
    q.cache = cache, q.previous = prev;
    return ccn_plan_create(c, &q, out, err);
}

#endif
