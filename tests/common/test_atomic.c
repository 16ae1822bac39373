/* common/atomic: a committed output appears whole and leaves no temporary;
 * every error path and abort leaves no temporary (and the old target as it
 * was); a process killed by SIGTERM/SIGINT/SIGHUP while writing removes its
 * temporary and dies of that signal (shell status 128+N); an output naming
 * an input is refused. */
#define _XOPEN_SOURCE 700 /* symlink, link */
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include <cmocka.h>

#include "atomic.h"
#include "testutil.h"

static void test_commit_renames(void **state)
{
    (void)state;
    char dir[1024], path[1100];
    assert_int_equal(tu_fresh_dir("commit", dir, sizeof dir), 0);
    snprintf(path, sizeof path, "%s/out.json", dir);
    assert_int_equal(tu_write_file(path, "old\n"), 0);
    ekm_atomic a;
    ekm_error err = {0};
    assert_int_equal(ekm_atomic_open(&a, path, &err), EKM_OK);
    fprintf(a.fp, "{\"x\": 1}\n");
    /* while writing: the temporary is in the target's directory, the
     * target still has its old content */
    assert_int_equal(tu_count_temporaries(dir), 1);
    assert_non_null(strstr(a.tmp_path, dir));
    char *text = tu_read_file(path);
    assert_string_equal(text, "old\n");
    free(text);
    assert_int_equal(ekm_atomic_commit(&a, &err), EKM_OK);
    text = tu_read_file(path);
    assert_string_equal(text, "{\"x\": 1}\n");
    free(text);
    assert_int_equal(tu_count_temporaries(dir), 0);
    /* abort after commit is harmless and removes nothing */
    ekm_atomic_abort(&a);
    assert_true(tu_exists(path));
}

static void test_path_mode(void **state)
{
    (void)state;
    char dir[1024], path[1100];
    assert_int_equal(tu_fresh_dir("pathmode", dir, sizeof dir), 0);
    snprintf(path, sizeof path, "%s/data.bin", dir);
    ekm_atomic a;
    ekm_error err = {0};
    assert_int_equal(ekm_atomic_begin_path(&a, path, &err), EKM_OK);
    assert_null(a.fp);
    assert_false(tu_exists(a.tmp_path));
    assert_int_equal(tu_write_file(a.tmp_path, "abc"), 0);
    assert_int_equal(ekm_atomic_commit(&a, &err), EKM_OK);
    char *text = tu_read_file(path);
    assert_string_equal(text, "abc");
    free(text);
    assert_int_equal(tu_count_temporaries(dir), 0);
    /* path mode, caller never created the file: commit fails, no output */
    snprintf(path, sizeof path, "%s/never.bin", dir);
    assert_int_equal(ekm_atomic_begin_path(&a, path, &err), EKM_OK);
    assert_int_equal(ekm_atomic_commit(&a, &err), EKM_EIO);
    assert_false(tu_exists(path));
    assert_non_null(strstr(err.message, path));
}

static void test_error_paths_leave_no_temporary(void **state)
{
    (void)state;
    char dir[1024], path[1100];
    assert_int_equal(tu_fresh_dir("errors", dir, sizeof dir), 0);
    ekm_atomic a;
    ekm_error err = {0};
    /* directory missing: refused at open, message names the target */
    snprintf(path, sizeof path, "%s/missing/out.csv", dir);
    assert_int_equal(ekm_atomic_open(&a, path, &err), EKM_EIO);
    assert_non_null(strstr(err.message, path));
    /* rename fails: the target is a non-empty directory */
    snprintf(path, sizeof path, "%s/target", dir);
    char inner[1200];
    assert_int_equal(mkdir(path, 0777), 0);
    snprintf(inner, sizeof inner, "%s/keep", path);
    assert_int_equal(tu_write_file(inner, "x"), 0);
    assert_int_equal(ekm_atomic_open(&a, path, &err), EKM_OK);
    fprintf(a.fp, "data\n");
    assert_int_equal(tu_count_temporaries(dir), 1);
    assert_int_equal(ekm_atomic_commit(&a, &err), EKM_EIO);
    assert_non_null(strstr(err.message, "cannot rename"));
    assert_int_equal(tu_count_temporaries(dir), 0);
    assert_true(tu_exists(inner));
    /* abort: no temporary, the old target untouched */
    snprintf(path, sizeof path, "%s/kept.txt", dir);
    assert_int_equal(tu_write_file(path, "old"), 0);
    assert_int_equal(ekm_atomic_open(&a, path, &err), EKM_OK);
    fprintf(a.fp, "new");
    ekm_atomic_abort(&a);
    ekm_atomic_abort(&a);
    assert_int_equal(tu_count_temporaries(dir), 0);
    char *text = tu_read_file(path);
    assert_string_equal(text, "old");
    free(text);
    /* a path too long for the registry */
    char longpath[EKM_ATOMIC_PATH_MAX + 10];
    memset(longpath, 'a', sizeof longpath - 1);
    longpath[sizeof longpath - 1] = '\0';
    assert_int_equal(ekm_atomic_open(&a, longpath, &err), EKM_EINPUT);
}

