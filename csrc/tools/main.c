/* ccnurbs: command-line front end of the CCNURBS library (DESIGN §3).
 * Errors: a message on stderr and exit code 2; no partial output files.
 *
 * Layout of csrc/tools (each file uses only the ones below it; no circles):
 *   main.c          usage and the dispatcher: owns the command table, calls the commands
 *   cmd_*.c         one subcommand each (entry points declared in commands.h)
 *   exp_*.c, exp.h  the pieces of `experiment` (see cmd_experiment.c)
 *   cli.c, cli.h    shared helpers of the commands: files, OBJ loading, mesh writing, errors,
 *                   option parsing, scheme names; calls the library only, never a command */
#include "commands.h"

#include <stdio.h>
#include <string.h>

typedef struct {
    const char *name;
    int (*run)(int argc, char **argv);
} command;

static const command commands[] = {
    {"refine", ccn_cmd_refine},
    {"matrix", ccn_cmd_matrix},
    {"limit", ccn_cmd_limit},
    {"patches", ccn_cmd_patches},
    {"export", ccn_cmd_export},
    {"experiment", ccn_cmd_experiment},
};

static int usage(void) {
    fprintf(stderr,
            "usage:\n"
            "  ccnurbs refine --scheme eigen|nurss|cc --levels K [--corners smooth|pinned] [--crease-method uniform|chaikin] [--polyhedron P] [--fvar-linear M] in.obj out.obj\n"
            "  ccnurbs limit --levels L [--scheme eigen|nurss|cc] [--cap bi5|refine|fill] [--corners smooth|pinned] [--crease-method uniform|chaikin] [--corner-normals] [--curvature] [--polyhedron P] [--fvar-linear M] in.obj out.obj|out.ply\n"
            "  ccnurbs patches [--scheme ...] [--cap bi5|refine|fill] [--corners ...] in.obj out.bv\n"
            "  ccnurbs export --format step|iges [--unpacked] [--fill-levels N] [--name NAME] [--face-map F]\n"
            "                 [--scheme ...] [--cap bi5|refine|fill] [--corners ...] in.obj out.step\n"
            "  ccnurbs matrix --valence N [--knots d0,d1,...] [--scheme eigen|nurss|cc]\n"
            "  ccnurbs experiment maxima|charmap --cases N --seed S [...] (experiment --help)\n"
            "  --fvar-linear none|corners-only|corners-plus1|corners-plus2|boundaries|all: the UV map's (vt)\n"
            "    interpolation at seams (OpenSubdiv's; default: the file's t facevaryinginterpolateboundary, else all)\n");
    return 2;
}

int main(int argc, char **argv) {
    if (argc < 2) return usage();
    const char *cmd = argv[1];
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        if (strcmp(cmd, commands[i].name) == 0) return commands[i].run(argc - 1, argv + 1);
    if (strcmp(cmd, "--help") == 0 || strcmp(cmd, "-h") == 0) { usage(); return 0; }
    fprintf(stderr, "ccnurbs: unknown command '%s'\n", cmd);
    return usage();
}
