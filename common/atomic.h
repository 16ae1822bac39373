/* atomic.h: output files that appear complete or not at all.
 *
 * A writer opens the target through ekm_atomic_open (stdio output: JSON,
 * CSV, XDMF) or ekm_atomic_begin_path (path only: the caller, e.g. the
 * HDF5 layer, creates a->tmp_path itself).  The data go to a temporary
 * "NAME.tmp.PID" in the target's own directory; ekm_atomic_commit flushes
 * and fsyncs it, renames it onto the target and fsyncs the directory.  On
 * every error path, and in ekm_atomic_abort, the temporary is removed.
 *
 * Signals: every temporary is registered, from its creation to its commit
 * or abort, in a fixed-size static table (the one documented global of
 * ekmbench: a signal handler can reach nothing else).  Each program's main
 * calls ekm_atomic_install_signal_cleanup() once; on SIGINT, SIGTERM,
 * SIGHUP or SIGXFSZ the handler unlinks every registered temporary
 * (unlink is async-signal-safe) and re-raises the signal with its default
 * action, so the process ends "killed by signal N" (shell status 128+N).
 * A signal ignored when the program started (nohup, background jobs)
 * stays ignored.  Single-threaded programs only.
 */
#ifndef EKM_ATOMIC_H
#define EKM_ATOMIC_H

#include <stddef.h>
#include <stdio.h>

#include "status.h"

enum {
    EKM_ATOMIC_PATH_MAX = 1024, /* longest target path [chars] */
    EKM_ATOMIC_SLOTS = 64
}; /* temporaries registered at once */

typedef struct {
    char path[EKM_ATOMIC_PATH_MAX];          /* the target */
    char tmp_path[EKM_ATOMIC_PATH_MAX + 32]; /* the temporary, same directory */
    FILE *fp;                                /* stdio mode: write here; NULL in path mode */
    int slot;                                /* registry slot, -1 when none */
    int active;                              /* 1 between open/begin and commit/abort */
    int synced;                              /* 1 after ekm_atomic_finish: only the rename left */
    int renamed;                             /* 1 once the temporary is renamed onto the target */
} ekm_atomic;

/* Create the temporary for PATH and open it for writing (a->fp). */
ekm_status ekm_atomic_open(ekm_atomic *a, const char *path, ekm_error *err);

/* Path mode: choose and register a->tmp_path for PATH without creating it
 * (the caller creates and closes it before commit).  Any file already
 * under that name is removed first. */
ekm_status ekm_atomic_begin_path(ekm_atomic *a, const char *path, ekm_error *err);

/* Write n bytes to the temporary (stdio mode); on failure (disk full,
 * EFBIG) abort it: EKM_EIO "PATH: cannot write the output file: REASON". */
ekm_status ekm_atomic_write(ekm_atomic *a, const void *data, size_t n, ekm_error *err);

/* Flush, fsync and close the temporary (stdio mode), or fsync the closed
 * temporary (path mode), without renaming it: after this only the rename
 * of ekm_atomic_commit is left (so several outputs can be completed
 * before any is renamed into place).  On failure the temporary is removed:
 * EKM_EIO "PATH: cannot write the output file: REASON". */
ekm_status ekm_atomic_finish(ekm_atomic *a, ekm_error *err);

/* ekm_atomic_finish (unless already done), then rename the temporary onto
 * a->path and fsync the directory.  On failure the temporary is removed
 * and the target left as it was. */
ekm_status ekm_atomic_commit(ekm_atomic *a, ekm_error *err);

/* Close (stdio mode) and remove the temporary; harmless when a is NULL,
 * never opened, or already committed/aborted. */
void ekm_atomic_abort(ekm_atomic *a);

/* Install the cleanup handlers for SIGINT, SIGTERM, SIGHUP, SIGXFSZ. */
ekm_status ekm_atomic_install_signal_cleanup(ekm_error *err);

/* Register / unregister a temporary path with the signal cleanup directly
 * (ekm_atomic_open/begin_path/commit/abort do it; for files created
 * elsewhere).  Register returns the slot in *slot. */
ekm_status ekm_atomic_register(const char *tmp_path, int *slot, ekm_error *err);
void ekm_atomic_unregister(int slot);

/* EKM_EIO "OUT: the output would overwrite the input INPUT" when out_path
 * names the same file as one of the n inputs (same st_dev/st_ino when both
 * exist, else the same realpath); call before any work. */
ekm_status ekm_atomic_refuse_input(const char *out_path, const char *const *inputs, size_t n, ekm_error *err);

/* EKM_EIO unless an output could be written at path: not a directory (nor
 * a name ending in '/'), its directory existing, a directory and writable.
 * Call before any work, so a bad -o fails at once, not at the rename. */
ekm_status ekm_atomic_check_target(const char *path, ekm_error *err);

#endif
