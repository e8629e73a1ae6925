/* OBJ reader: `v x y z`, `vt u [v [w]]`, `f a b c ...` (a, a/b, a/b/c, a//c; negative =
 * relative; the texture index b of every corner makes the UV map, ccn_obj_get_fvar), the
 * comment statements `# knot i j d`, `# crease i j s`, `# corner i s` (1-based vertex indices;
 * other readers skip them), and OpenSubdiv's shape tags `t name nints/nfloats/nstrings ...`
 * (regression/common/shape_utils.cpp: crease, corner with 0-based indices, interpolateboundary,
 * creasemethod, facevaryinginterpolateboundary; other tags are skipped with a warning).
 * A `# crease`/`# corner` comment whose next word is not an integer is prose (OpenSubdiv's
 * shapes say "#  crease tags for perimeter:") and is skipped. Other statements are skipped.
 * A backslash at the end of a line continues the statement on the next (errors name the
 * statement's first line). Never reads past `len`; any malformed number is a CCN_ERR_IO naming
 * the line. */
#include "ccnurbs.h"

#include "base/error.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define OBJ_MAX_WARNINGS 16

struct ccn_obj {
    double *pos;   int32_t nv, cap_v;
    int32_t *fsz;  int32_t nf, cap_f;
    int32_t *fv;   int32_t nfv, cap_fv;
    /* per-edge statements, in file order: knot (0 = none) and sharpness (0 = none) */
    int32_t *ev;   int32_t cap_e;
    double *knot;  int32_t nk, cap_k;
    double *crease; int32_t cap_c;
    int has_crease;
    /* "# corner" statements in file order (vertex, sharpness): stored as given so that a
     * large index costs nothing before the vertex count is known; expanded to vcrease (one
     * value per vertex, 0 = none) once the file is read */
    int32_t *ci;   int32_t nci, cap_ci;
    double *cs;    int32_t cap_cs;
    double *vcrease; int32_t nvc;
    /* UV map: vt values (3 per line, padded with 0), the texture index of each face corner
     * (-1: none), the most components a vt line had, the largest index used and its line */
    double *vt;    int32_t nvt, cap_vt, vt_width;
    int32_t *fvt;  int32_t cap_fvt, nfvt_missing;
    int32_t vt_max; long vt_max_line;
    int fvar_ok;   /* every corner has a texture index and there are vt lines */
    ccn_obj_tags tags;
    int32_t nwarn;
    char warn[OBJ_MAX_WARNINGS][128];
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

/* A backslash ending a physical line continues the statement on the next one (the OBJ
 * format's line continuation): the backslash, its '\r' and '\n' count as white space. */
static int continuation(const cursor *c) {
    const char *p = c->s;
    if (p >= c->end || *p != '\\') return 0;
    p++;
    if (p < c->end && *p == '\r') p++;
    return p < c->end && *p == '\n' ? (int)(p + 1 - c->s) : 0;
}

static void skip_ws(cursor *c) {
    for (;;) {
        int k;
        if (c->s < c->end && (*c->s == ' ' || *c->s == '\t' || *c->s == '\r')) c->s++;
        else if ((k = continuation(c)) > 0) c->s += k;
        else return;
    }
}

/* Copies the next token (up to 63 chars) into buf; returns its length (0 at end of line). */
static int token(cursor *c, char *buf) {
    skip_ws(c);
    int n = 0;
    while (c->s < c->end && *c->s != ' ' && *c->s != '\t' && *c->s != '\r' && *c->s != '\n' &&
           !continuation(c)) {
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

static ccn_status parse_vt(ccn_obj *o, cursor *c, long line, ccn_error *err) {
    char t[64];
    if (grow((void **)&o->vt, &o->cap_vt, 3 * (o->nvt + 1), sizeof(double)))
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_LINE, (int32_t)line, "out of memory");
    int k = 0, len;
    for (; k < 3 && (len = token(c, t)) > 0; k++)
        if (parse_double(t, &o->vt[3 * o->nvt + k]) || !isfinite(o->vt[3 * o->nvt + k]))
            return bad(err, line, "texture coordinate needs finite numbers");
    if (k == 0) return bad(err, line, "texture coordinate needs a number");
    for (int j = k; j < 3; j++) o->vt[3 * o->nvt + j] = 0.0;
    if (k > o->vt_width) o->vt_width = k;
    o->nvt++;
    return CCN_OK;
}

/* Texture index of a face token "a/b[/c]": 0-based, -1 when there is none. */
static ccn_status texture_index(ccn_obj *o, const char *t, long line, int32_t *out, ccn_error *err) {
    const char *s = strchr(t, '/');
    *out = -1;
    if (!s || s[1] == '/' || s[1] == '\0') return CCN_OK;
    char *e;
    errno = 0;
    long b = strtol(s + 1, &e, 10);
    if (e == s + 1 || (*e != '\0' && *e != '/') || errno == ERANGE || b == 0)
        return bad(err, line, "bad texture index");
    if (b < 0) b = o->nvt + b + 1; /* relative index */
    if (b < 1 || b > INT32_MAX) return bad(err, line, "texture index out of range");
    *out = (int32_t)(b - 1);
    if (*out > o->vt_max) { o->vt_max = *out; o->vt_max_line = line; }
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
        if (grow((void **)&o->fv, &o->cap_fv, o->nfv + n + 1, sizeof(int32_t)) ||
            grow((void **)&o->fvt, &o->cap_fvt, o->nfv + n + 1, sizeof(int32_t)))
            return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_LINE, (int32_t)line, "out of memory");
        ccn_status st = texture_index(o, t, line, &o->fvt[o->nfv + n], err);
        if (st) return st;
        o->nfvt_missing += o->fvt[o->nfv + n] < 0;
        o->fv[o->nfv + n++] = (int32_t)(idx - 1);
    }
    if (grow((void **)&o->fsz, &o->cap_f, o->nf + 1, sizeof(int32_t)))
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_LINE, (int32_t)line, "out of memory");
    o->fsz[o->nf++] = n;
    o->nfv += n;
    return CCN_OK;
}

