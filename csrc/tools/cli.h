/* Shared helpers of the ccnurbs command-line tool: used by the commands (cmd_*.c, exp_*.c);
 * this module calls only the library, never a command. */
#ifndef CCN_CLI_H
#define CCN_CLI_H
#include "ccnurbs.h"
#include <stdio.h>

/* "eigen" / "nurss" / "cc" -> scheme; returns 0 on success. */
int ccn_cli_scheme(const char *s, ccn_scheme *out);
/* scheme -> "eigen" / "nurss" / "cc". */
const char *ccn_cli_scheme_name(ccn_scheme s);
/* Reads a whole file (NUL-terminated); NULL on error with a message on stderr. */
char *ccn_cli_read_file(const char *path, size_t *len);
/* Parses an OBJ file and builds the mesh; prints the error and returns non-zero on failure.
 * Options the command line left unset (-1: boundary_corners, crease_method) are taken from
 * the file's tags (t interpolateboundary, t creasemethod), else the defaults. */
int ccn_cli_load_mesh(const char *path, ccn_options *o, ccn_mesh **out);
/* Parses an OBJ and creates a plan (options resolved as above); prints the error and returns
 * 2 on failure. */
int ccn_cli_load_plan(const char *path, ccn_options *o, ccn_plan **plan);
/* The same, for the finite patch set (patches, export): the output level o->levels is raised
 * until the plan builds its bi-5 caps (none at levels not above the cap level, issue 14). */
int ccn_cli_load_plan_caps(const char *path, ccn_options *o, ccn_plan **plan);
/* Writes a mesh as OBJ with "# knot", "# crease" and "# corner" lines to path via a temporary file and rename, so no
 * partial output is left behind on failure. Returns 0 on success. */
int ccn_cli_write_mesh(const char *path, const ccn_mesh *m, const char *header);
/* Prints "ccnurbs: <what>: <message>" to stderr and returns 2. */
int ccn_cli_error(const char *what, const ccn_error *err);
/* Parses a non-negative int option value; returns 0 on success. */
int ccn_cli_int(const char *s, int lo, int hi, int *out);
/* Options of refine / limit / patches: --scheme, --corners and --crease-method always,
 * --levels (0..max_levels) and --cap when allowed; then in and out paths. --corners and
 * --crease-method not given are left -1 (see ccn_cli_load_mesh). Prints the problem and
 * returns 2 on error. */
#define CCN_CLI_LEVELS 1u
#define CCN_CLI_CAP 2u
int ccn_cli_parse(int argc, char **argv, unsigned allowed, int max_levels, ccn_options *o,
                  const char **in, const char **out);
#endif
