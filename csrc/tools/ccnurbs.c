/* ccnurbs: command-line front end of the CCNURBS library (DESIGN §3).
 * Errors: a message on stderr and exit code 2; no partial output files. */
#include "cli.h"

#include <string.h>

static int usage(void) {
    fprintf(stderr,
            "usage:\n"
            "  ccnurbs refine --scheme eigen|nurss|cc --levels K [--corners smooth|pinned] in.obj out.obj\n"
            "  ccnurbs limit --levels L [--scheme eigen|nurss|cc] [--cap bi5|refine] [--corners smooth|pinned] in.obj out.obj\n"
            "  ccnurbs patches [--scheme ...] [--corners ...] in.obj out.bv\n"
            "  ccnurbs matrix --valence N [--knots d0,d1,...] [--scheme eigen|nurss|cc]\n"
            "  ccnurbs experiment maxima|charmap --cases N --seed S [...] (experiment --help)\n");
    return 2;
}

int main(int argc, char **argv) {
    if (argc < 2) return usage();
    const char *cmd = argv[1];
    if (strcmp(cmd, "refine") == 0) return ccn_cmd_refine(argc - 1, argv + 1);
    if (strcmp(cmd, "matrix") == 0) return ccn_cmd_matrix(argc - 1, argv + 1);
    if (strcmp(cmd, "limit") == 0) return ccn_cmd_limit(argc - 1, argv + 1);
    if (strcmp(cmd, "patches") == 0) return ccn_cmd_patches(argc - 1, argv + 1);
    if (strcmp(cmd, "experiment") == 0) return ccn_cmd_experiment(argc - 1, argv + 1);
    if (strcmp(cmd, "--help") == 0 || strcmp(cmd, "-h") == 0) { usage(); return 0; }
    fprintf(stderr, "ccnurbs: unknown command '%s'\n", cmd);
    return usage();
}