static ccn_status no_memory(ccn_error *err, long line) {
    return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_LINE, (int32_t)line, "out of memory");
}

/* Appends an edge statement (0-based vertices a, b). */
static ccn_status add_edge(ccn_obj *o, long a, long b, double knot, double crease, long line,
                           ccn_error *err) {
    if (grow((void **)&o->knot, &o->cap_k, o->nk + 1, sizeof(double)) ||
        grow((void **)&o->crease, &o->cap_c, o->nk + 1, sizeof(double)) ||
        grow((void **)&o->ev, &o->cap_e, 2 * (o->nk + 1), sizeof(int32_t)))
        return no_memory(err, line);
    o->ev[2 * o->nk] = (int32_t)a;
    o->ev[2 * o->nk + 1] = (int32_t)b;
    o->knot[o->nk] = knot;
    o->crease[o->nk] = crease;
    o->nk++;
    if (crease != 0.0) o->has_crease = 1;
    return CCN_OK;
}

/* Vertex a (0-based) gets sharpness s. */
static ccn_status add_corner(ccn_obj *o, long a, double s, long line, ccn_error *err) {
    if (grow((void **)&o->ci, &o->cap_ci, o->nci + 1, sizeof(int32_t)) ||
        grow((void **)&o->cs, &o->cap_cs, o->nci + 1, sizeof(double)))
        return no_memory(err, line);
    o->ci[o->nci] = (int32_t)a;
    o->cs[o->nci] = s;
    o->nci++;
    return CCN_OK;
}

static void warn(ccn_obj *o, long line, const char *what, const char *name) {
    if (o->nwarn < OBJ_MAX_WARNINGS)
        snprintf(o->warn[o->nwarn], sizeof o->warn[0], "OBJ line %ld: %s '%s' ignored", line, what, name);
    o->nwarn++;
}

static int is_index(const char *t, long *out) {
    char *e;
    errno = 0;
    long x = strtol(t, &e, 10);
    if (e == t || *e != '\0' || errno == ERANGE) return 0;
    *out = x;
    return 1;
}

