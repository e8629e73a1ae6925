/* Windows stand-in for <sys/resource.h>, on the include path of the Windows test builds only
 * (tests/package/package.mk): tests/c/test_badinput*.c print the peak RSS with getrusage(). */
#ifndef CCN_WIN_SYS_RESOURCE_H
#define CCN_WIN_SYS_RESOURCE_H
#define PSAPI_VERSION 2
#include <windows.h>
#include <psapi.h>
#define RUSAGE_SELF 0
struct rusage { long ru_maxrss; /* KiB, as on Linux */ };
static inline int getrusage(int who, struct rusage *ru) {
    PROCESS_MEMORY_COUNTERS pmc;
    (void)who;
    ru->ru_maxrss = 0;
    if (!GetProcessMemoryInfo(GetCurrentProcess(), &pmc, sizeof pmc)) return -1;
    ru->ru_maxrss = (long)(pmc.PeakWorkingSetSize / 1024);
    return 0;
}
#endif
