/* atomic.c: temporary + fsync + rename outputs and their signal cleanup
 * (see atomic.h). */
#define _XOPEN_SOURCE 700 /* realpath, fsync */
#include "atomic.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* The signal-cleanup registry: the one global of ekmbench (atomic.h).  A
 * slot's path is written completely before `used` is set, so the handler
 * never sees a half-written path. */
static struct {
    volatile sig_atomic_t used;
    char path[EKM_ATOMIC_PATH_MAX + 32];
} cleanup_table[EKM_ATOMIC_SLOTS];

static const int cleanup_signals[] = {SIGINT, SIGTERM, SIGHUP, SIGXFSZ};

static void cleanup_handler(int sig)
{
    const int saved_errno = errno;
    for (int i = 0; i < EKM_ATOMIC_SLOTS; i++)
        if (cleanup_table[i].used)
            unlink(cleanup_table[i].path);
    struct sigaction dfl;
    memset(&dfl, 0, sizeof dfl);
    dfl.sa_handler = SIG_DFL;
    sigemptyset(&dfl.sa_mask);
    sigaction(sig, &dfl, NULL);
    /* still blocked inside the handler: delivered, with the default action,
     * as soon as the handler returns */
    raise(sig);
    errno = saved_errno;
}

ekm_status ekm_atomic_install_signal_cleanup(ekm_error *err)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = cleanup_handler;
    sigemptyset(&sa.sa_mask);
    for (size_t i = 0; i < sizeof cleanup_signals / sizeof *cleanup_signals; i++)
        sigaddset(&sa.sa_mask, cleanup_signals[i]);
    for (size_t i = 0; i < sizeof cleanup_signals / sizeof *cleanup_signals; i++) {
        struct sigaction old;
        if (sigaction(cleanup_signals[i], NULL, &old) != 0)
            return EKM_FAIL(err, EKM_EINTERNAL, "cannot query signal %d: %s", cleanup_signals[i],
                            strerror(errno));
        if (old.sa_handler == SIG_IGN)
            continue; /* ignored by whoever started us: keep it so */
        if (sigaction(cleanup_signals[i], &sa, NULL) != 0)
            return EKM_FAIL(err, EKM_EINTERNAL, "cannot install the handler for signal %d: %s",
                            cleanup_signals[i], strerror(errno));
    }
    return EKM_OK;
}

ekm_status ekm_atomic_register(const char *tmp_path, int *slot, ekm_error *err)
{
    *slot = -1;
    if (strlen(tmp_path) >= sizeof cleanup_table[0].path)
        return EKM_FAIL(err, EKM_EINPUT, "%s: path too long", tmp_path);
    for (int i = 0; i < EKM_ATOMIC_SLOTS; i++)
        if (!cleanup_table[i].used) {
            memcpy(cleanup_table[i].path, tmp_path, strlen(tmp_path) + 1);
            cleanup_table[i].used = 1;
            *slot = i;
            return EKM_OK;
        }
    return EKM_FAIL(err, EKM_EINTERNAL, "%s: more than %d temporary files open at once", tmp_path,
                    EKM_ATOMIC_SLOTS);
}

void ekm_atomic_unregister(int slot)
{
    if (slot >= 0 && slot < EKM_ATOMIC_SLOTS)
        cleanup_table[slot].used = 0;
}

/* a->path, a->tmp_path and the registration; the temporary not created. */
static ekm_status prepare(ekm_atomic *a, const char *path, ekm_error *err)
{
    memset(a, 0, sizeof *a);
    a->slot = -1;
    if (strlen(path) >= sizeof a->path)
        return EKM_FAIL(err, EKM_EINPUT, "%s: output path too long (at most %d characters)", path,
                        EKM_ATOMIC_PATH_MAX - 1);
    if (path[0] == '\0')
        return EKM_FAIL(err, EKM_EINPUT, "empty output path");
    memcpy(a->path, path, strlen(path) + 1);
    snprintf(a->tmp_path, sizeof a->tmp_path, "%s.tmp.%ld", path, (long)getpid());
    ekm_status st = ekm_atomic_register(a->tmp_path, &a->slot, err);
    if (st != EKM_OK)
        return st;
    a->active = 1;
    if (unlink(a->tmp_path) != 0 && errno != ENOENT) {
        const int e = errno;
        ekm_atomic_abort(a);
        return EKM_FAIL(err, EKM_EIO, "%s: cannot remove the stale temporary %s: %s", path, a->tmp_path,
                        strerror(e));
    }
    return EKM_OK;
}

