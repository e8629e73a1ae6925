/* Status reporting: every fallible call fills a ccn_error (which may be NULL). */
#include "base/error.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

ccn_status ccn__fail(ccn_error *err, ccn_status st, int32_t kind, int32_t element,
                     const char *fmt, ...) {
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->message, sizeof err->message, fmt, ap);
        va_end(ap);
        err->status = st;
        err->element_kind = kind;
        err->element = element;
        err->reason = st == CCN_OK ? CCN_REASON_NONE
                    : st == CCN_ERR_MEMORY ? CCN_REASON_OUT_OF_MEMORY : CCN_REASON_OTHER;
        err->element_verts[0] = err->element_verts[1] = -1;
    }
    return st;
}

ccn_status ccn__because(ccn_error *err, ccn_reason reason, ccn_status st) {
    if (err) err->reason = (int32_t)reason;
    return st;
}

void ccn__ok(ccn_error *err) {
    if (err) {
        err->status = CCN_OK;
        err->element_kind = CCN_ELEM_NONE;
        err->element = -1;
        err->message[0] = '\0';
        err->reason = CCN_REASON_NONE;
        err->element_verts[0] = err->element_verts[1] = -1;
    }
}

const char *ccn_status_name(ccn_status s) {
    switch (s) {
    case CCN_OK: return "ok";
    case CCN_ERR_ARGUMENT: return "argument error";
    case CCN_ERR_TOPOLOGY: return "topology error";
    case CCN_ERR_KNOTS: return "knot interval error";
    case CCN_ERR_MEMORY: return "out of memory";
    case CCN_ERR_INTERNAL: return "internal error";
    case CCN_ERR_IO: return "input/output error";
    }
    return "unknown status";
}
