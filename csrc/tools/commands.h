/* The subcommands of the ccnurbs command-line tool, dispatched by main.c's command table.
 * Each takes argv[0] = the subcommand name and returns the process exit code. */
#ifndef CCN_COMMANDS_H
#define CCN_COMMANDS_H

int ccn_cmd_refine(int argc, char **argv);     /* cmd_refine.c */
int ccn_cmd_matrix(int argc, char **argv);     /* cmd_matrix.c */
int ccn_cmd_limit(int argc, char **argv);      /* cmd_limit.c */
int ccn_cmd_patches(int argc, char **argv);    /* cmd_patches.c */
int ccn_cmd_export(int argc, char **argv);     /* cmd_export.c */
int ccn_cmd_experiment(int argc, char **argv); /* cmd_experiment.c */
#endif