ekm_status ekm_atomic_begin_path(ekm_atomic *a, const char *path, ekm_error *err)
{
    return prepare(a, path, err);
}

ekm_status ekm_atomic_open(ekm_atomic *a, const char *path, ekm_error *err)
{
    ekm_status st = prepare(a, path, err);
    if (st != EKM_OK)
        return st;
    const int fd = open(a->tmp_path, O_WRONLY | O_CREAT | O_EXCL, 0666);
    if (fd < 0) {
        const int e = errno;
        ekm_atomic_abort(a);
        return EKM_FAIL(err, EKM_EIO, "%s: cannot create the output file: %s", path, strerror(e));
    }
    a->fp = fdopen(fd, "w");
    if (!a->fp) {
        const int e = errno;
        close(fd);
        ekm_atomic_abort(a);
        return EKM_FAIL(err, EKM_EIO, "%s: cannot create the output file: %s", path, strerror(e));
    }
    return EKM_OK;
}

void ekm_atomic_abort(ekm_atomic *a)
{
    if (!a || !a->active)
        return;
    if (a->fp) {
        FILE *fp = a->fp;
        a->fp = NULL; /* closed once, whatever fclose says */
        fclose(fp);
    }
    unlink(a->tmp_path);
    ekm_atomic_unregister(a->slot);
    a->slot = -1;
    a->active = 0;
}

/* The directory holding path ("." when it has no '/'). */
static void directory_of(const char *path, char *out, size_t size)
{
    const char *slash = strrchr(path, '/');
    if (!slash)
        snprintf(out, size, ".");
    else if (slash == path)
        snprintf(out, size, "/");
    else
        snprintf(out, size, "%.*s", (int)(slash - path), path);
}

ekm_status ekm_atomic_check_target(const char *path, ekm_error *err)
{
    struct stat st;
    const size_t len = strlen(path);
    if (len == 0 || path[len - 1] == '/' || (stat(path, &st) == 0 && S_ISDIR(st.st_mode)))
        return EKM_FAIL(err, EKM_EIO, "%s: cannot write the output: is a directory", path);
    char dir[EKM_ATOMIC_PATH_MAX];
    directory_of(path, dir, sizeof dir);
    if (stat(dir, &st) != 0)
        return EKM_FAIL(err, EKM_EIO, "%s: cannot write the output: directory %s: %s", path, dir,
                        strerror(errno));
    if (!S_ISDIR(st.st_mode))
        return EKM_FAIL(err, EKM_EIO, "%s: cannot write the output: %s is not a directory", path, dir);
    if (access(dir, W_OK) != 0)
        return EKM_FAIL(err, EKM_EIO, "%s: cannot write the output: directory %s: %s", path, dir,
                        strerror(errno));
    return EKM_OK;
}

static int fsync_path(const char *path, int flags)
{
    const int fd = open(path, O_RDONLY | flags);
    if (fd < 0)
        return -1;
    int rc = fsync(fd);
    /* some file systems cannot sync a directory: not a failure of ours */
    if (rc != 0 && (flags & O_DIRECTORY) && (errno == EINVAL || errno == ENOTSUP))
        rc = 0;
    const int e = errno;
    if (close(fd) != 0 && rc == 0)
        return -1;
    errno = e;
    return rc;
}

ekm_status ekm_atomic_write(ekm_atomic *a, const void *data, size_t n, ekm_error *err)
{
    if (!a->active || !a->fp)
        return EKM_FAIL(err, EKM_EINTERNAL, "%s: write to an output that is not open", a->path);
    errno = 0;
    if (n > 0 && fwrite(data, 1, n, a->fp) != n) {
        const int e = errno ? errno : EIO;
        ekm_atomic_abort(a);
        return EKM_FAIL(err, EKM_EIO, "%s: cannot write the output file: %s", a->path, strerror(e));
    }
    return EKM_OK;
}

