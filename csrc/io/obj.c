/* OBJ reader: `v x y z`, `f a b c ...` (a, a/b, a/b/c, a//c; negative = relative), and the
 * comment statements `# knot i j d` / `# crease i j c` (1-based vertex indices of an edge)
 * that other readers ignore (DESIGN §3). Other statements are skipped. Never reads past
 * `len`; any malformed number is a CCN_ERR_IO naming the line. */
#include "ccnurbs.h"

#include "base/error.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

struct ccn_obj {
    double *pos;   int32_t nv, cap_v;
    int32_t *fsz;  int32_t nf, cap_f;
    int32_t *fv;   int32_t nfv, cap_fv;
    int32_t *ev;   int32_t cap_e;
    double *knot;  int32_t nk, cap_k;
};

static int grow(void **p, int32_t *cap, int32_t need, size_t elem) {
    if (need <= *cap) return 0;
    int64_t nc = *cap ? 2 * (int64_t)*cap : 64;
    while (nc < need) nc *= 2;
    if (nc > INT32_MAX / 4) return -1;
    void *q = realloc(*p, (size_t)nc * elem);
    if (!q) return -1;
    *p = q;
    *cap = (int32_t)nc;
    return 0;
}

typedef struct { const char *s, *end; } cursor;

static void skip_ws(cursor *c) {
    while (c->s < c->end && (*c->s == ' ' || *c->s == '\t' || *c->s == '\r')) c->s++;
}

/* Copies the next token (up to 63 chars) into buf; returns its length (0 at end of line). */
static int token(cursor *c, char *buf) {
    skip_ws(c);
    int n = 0;
    while (c->s < c->end && *c->s != ' ' && *c->s != '\t' && *c->s != '\r' && *c->s != '\n') {
        if (n < 63) buf[n] = *c->s;
        n++;
        c->s++;
    }
    if (n > 63) return -1;
    buf[n] = '\0';
    return n;
}

static int parse_double(const char *t, double *out) {
    char *e;
    errno = 0;
    double x = strtod(t, &e);
    if (e == t || *e != '\0') return -1;
    *out = x;
    return 0;
}

static int parse_int(const char *t, long *out) {
    char *e;
    errno = 0;
    long x = strtol(t, &e, 10);
    if (e == t || (*e != '\0' && *e != '/') || errno == ERANGE) return -1;
    *out = x;
    return 0;
}

static ccn_status bad(ccn_error *err, long line, const char *what) {
    return ccn__fail(err, CCN_ERR_IO, CCN_ELEM_LINE, (int32_t)(line > INT32_MAX ? -1 : line),
                     "OBJ line %ld: %s", line, what);
}

static ccn_status parse_v(ccn_obj *o, cursor *c, long line, ccn_error *err) {
    char t[64];
    if (grow((void **)&o->pos, &o->cap_v, 3 * (o->nv + 1), sizeof(double)))
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_LINE, (int32_t)line, "out of memory");
    for (int k = 0; k < 3; k++) {
        if (token(c, t) <= 0 || parse_double(t, &o->pos[3 * o->nv + k]))
            return bad(err, line, "vertex needs three numbers");
    }
    o->nv++;
    return CCN_OK;
}

static ccn_status parse_f(ccn_obj *o, cursor *c, long line, ccn_error *err) {
    char t[64];
    int32_t n = 0;
    int len;
    while ((len = token(c, t)) != 0) {
        long idx;
        if (len < 0 || parse_int(t, &idx) || idx == 0) return bad(err, line, "bad face index");
        if (idx < 0) idx = o->nv + idx + 1; /* relative index */
        if (idx < 1 || idx > INT32_MAX) return bad(err, line, "face index out of range");
        if (grow((void **)&o->fv, &o->cap_fv, o->nfv + n + 1, sizeof(int32_t)))
            return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_LINE, (int32_t)line, "out of memory");
        o->fv[o->nfv + n++] = (int32_t)(idx - 1);
    }
    if (grow((void **)&o->fsz, &o->cap_f, o->nf + 1, sizeof(int32_t)))
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_LINE, (int32_t)line, "out of memory");
    o->fsz[o->nf++] = n;
    o->nfv += n;
    return CCN_OK;
}

/* "# knot i j d" (c is after '#'); other comments are ignored. */
static ccn_status parse_comment(ccn_obj *o, cursor *c, long line, ccn_error *err) {
    char t[64];
    if (token(c, t) <= 0 || strcmp(t, "knot") != 0) return CCN_OK;
    long i, j;
    double d;
    char a[64], b[64];
    if (token(c, a) <= 0 || token(c, b) <= 0 || token(c, t) <= 0 || parse_int(a, &i) ||
        parse_int(b, &j) || parse_double(t, &d) || i < 1 || j < 1 || i > INT32_MAX || j > INT32_MAX)
        return bad(err, line, "expected '# knot i j d' with 1-based vertex indices");
    if (grow((void **)&o->knot, &o->cap_k, o->nk + 1, sizeof(double)) ||
        grow((void **)&o->ev, &o->cap_e, 2 * (o->nk + 1), sizeof(int32_t)))
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_LINE, (int32_t)line, "out of memory");
    o->ev[2 * o->nk] = (int32_t)(i - 1);
    o->ev[2 * o->nk + 1] = (int32_t)(j - 1);
    o->knot[o->nk++] = d;
    return CCN_OK;
}

static ccn_status parse_line(ccn_obj *o, cursor *c, long line, ccn_error *err) {
    char t[64];
    skip_ws(c);
    if (c->s < c->end && *c->s == '#') {
        c->s++;
        return parse_comment(o, c, line, err);
    }
    int len = token(c, t);
    if (len == 0) return CCN_OK;
    if (len < 0) return bad(err, line, "token too long");
    if (strcmp(t, "v") == 0) return parse_v(o, c, line, err);
    if (strcmp(t, "f") == 0) return parse_f(o, c, line, err);
    return CCN_OK; /* vt, vn, o, g, s, usemtl, ... */
}

ccn_status ccn_obj_parse(const char *text, size_t len, ccn_obj **out, ccn_error *err) {
    ccn__ok(err);
    if (!out || (!text && len)) return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "NULL argument");
    *out = NULL;
    ccn_obj *o = calloc(1, sizeof *o);
    if (!o) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
    const char *s = text, *end = text + len;
    long line = 0;
    while (s < end) {
        const char *nl = memchr(s, '\n', (size_t)(end - s));
        const char *le = nl ? nl : end;
        cursor c = {s, le};
        line++;
        ccn_status st = parse_line(o, &c, line, err);
        if (st) { ccn_obj_destroy(o); return st; }
        s = nl ? nl + 1 : end;
    }
    *out = o;
    return CCN_OK;
}

void ccn_obj_destroy(ccn_obj *o) {
    if (!o) return;
    free(o->pos); free(o->fsz); free(o->fv); free(o->ev); free(o->knot);
    free(o);
}

ccn_status ccn_obj_cage(const ccn_obj *o, ccn_cage *c) {
    if (!o || !c) return CCN_ERR_ARGUMENT;
    memset(c, 0, sizeof *c);
    c->num_verts = o->nv;
    c->num_faces = o->nf;
    c->num_edges = o->nk;
    c->positions = o->pos;
    c->face_sizes = o->fsz;
    c->face_verts = o->fv;
    c->edge_verts = o->nk ? o->ev : NULL;
    c->edge_knots = o->nk ? o->knot : NULL;
    return CCN_OK;
}
