/* Tiny test runner shared by tests/c/test_*.c: CHECK records a failure and goes on;
 * TEST_MAIN prints "N passed, N failed" and returns non-zero on any failure. */
#ifndef CCN_TESTLIB_H
#define CCN_TESTLIB_H
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static int tl_passed, tl_failed, tl_cur_failed;
static const char *tl_cur_name;

#define CHECK(cond, ...)                                                            \
    do {                                                                            \
        if (!(cond)) {                                                              \
            tl_cur_failed++;                                                        \
            fprintf(stderr, "FAIL %s (%s:%d): %s: ", tl_cur_name, __FILE__, __LINE__, \
                    #cond);                                                         \
            fprintf(stderr, __VA_ARGS__);                                           \
            fputc('\n', stderr);                                                    \
        }                                                                           \
    } while (0)

#define CHECK_NEAR(a, b, tol, what)                                                 \
    CHECK(fabs((double)(a) - (double)(b)) <= (tol), "%s: %.17g vs %.17g (tol %g)",   \
          (what), (double)(a), (double)(b), (double)(tol))

static double tl_now(void) {
    struct timespec t;
    timespec_get(&t, TIME_UTC);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}
/* runs one test; its wall time is printed so the slow ones can be found */
static void tl_run(const char *name, void (*fn)(void)) {
    tl_cur_name = name;
    tl_cur_failed = 0;
    double t0 = tl_now();
    fn();
    double dt = tl_now() - t0;
    if (tl_cur_failed) { tl_failed++; fprintf(stderr, "not ok - %s (%.1f s)\n", name, dt); }
    else { tl_passed++; printf("ok - %s (%.1f s)\n", name, dt); }
}
#define RUN(fn) tl_run(#fn, fn)
#define TEST_SUMMARY() (printf("%d passed, %d failed\n", tl_passed, tl_failed), tl_failed != 0)

/* Deterministic RNG for tests (splitmix64). */
static unsigned long long tl_rng_state = 0x9E3779B97F4A7C15ull;
static inline double tl_rand01(void) {
    unsigned long long z = (tl_rng_state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return (double)(z >> 11) * (1.0 / 9007199254740992.0);
}

/* Reads a whole file (NUL-terminated); NULL on error. */
static inline char *tl_slurp(const char *path, size_t *len) {
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *b = n >= 0 ? malloc((size_t)n + 1) : NULL;
    if (b && fread(b, 1, (size_t)n, f) != (size_t)n) { free(b); b = NULL; }
    fclose(f);
    if (b) { b[n] = 0; *len = (size_t)n; }
    return b;
}
#endif