/* "# knot i j d", "# crease i j s", "# corner i s" (c is after '#'); other comments are
 * ignored. */
static ccn_status parse_comment(ccn_obj *o, cursor *c, long line, ccn_error *err) {
    char t[64], a[64], b[64];
    if (token(c, t) <= 0) return CCN_OK;
    int knot = strcmp(t, "knot") == 0, crease = strcmp(t, "crease") == 0;
    int corner = strcmp(t, "corner") == 0;
    if (!knot && !crease && !corner) return CCN_OK;
    long i, j = 0;
    double d;
    int na = token(c, a);
    if ((crease || corner) && (na <= 0 || !is_index(a, &i))) return CCN_OK; /* prose */
    if (corner) {
        if (token(c, t) <= 0 || parse_double(t, &d) || i < 1 || i > INT32_MAX / 4)
            return bad(err, line, "expected '# corner i s' with a 1-based vertex index");
        return add_corner(o, i - 1, d, line, err);
    }
    if (na <= 0 || token(c, b) <= 0 || token(c, t) <= 0 || parse_int(a, &i) ||
        parse_int(b, &j) || parse_double(t, &d) || i < 1 || j < 1 || i > INT32_MAX || j > INT32_MAX)
        return bad(err, line, knot ? "expected '# knot i j d' with 1-based vertex indices"
                                   : "expected '# crease i j s' with 1-based vertex indices");
    return add_edge(o, i - 1, j - 1, knot ? d : 0.0, knot ? 0.0 : d, line, err);
}

#define TAG_MAX_VALUES 4096

/* OpenSubdiv's `t name nints/nfloats/nstrings ints floats strings` (c is after "t"). */
static ccn_status parse_tag(ccn_obj *o, cursor *c, long line, ccn_error *err) {
    char name[64], cnt[64], t[64];
    long n[3];
    if (token(c, name) <= 0 || token(c, cnt) <= 0) return bad(err, line, "tag needs a name and nints/nfloats/nstrings");
    {
        char *p = cnt, *e;
        for (int k = 0; k < 3; k++) {
            errno = 0;
            n[k] = strtol(p, &e, 10);
            if (e == p || n[k] < 0 || n[k] > TAG_MAX_VALUES || errno || (k < 2 ? *e != '/' : *e != '\0'))
                return bad(err, line, "tag counts must be nints/nfloats/nstrings");
            p = e + 1;
        }
    }
    int known = !strcmp(name, "crease") || !strcmp(name, "corner") || !strcmp(name, "interpolateboundary") ||
                !strcmp(name, "creasemethod") || !strcmp(name, "facevaryinginterpolateboundary");
    if (!known) { warn(o, line, "unsupported tag", name); return CCN_OK; }
    long *ints = malloc(sizeof(long) * (size_t)(n[0] + 1));
    double *fl = malloc(sizeof(double) * (size_t)(n[1] + 1));
    char str[64] = "";
    ccn_status st = CCN_OK;
    if (!ints || !fl) { st = no_memory(err, line); goto done; }
    for (long k = 0; k < n[0] && !st; k++)
        if (token(c, t) <= 0 || !is_index(t, &ints[k])) st = bad(err, line, "tag integer expected");
    for (long k = 0; k < n[1] && !st; k++)
        if (token(c, t) <= 0 || parse_double(t, &fl[k])) st = bad(err, line, "tag number expected");
    for (long k = 0; k < n[2] && !st; k++)
        if (token(c, t) <= 0) st = bad(err, line, "tag string expected");
        else if (k == 0) memcpy(str, t, sizeof str);
    if (!st && token(c, t) != 0) st = bad(err, line, "tag has extra values");
    if (st) goto done;
    if (!strcmp(name, "crease")) {
        long pairs = n[0] / 2;
        if (n[0] < 2 || n[0] % 2 || !(n[1] == 1 || n[1] == pairs)) {
            st = bad(err, line, "crease tag needs vertex pairs and one sharpness or one per pair");
            goto done;
        }
        for (long k = 0; k < pairs && !st; k++) {
            long a = ints[2 * k], b = ints[2 * k + 1];
            if (a < 0 || b < 0 || a >= INT32_MAX || b >= INT32_MAX) { st = bad(err, line, "bad crease vertex"); break; }
            double sh = fl[n[1] == 1 ? 0 : k];
            st = add_edge(o, a, b, 0.0, sh > 0 ? sh : 0.0, line, err);
        }
    } else if (!strcmp(name, "corner")) {
        if (n[0] < 1 || !(n[1] == 1 || n[1] == n[0])) {
            st = bad(err, line, "corner tag needs vertices and one sharpness or one per vertex");
            goto done;
        }
        for (long k = 0; k < n[0] && !st; k++) {
            if (ints[k] < 0 || ints[k] >= INT32_MAX / 4) { st = bad(err, line, "bad corner vertex"); break; }
            double sh = fl[n[1] == 1 ? 0 : k];
            st = add_corner(o, ints[k], sh > 0 ? sh : 0.0, line, err);
        }
    } else if (!strcmp(name, "interpolateboundary")) {
        if (n[0] != 1 || ints[0] < 0 || ints[0] > 2) { st = bad(err, line, "interpolateboundary needs one integer 0..2"); goto done; }
        o->tags.boundary_corners = ints[0] == 1 ? CCN_CORNERS_PINNED : CCN_CORNERS_SMOOTH;
        o->tags.boundary_none = ints[0] == 0;
    } else if (!strcmp(name, "facevaryinginterpolateboundary")) {
        if (n[0] != 1 || ints[0] < 0 || ints[0] > 5) { st = bad(err, line, "facevaryinginterpolateboundary needs one integer 0..5"); goto done; }
        o->tags.fvar_boundary = (int32_t)ints[0];
    } else { /* creasemethod */
        if (n[2] != 1 || (strcmp(str, "normal") && strcmp(str, "uniform") && strcmp(str, "chaikin"))) {
            st = bad(err, line, "creasemethod needs one string: normal (or uniform) or chaikin");
            goto done;
        }
        o->tags.crease_method = strcmp(str, "chaikin") ? CCN_CREASE_UNIFORM : CCN_CREASE_CHAIKIN;
    }
done:
    free(ints);
    free(fl);
    return st;
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
    if (strcmp(t, "vt") == 0) return parse_vt(o, c, line, err);
    if (strcmp(t, "t") == 0) return parse_tag(o, c, line, err);
    return CCN_OK; /* vn, o, g, s, usemtl, ... */
}

