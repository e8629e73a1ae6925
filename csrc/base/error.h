/* Status reporting shared by every layer (internal): ccn__fail fills a ccn_error (which may be
 * NULL) and returns the status, ccn__ok clears it. */
#ifndef CCN_BASE_ERROR_H
#define CCN_BASE_ERROR_H

#include "ccnurbs.h"

/* ccn__because(err, CCN_REASON_X, ccn__fail(err, ...)): the failure's reason (ccn__fail sets
 * CCN_REASON_OTHER, or CCN_REASON_OUT_OF_MEMORY for CCN_ERR_MEMORY). */
ccn_status ccn__because(ccn_error *err, ccn_reason reason, ccn_status st);
ccn_status ccn__fail(ccn_error *err, ccn_status st, int32_t kind, int32_t element,
                     const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;
void ccn__ok(ccn_error *err);

#endif