/* Child: reset sig to default, install the cleanup, open an output, tell
 * the parent (one byte on fd) and wait to be killed. */
static void child_writes_and_waits(const char *path, int fd, int ignore_sighup)
{
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    signal(SIGHUP, ignore_sighup ? SIG_IGN : SIG_DFL);
    ekm_error err = {0};
    ekm_atomic a;
    if (ekm_atomic_install_signal_cleanup(&err) != EKM_OK || ekm_atomic_open(&a, path, &err) != EKM_OK)
        _exit(90);
    fprintf(a.fp, "partial output\n");
    fflush(a.fp);
    if (write(fd, "r", 1) != 1)
        _exit(91);
    for (;;)
        pause();
}

static void kill_while_writing(int sig)
{
    char dir[1024], path[1100], name[64];
    snprintf(name, sizeof name, "signal%d", sig);
    assert_int_equal(tu_fresh_dir(name, dir, sizeof dir), 0);
    snprintf(path, sizeof path, "%s/out.h5", dir);
    int fds[2];
    assert_int_equal(pipe(fds), 0);
    fflush(NULL);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        close(fds[0]);
        child_writes_and_waits(path, fds[1], 0);
    }
    close(fds[1]);
    char c;
    assert_int_equal(read(fds[0], &c, 1), 1);
    close(fds[0]);
    assert_int_equal(tu_count_temporaries(dir), 1); /* the test can fail */
    assert_int_equal(kill(pid, sig), 0);
    int status;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    assert_true(WIFSIGNALED(status)); /* the shell shows 128 + sig */
    assert_int_equal(WTERMSIG(status), sig);
    assert_int_equal(tu_count_temporaries(dir), 0);
    assert_false(tu_exists(path));
}

static void test_sigterm_removes_temporary(void **state)
{
    (void)state;
    kill_while_writing(SIGTERM);
}

static void test_sigint_removes_temporary(void **state)
{
    (void)state;
    kill_while_writing(SIGINT);
}

static void test_sighup_removes_temporary(void **state)
{
    (void)state;
    kill_while_writing(SIGHUP);
}

/* SIGXFSZ: the file-size limit is hit while writing; the kernel's signal
 * removes the temporary like the others. */
static void test_sigxfsz_removes_temporary(void **state)
{
    (void)state;
    char dir[1024], path[1100];
    assert_int_equal(tu_fresh_dir("sigxfsz", dir, sizeof dir), 0);
    snprintf(path, sizeof path, "%s/big.csv", dir);
    fflush(NULL);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        signal(SIGXFSZ, SIG_DFL);
        struct rlimit lim = {4096, 4096}, no_core = {0, 0};
        setrlimit(RLIMIT_CORE, &no_core); /* SIGXFSZ's default action dumps core */
        ekm_error err = {0};
        ekm_atomic a;
        if (setrlimit(RLIMIT_FSIZE, &lim) != 0 || ekm_atomic_install_signal_cleanup(&err) != EKM_OK ||
            ekm_atomic_open(&a, path, &err) != EKM_OK)
            _exit(90);
        for (int i = 0; i < 10000; i++)
            fprintf(a.fp, "%d,%d\n", i, i * i);
        ekm_atomic_commit(&a, &err); /* not reached: the signal ends us */
        _exit(92);
    }
    int status;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    assert_true(WIFSIGNALED(status));
    assert_int_equal(WTERMSIG(status), SIGXFSZ);
    assert_int_equal(tu_count_temporaries(dir), 0);
    assert_false(tu_exists(path));
}