/* The UV map is used when there are vt lines and every face corner has a texture index; an
 * index beyond the vt lines is an error naming its line, a partial map a warning. */
static ccn_status finish_uvs(ccn_obj *o, ccn_error *err) {
    int any = o->nfv > o->nfvt_missing;
    if (o->nvt > 0 && any && o->vt_max >= o->nvt)
        return ccn__fail(err, CCN_ERR_IO, CCN_ELEM_LINE, (int32_t)(o->vt_max_line > INT32_MAX ? -1 : o->vt_max_line),
                         "OBJ line %ld: texture index %d, but the file has %d vt lines",
                         o->vt_max_line, (int)o->vt_max + 1, (int)o->nvt);
    o->fvar_ok = o->nvt > 0 && o->nfv > 0 && o->nfvt_missing == 0;
    if ((o->nvt > 0 || any) && !o->fvar_ok && o->nwarn < OBJ_MAX_WARNINGS)
        snprintf(o->warn[o->nwarn], sizeof o->warn[0], "UV map ignored: %s",
                 o->nvt == 0 ? "texture indices but no vt lines"
                 : any ? "some face corners have no texture index" : "no face uses the vt lines");
    if ((o->nvt > 0 || any) && !o->fvar_ok) o->nwarn++;
    if (o->fvar_ok) /* pack to vt_width components */
        for (int32_t i = 0; i < o->nvt; i++)
            for (int32_t k = 0; k < o->vt_width; k++) o->vt[(size_t)o->vt_width * i + k] = o->vt[3 * (size_t)i + k];
    return CCN_OK;
}

