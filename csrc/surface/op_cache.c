/* ccn_cache: the guided bi-5 operators (one per valence and ring-speed set, bi5/bi5.h) kept
 * across plans (creating the valence-32 operator is ~0.4 s of every rebuild of a
 * cage with a 32-gon). Operators are immutable once built, so plans share them; a mutex
 * guards the table, so plans may be created with one cache from several threads. */
#include "surface/op_cache.h"

#include "base/error.h"
#include "bi5/bi5.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>

struct ccn_cache {
    pthread_mutex_t mu;
    struct ccn__bi5 **ops;
    int32_t *key;
    int32_t n, cap;
};

ccn_status ccn_cache_create(ccn_cache **out, ccn_error *err) {
    ccn__ok(err);
    if (!out) return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "out is NULL");
    *out = calloc(1, sizeof **out);
    if (!*out) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
    if (pthread_mutex_init(&(*out)->mu, NULL)) {
        free(*out);
        *out = NULL;
        return ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_NONE, -1, "cannot create the cache's mutex");
    }
    return CCN_OK;
}

void ccn_cache_destroy(ccn_cache *c) {
    if (!c) return;
    for (int32_t i = 0; i < c->n; i++) ccn__bi5_destroy(c->ops[i]);
    free(c->ops); free(c->key);
    pthread_mutex_destroy(&c->mu);
    free(c);
}

const struct ccn__bi5 *ccn__cache_op(ccn_cache *c, int32_t key, int32_t n, const double *sig,
                                     int32_t nsig, ccn_error *err) {
    const struct ccn__bi5 *op = NULL;
    pthread_mutex_lock(&c->mu);
    for (int32_t i = 0; i < c->n && !op; i++)
        if (c->key[i] == key) op = c->ops[i];
    if (!op && c->n == c->cap) {
        int32_t cap = c->cap ? 2 * c->cap : 8;
        struct ccn__bi5 **ops = realloc(c->ops, sizeof(*ops) * (size_t)cap);
        if (ops) c->ops = ops;
        int32_t *k = realloc(c->key, sizeof(int32_t) * (size_t)cap);
        if (k) c->key = k;
        if (ops && k) c->cap = cap;
    }
    /* built under the lock: a second plan asking for the same valence waits for it */
    if (!op && c->n < c->cap && ccn__bi5_create(n, sig, nsig, &c->ops[c->n], err) == CCN_OK) {
        c->key[c->n] = key;
        op = c->ops[c->n++];
    }
    pthread_mutex_unlock(&c->mu);
    return op;
}
