/* Force-included (-include) into every file of the cross builds of tests/package/package.mk, so
 * that csrc/ builds unchanged for every platform. Differences from the Debian build handled here:
 *  - LAPACKE: scipy-openblas32's OpenBLAS exports LAPACKE_x as scipy_LAPACKE_x; scipy_lapacke.h
 *    (generated from its lapacke.h by tests/package/deps_xbuild.sh) maps every name.
 *  - Windows (mingw-w64 and winpthreads, from Zig): no sysconf() (the processor count comes from
 *    pthread_num_processors_np()), and rename() does not replace an existing file (the CLI
 *    writes a temporary file and renames it over the output).
 *  - Windows and macOS: no glibc mallopt() (csrc/tools/cmd_experiment.c tunes glibc's malloc);
 *    a no-op. */
#ifndef CCN_PACKAGE_COMPAT_H
#define CCN_PACKAGE_COMPAT_H
#include "scipy_lapacke.h"
#if defined(_WIN32)
#include <stdio.h>
int pthread_num_processors_np(void);
#define _SC_NPROCESSORS_ONLN 84
#define sysconf(name) ((name) == _SC_NPROCESSORS_ONLN ? (long)pthread_num_processors_np() : -1L)
static inline int ccn_compat_rename(const char *from, const char *to) {
    remove(to);
    return rename(from, to);
}
#define rename ccn_compat_rename
#endif
#if defined(_WIN32) || defined(__APPLE__)
#define M_TRIM_THRESHOLD (-1)
#define M_MMAP_THRESHOLD (-3)
#define mallopt(param, value) ((void)(param), (void)(value))
#endif
#endif