ccn_status ccn_obj_parse(const char *text, size_t len, ccn_obj **out, ccn_error *err) {
    ccn__ok(err);
    if (!out || (!text && len)) return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "NULL argument");
    *out = NULL;
    ccn_obj *o = calloc(1, sizeof *o);
    if (!o) return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
    o->tags.boundary_corners = o->tags.boundary_none = o->tags.crease_method = o->tags.fvar_boundary = -1;
    o->vt_max = -1;
    const char *s = text, *end = text + len;
    long line = 0;
    while (s < end) {
        const char *nl = memchr(s, '\n', (size_t)(end - s));
        long more = 0; /* physical lines joined by continuations */
        for (;;) {
            const char *b = nl;
            if (b && b > s && b[-1] == '\r') b--;
            if (!b || b == s || b[-1] != '\\') break;
            more++;
            nl = memchr(nl + 1, '\n', (size_t)(end - nl - 1));
        }
        const char *le = nl ? nl : end;
        cursor c = {s, le};
        line++;
        ccn_status st = parse_line(o, &c, line, err);
        if (st) { ccn_obj_destroy(o); return st; }
        line += more;
        s = nl ? nl + 1 : end;
    }
    if (o->nci > 0) { /* vertex sharpness for every vertex (0 where no corner was given) */
        int32_t top = 0;
        for (int32_t k = 0; k < o->nci; k++)
            if (o->ci[k] > top) top = o->ci[k];
        if (top >= o->nv) {
            int32_t nv = o->nv;
            ccn_obj_destroy(o);
            return ccn__fail(err, CCN_ERR_IO, CCN_ELEM_VERTEX, top,
                             "OBJ: a corner names vertex %d, but the file has %d vertices",
                             (int)top + 1, (int)nv);
        }
        o->vcrease = calloc((size_t)(o->nv > 0 ? o->nv : 1), sizeof(double));
        if (!o->vcrease) {
            ccn_obj_destroy(o);
            return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
        }
        for (int32_t k = 0; k < o->nci; k++) o->vcrease[o->ci[k]] = o->cs[k]; /* the last wins */
        o->nvc = o->nv;
    }
    ccn_status st = finish_uvs(o, err);
    if (st) { ccn_obj_destroy(o); return st; }
    *out = o;
    return CCN_OK;
}

void ccn_obj_destroy(ccn_obj *o) {
    if (!o) return;
    free(o->pos); free(o->fsz); free(o->fv); free(o->ev); free(o->knot); free(o->crease);
    free(o->ci); free(o->cs); free(o->vcrease); free(o->vt); free(o->fvt);
    free(o);
}

ccn_status ccn_obj_get_cage(const ccn_obj *o, ccn_cage *c) {
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
    c->edge_creases = o->has_crease ? o->crease : NULL;
    c->vertex_creases = o->nvc > 0 ? o->vcrease : NULL; /* nvc = nv (ccn_obj_parse) */
    return CCN_OK;
}

ccn_status ccn_obj_get_fvar(const ccn_obj *o, ccn_fvar_channel *ch) {
    if (!o || !ch) return CCN_ERR_ARGUMENT;
    memset(ch, 0, sizeof *ch);
    ch->linear = o->tags.fvar_boundary >= 0 ? o->tags.fvar_boundary : CCN_FVAR_LINEAR_ALL;
    if (!o->fvar_ok) return CCN_OK;
    ch->width = o->vt_width;
    ch->num_values = o->nvt;
    ch->values = o->vt;
    ch->indices = o->fvt;
    return CCN_OK;
}

ccn_status ccn_obj_get_tags(const ccn_obj *o, ccn_obj_tags *tags) {
    if (!o || !tags) return CCN_ERR_ARGUMENT;
    *tags = o->tags;
    return CCN_OK;
}

int32_t ccn_obj_get_num_warnings(const ccn_obj *o) {
    return o ? (o->nwarn < OBJ_MAX_WARNINGS ? o->nwarn : OBJ_MAX_WARNINGS) : 0;
}

const char *ccn_obj_get_warning(const ccn_obj *o, int32_t i) {
    return o && i >= 0 && i < ccn_obj_get_num_warnings(o) ? o->warn[i] : NULL;
}