ekm_status ekm_atomic_finish(ekm_atomic *a, ekm_error *err)
{
    if (!a->active)
        return EKM_FAIL(err, EKM_EINTERNAL, "%s: commit of an output that is not open", a->path);
    if (a->synced)
        return EKM_OK;
    if (a->fp) {
        FILE *fp = a->fp;
        a->fp = NULL;
        errno = 0;
        /* fflush first: after a failed write it fails again with the
         * reason (ENOSPC), which ferror alone would not tell */
        int bad = fflush(fp) != 0 || ferror(fp) || fsync(fileno(fp)) != 0;
        int e = errno ? errno : EIO;
        if (fclose(fp) != 0 && !bad) {
            bad = 1;
            e = errno;
        }
        if (bad) {
            ekm_atomic_abort(a);
            return EKM_FAIL(err, EKM_EIO, "%s: cannot write the output file: %s", a->path, strerror(e));
        }
    } else if (fsync_path(a->tmp_path, 0) != 0) {
        const int e = errno;
        ekm_atomic_abort(a);
        return EKM_FAIL(err, EKM_EIO, "%s: cannot write the output file: %s", a->path, strerror(e));
    }
    a->synced = 1;
    return EKM_OK;
}

ekm_status ekm_atomic_commit(ekm_atomic *a, ekm_error *err)
{
    ekm_status st = ekm_atomic_finish(a, err);
    if (st != EKM_OK)
        return st;
    if (rename(a->tmp_path, a->path) != 0) {
        const int e = errno;
        ekm_atomic_abort(a);
        return EKM_FAIL(err, EKM_EIO, "%s: cannot rename the finished output into place: %s", a->path,
                        strerror(e));
    }
    ekm_atomic_unregister(a->slot);
    a->slot = -1;
    a->active = 0;
    a->renamed = 1;
    char dir[EKM_ATOMIC_PATH_MAX];
    directory_of(a->path, dir, sizeof dir);
    if (fsync_path(dir, O_DIRECTORY) != 0)
        return EKM_FAIL(err, EKM_EIO, "%s: written, but its directory %s could not be synced: %s", a->path,
                        dir, strerror(errno));
    return EKM_OK;
}

/* The canonical name of path, also when its last component does not exist
 * (then the directory's realpath + "/" + the name); 0 when unresolvable. */
static int canonical(const char *path, char *out, size_t size)
{
    char buf[PATH_MAX];
    if (realpath(path, buf)) {
        snprintf(out, size, "%s", buf);
        return 1;
    }
    char dir[EKM_ATOMIC_PATH_MAX];
    directory_of(path, dir, sizeof dir);
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    if (!realpath(dir, buf))
        return 0;
    return snprintf(out, size, "%s/%s", strcmp(buf, "/") == 0 ? "" : buf, base) < (int)size;
}

ekm_status ekm_atomic_refuse_input(const char *out_path, const char *const *inputs, size_t n, ekm_error *err)
{
    struct stat so;
    const int out_exists = stat(out_path, &so) == 0;
    char out_canon[PATH_MAX + 2];
    const int out_resolved = canonical(out_path, out_canon, sizeof out_canon);
    for (size_t i = 0; i < n; i++) {
        struct stat si;
        if (out_exists && stat(inputs[i], &si) == 0) {
            if (si.st_dev == so.st_dev && si.st_ino == so.st_ino)
                return EKM_FAIL(err, EKM_EIO, "%s: the output would overwrite the input %s", out_path,
                                inputs[i]);
            continue;
        }
        char in_canon[PATH_MAX + 2];
        if (out_resolved && canonical(inputs[i], in_canon, sizeof in_canon) &&
            strcmp(in_canon, out_canon) == 0)
            return EKM_FAIL(err, EKM_EIO, "%s: the output would overwrite the input %s", out_path, inputs[i]);
    }
    return EKM_OK;
}
