/* agree_cli.h: `ekm agree NEWTON.h5 RUN.h5 [--tol X]`: does the last
 * state of an `ekm steady` output agree with the steady state an `ekm run`
 * output reached? The campaign's test (scripts/campaign/ekm_step.sh), by
 * the one measure of point.h (ekm_point_agreement), which the calibration
 * uses in-process.
 */
#ifndef EKM_AGREE_CLI_H
#define EKM_AGREE_CLI_H

/* argv: the arguments after "agree". Prints one line on stdout ("agree:
 * ..." or "disagree: ..."); returns the exit code: 0 agree, 6 disagree
 * (the run did not end steady, or a difference above the tolerance), else
 * the code of the error printed on stderr (docs/exit-codes.md). */
int ekm_agree_cli_main(int argc, char **argv);

#endif
