/* loadcheck LIBRARY [--need NAME...] [--out FILE] CAGE.obj...: loads a packaged CCNURBS library the
 * way the add-on's ctypes does (Windows: LoadLibraryExW with the package folder added as a DLL
 * directory, as os.add_dll_directory does, so OpenBLAS beside it is found; elsewhere dlopen),
 * checks that every NAME it is given (the functions addon/native.py binds) is exported, then
 * evaluates each cage through the plan API (eigen, guided bi-5 cap, level 2, the OBJ's tags
 * ignored) and prints the limit positions and normals as OBJ `v`/`vn` lines (%.17g), so that two
 * platforms' libraries can be compared number by number (tests/package/objcmp.py).
 * Built per platform by tests/package/package.mk; run by run_wine.sh (Windows, under Wine) and on
 * Linux against the linux-x64 package. Exit 0 when all is loaded and evaluated. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ccnurbs.h"

#if defined(_WIN32)
#include <windows.h>
typedef HMODULE lib_t;
static lib_t open_lib(const char *path) {
    wchar_t w[4096], dir[4096];
    if (!MultiByteToWideChar(CP_UTF8, 0, path, -1, w, 4096)) return NULL;
    wchar_t *fp = NULL;
    if (!GetFullPathNameW(w, 4096, dir, &fp) || !fp) return NULL;
    wchar_t full[4096];
    wcscpy(full, dir);
    *fp = 0; /* dir: the package folder */
    if (!AddDllDirectory(dir)) fprintf(stderr, "loadcheck: AddDllDirectory failed\n");
    return LoadLibraryExW(full, NULL, LOAD_LIBRARY_SEARCH_DEFAULT_DIRS |
                                      LOAD_LIBRARY_SEARCH_DLL_LOAD_DIR);
}
static void *sym(lib_t h, const char *name) { return (void *)(uintptr_t)GetProcAddress(h, name); }
static const char *lib_error(void) {
    static char msg[64];
    snprintf(msg, sizeof msg, "error %lu", (unsigned long)GetLastError());
    return msg;
}
#else
#include <dlfcn.h>
typedef void *lib_t;
static lib_t open_lib(const char *path) { return dlopen(path, RTLD_NOW | RTLD_LOCAL); }
static void *sym(lib_t h, const char *name) { return dlsym(h, name); }
static const char *lib_error(void) { return dlerror(); }
#endif

typedef ccn_status (*obj_parse_fn)(const char *, size_t, ccn_obj **, ccn_error *);
typedef void (*obj_destroy_fn)(ccn_obj *);
typedef ccn_status (*obj_cage_fn)(const ccn_obj *, ccn_cage *);
typedef ccn_status (*cache_create_fn)(ccn_cache **, ccn_error *);
typedef void (*cache_destroy_fn)(ccn_cache *);
typedef ccn_status (*plan_create_fn)(const ccn_cage *, const ccn_options *, ccn_plan **,
                                     ccn_error *);
typedef ccn_status (*plan_sizes_fn)(const ccn_plan *, ccn_sizes *);
typedef ccn_status (*plan_evaluate_fn)(ccn_plan *, const double *, ccn_limit_mesh *, ccn_error *);
typedef void (*plan_destroy_fn)(ccn_plan *);

