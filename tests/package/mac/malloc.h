/* macOS stand-in for <malloc.h> (glibc's; macOS has none), on the include path of the macOS
 * builds only (tests/package/package.mk): csrc/tools/cmd_experiment.c includes it for mallopt(),
 * which tests/package/compat.h makes a no-op outside glibc. */
#include <stdlib.h>
