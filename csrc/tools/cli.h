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
/* Parses an OBJ and creates a plan. Options the command line left unset (-1:
 * boundary_corners, crease_method) are taken from the file's tags (t interpolateboundary,
 * t creasemethod), else the defaults. Prints the error and returns 2 on failure. */
int ccn_cli_load_plan(const char *path, ccn_options *o, ccn_plan **plan);
/* The same, for the finite patch set (patches, export): the output level o->levels is raised
 * until the plan builds its bi-5 caps (none at levels not above the cap level). */
int ccn_cli_load_plan_caps(const char *path, ccn_options *o, ccn_plan **plan);
/* Parses an OBJ (options as above) and views it as a cage and its UV map (uv->num_values = 0
 * when there is none); the UV map's mode is *fvar_linear, or when that is -1 the file's
 * `t facevaryinginterpolateboundary` tag, else ALL (written back to *fvar_linear). *obj holds
 * the arrays (ccn_obj_destroy). Prints the error and returns 2 on failure. */
int ccn_cli_load_uv(const char *path, ccn_options *o, int *fvar_linear, ccn_obj **obj,
                    ccn_cage *cage, ccn_fvar_channel *uv);
/* Writes a mesh as OBJ with "# knot", "# crease" and "# corner" lines to path via a temporary file and rename, so no
 * partial output is left behind on failure. Returns 0 on success. */
int ccn_cli_write_mesh(const char *path, const ccn_mesh *m, const char *header);
/* The same with the refined UV map (may be NULL): `vt` lines and `f v/vt` corners. */
int ccn_cli_write_mesh_uv(const char *path, const ccn_mesh *m, const ccn_fvar *uv, const char *header);
/* ccn_fvar_linear <-> OpenSubdiv's names: none, corners-only, corners-plus1, corners-plus2,
 * boundaries, all. Returns -1 for an unknown name. */
int ccn_cli_fvar_linear(const char *s);
const char *ccn_cli_fvar_linear_name(int m);
/* Prints "ccnurbs: <what>: <message>" to stderr and returns 2. */
int ccn_cli_error(const char *what, const ccn_error *err);
/* Parses a non-negative int option value; returns 0 on success. */
int ccn_cli_int(const char *s, int lo, int hi, int *out);
/* Options of refine / limit / patches: --scheme, --corners and --crease-method always,
 * --levels (0..max_levels) and --cap when allowed, --fvar-linear when fvar_linear is not NULL
 * (left -1 when not given); then in and out paths. --corners and --crease-method not given are
 * left -1 (see ccn_cli_load_plan). Prints the problem and returns 2 on error. */
#define CCN_CLI_LEVELS 1u
#define CCN_CLI_CAP 2u
int ccn_cli_parse(int argc, char **argv, unsigned allowed, int max_levels, ccn_options *o,
                  int *fvar_linear, const char **in, const char **out);
#endif
