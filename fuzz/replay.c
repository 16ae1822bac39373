/* replay.c: walk the files and folders given to a fuzz target's replay main
 * (see replay.h). */
#define _POSIX_C_SOURCE 200809L
#include "replay.h"

#include <dirent.h>
#include <stdio.h>
#include <sys/stat.h>

static int replay_path(const char *name, const char *path, int top, int (*one)(const char *), int *count)
{
    struct stat st;
    if (stat(path, &st)) {
        if (top)
            fprintf(stderr, "%s: %s: not found, skipped\n", name, path);
        return 0;
    }
    if (!S_ISDIR(st.st_mode)) {
        ++*count;
        return one(path);
    }
    DIR *dir = opendir(path);
    if (!dir)
        return 1;
    int rc = 0;
    for (struct dirent *e; (e = readdir(dir));) {
        if (e->d_name[0] == '.')
            continue;
        char sub[4096];
        snprintf(sub, sizeof sub, "%s/%s", path, e->d_name);
        rc |= replay_path(name, sub, 0, one, count);
    }
    closedir(dir);
    return rc;
}

int fuzz_replay(const char *name, char *const *paths, int n, int (*one)(const char *path))
{
    int rc = 0, count = 0;
    for (int i = 0; i < n; i++)
        rc |= replay_path(name, paths[i], 1, one, &count);
    printf("%s: replayed %d file(s)\n", name, count);
    return rc;
}