static char *read_file(const char *path, size_t *len) {
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    size_t cap = 1 << 16, n = 0;
    char *buf = malloc(cap);
    size_t got;
    while (buf && (got = fread(buf + n, 1, cap - n, f)) > 0) {
        n += got;
        if (n == cap) {
            char *nb = realloc(buf, cap *= 2);
            if (!nb) { free(buf); buf = NULL; }
            buf = nb;
        }
    }
    fclose(f);
    *len = n;
    return buf;
}

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: loadcheck LIBRARY [--need NAME...] [--out FILE] CAGE.obj...\n");
        return 2;
    }
    lib_t h = open_lib(argv[1]);
    if (!h) {
        fprintf(stderr, "loadcheck: cannot load %s: %s\n", argv[1], lib_error());
        return 1;
    }
    int bad = 0, i = 2;
    FILE *out = stdout;
    for (; i < argc && argv[i][0] == '-'; i += 2) {
        if (i + 1 >= argc) return 2;
        if (strcmp(argv[i], "--need") == 0 && !sym(h, argv[i + 1])) {
            fprintf(stderr, "loadcheck: %s does not export %s\n", argv[1], argv[i + 1]);
            bad = 1;
        } else if (strcmp(argv[i], "--out") == 0 && !(out = fopen(argv[i + 1], "w"))) {
            fprintf(stderr, "loadcheck: cannot write %s\n", argv[i + 1]);
            return 2;
        }
    }
    obj_parse_fn obj_parse = (obj_parse_fn)sym(h, "ccn_obj_parse");
    obj_destroy_fn obj_destroy = (obj_destroy_fn)sym(h, "ccn_obj_destroy");
    obj_cage_fn obj_cage = (obj_cage_fn)sym(h, "ccn_obj_get_cage");
    cache_create_fn cache_create = (cache_create_fn)sym(h, "ccn_cache_create");
    cache_destroy_fn cache_destroy = (cache_destroy_fn)sym(h, "ccn_cache_destroy");
    plan_create_fn plan_create = (plan_create_fn)sym(h, "ccn_plan_create");
    plan_sizes_fn plan_sizes = (plan_sizes_fn)sym(h, "ccn_plan_get_sizes");
    plan_evaluate_fn plan_evaluate = (plan_evaluate_fn)sym(h, "ccn_plan_evaluate");
    plan_destroy_fn plan_destroy = (plan_destroy_fn)sym(h, "ccn_plan_destroy");
    if (!obj_parse || !obj_destroy || !obj_cage || !cache_create || !cache_destroy ||
        !plan_create || !plan_sizes || !plan_evaluate || !plan_destroy) {
        fprintf(stderr, "loadcheck: %s lacks a plan API function\n", argv[1]);
        return 1;
    }
    ccn_cache *cache = NULL;
    ccn_error err;
    if (cache_create(&cache, &err) != CCN_OK) {
        fprintf(stderr, "loadcheck: ccn_cache_create: %s\n", err.message);
        return 1;
    }
    for (; i < argc; i++) {
        size_t len = 0;
        char *text = read_file(argv[i], &len);
        ccn_obj *obj = NULL;
        ccn_cage cage;
        ccn_plan *plan = NULL;
        ccn_sizes sz;
        ccn_options opts;
        memset(&opts, 0, sizeof opts);
        opts.levels = 2;
        opts.threads = 2;
        fprintf(out, "# %s\n", argv[i]);
        if (!text || obj_parse(text, len, &obj, &err) != CCN_OK || obj_cage(obj, &cage) != CCN_OK) {
            fprintf(out, "# not read\n");
        } else if ((opts.cache = cache, plan_create(&cage, &opts, &plan, &err)) != CCN_OK) {
            fprintf(out, "# plan: %s\n", err.message);
        } else if (plan_sizes(plan, &sz) == CCN_OK) {
            double *P = malloc(sizeof(double) * 3 * (size_t)sz.num_verts);
            double *N = malloc(sizeof(double) * 3 * (size_t)sz.num_verts);
            ccn_limit_mesh m;
            memset(&m, 0, sizeof m);
            m.positions = P;
            m.normals = N;
            if (!P || !N || plan_evaluate(plan, NULL, &m, &err) != CCN_OK) {
                fprintf(out, "# evaluate failed\n");
                bad = 1;
            } else {
                for (int32_t v = 0; v < sz.num_verts; v++)
                    fprintf(out, "v %.17g %.17g %.17g\n", P[3 * v], P[3 * v + 1], P[3 * v + 2]);
                for (int32_t v = 0; v < sz.num_verts; v++)
                    fprintf(out, "vn %.17g %.17g %.17g\n", N[3 * v], N[3 * v + 1], N[3 * v + 2]);
            }
            free(P);
            free(N);
        }
        if (plan) plan_destroy(plan);
        if (obj) obj_destroy(obj);
        free(text);
    }
    cache_destroy(cache);
    if (out != stdout) fclose(out);
    return bad;
}