/* A signal ignored by whoever started the program stays ignored. */
static void test_ignored_signal_stays_ignored(void **state)
{
    (void)state;
    char dir[1024], path[1100];
    assert_int_equal(tu_fresh_dir("ignored", dir, sizeof dir), 0);
    snprintf(path, sizeof path, "%s/out.txt", dir);
    int fds[2];
    assert_int_equal(pipe(fds), 0);
    fflush(NULL);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        close(fds[0]);
        child_writes_and_waits(path, fds[1], 1);
    }
    close(fds[1]);
    char c;
    assert_int_equal(read(fds[0], &c, 1), 1);
    close(fds[0]);
    assert_int_equal(kill(pid, SIGHUP), 0);
    const struct timespec pause_100ms = {0, 100000000L};
    nanosleep(&pause_100ms, NULL);
    int status;
    assert_int_equal(waitpid(pid, &status, WNOHANG), 0); /* still running */
    assert_int_equal(tu_count_temporaries(dir), 1);
    assert_int_equal(kill(pid, SIGTERM), 0);
    assert_int_equal(waitpid(pid, &status, 0), pid);
    assert_int_equal(WTERMSIG(status), SIGTERM);
    assert_int_equal(tu_count_temporaries(dir), 0);
}

static void test_refuse_input(void **state)
{
    (void)state;
    char dir[1024], in[1100], other[1100], alias[1200], link_path[1100], hard[1100];
    assert_int_equal(tu_fresh_dir("refuse", dir, sizeof dir), 0);
    snprintf(in, sizeof in, "%s/scenario.ini", dir);
    snprintf(other, sizeof other, "%s/other.ini", dir);
    snprintf(alias, sizeof alias, "%s/./../refuse/scenario.ini", dir);
    snprintf(link_path, sizeof link_path, "%s/link.ini", dir);
    snprintf(hard, sizeof hard, "%s/hard.ini", dir);
    assert_int_equal(tu_write_file(in, "[run]\n"), 0);
    assert_int_equal(tu_write_file(other, "[run]\n"), 0);
    assert_int_equal(symlink(in, link_path), 0);
    assert_int_equal(link(in, hard), 0);
    ekm_error err = {0};
    const char *inputs[] = {other, in};
    assert_int_equal(ekm_atomic_refuse_input(in, inputs, 2, &err), EKM_EIO);
    char expected[4096];
    snprintf(expected, sizeof expected, "%s: the output would overwrite the input %s", in, in);
    assert_string_equal(err.message, expected);
    assert_int_equal(ekm_atomic_refuse_input(alias, inputs, 2, &err), EKM_EIO);
    assert_int_equal(ekm_atomic_refuse_input(link_path, inputs, 2, &err), EKM_EIO);
    assert_int_equal(ekm_atomic_refuse_input(hard, inputs, 2, &err), EKM_EIO);
    /* a different file, or an output not yet there, is fine */
    const char *just_other[] = {other};
    assert_int_equal(ekm_atomic_refuse_input(in, just_other, 1, &err), EKM_OK);
    char fresh[1100];
    snprintf(fresh, sizeof fresh, "%s/new.h5", dir);
    assert_int_equal(ekm_atomic_refuse_input(fresh, inputs, 2, &err), EKM_OK);
    /* neither exists yet: the same name is still refused */
    char ghost[1100];
    snprintf(ghost, sizeof ghost, "%s/ghost", dir);
    const char *ghosts[] = {ghost};
    assert_int_equal(ekm_atomic_refuse_input(ghost, ghosts, 1, &err), EKM_EIO);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_commit_renames),
        cmocka_unit_test(test_path_mode),
        cmocka_unit_test(test_error_paths_leave_no_temporary),
        cmocka_unit_test(test_sigterm_removes_temporary),
        cmocka_unit_test(test_sigint_removes_temporary),
        cmocka_unit_test(test_sighup_removes_temporary),
        cmocka_unit_test(test_sigxfsz_removes_temporary),
        cmocka_unit_test(test_ignored_signal_stays_ignored),
        cmocka_unit_test(test_refuse_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
