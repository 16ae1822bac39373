/* h5kind.c: which tool wrote an HDF5 input (see h5kind.h). */
#include "h5kind.h"

#include <errno.h>
#include <string.h>
#include <sys/stat.h>

unsigned cg_h5kind_of(ekm_h5_file *f)
{
    unsigned k = 0;
    if (ekm_h5_attr_exists(f, NULL, "kernel") && ekm_h5_attr_exists(f, NULL, "snapshots_used"))
        k |= CG_H5KIND_CG;
    if (ekm_h5_attr_exists(f, NULL, "stats.steps") && ekm_h5_attr_exists(f, NULL, "variant"))
        k |= CG_H5KIND_EKM;
    return k;
}

static const char *kind_name(unsigned k)
{
    return k == CG_H5KIND_CG ? "ekmcompare cg" : "ekm run";
}

ekm_status cg_h5kind_check(ekm_h5_file *f, const char *cmd, const char *option, unsigned allowed,
                           ekm_error *err)
{
    const unsigned k = cg_h5kind_of(f);
    if (k & allowed)
        return EKM_OK;
    const char *want = allowed == CG_H5KIND_CG    ? "an ekmcompare cg output"
                       : allowed == CG_H5KIND_EKM ? "an ekm run output"
                                                  : "an ekm run or ekmcompare cg output";
    if (k == CG_H5KIND_CG || k == CG_H5KIND_EKM)
        return EKM_FAIL(err, EKM_EINPUT, "%s: %s %s: not %s (written by %s?)", cmd, option, ekm_h5_path(f),
                        want, kind_name(k));
    return EKM_FAIL(err, EKM_EINPUT,
                    "%s: %s %s: not %s (expected the root attributes kernel and snapshots_used of a cg "
                    "output, or stats.steps and variant of an ekm run)",
                    cmd, option, ekm_h5_path(f), want);
}

ekm_status cg_h5kind_check_path(const char *path, const char *cmd, const char *option, unsigned allowed,
                                ekm_error *err)
{
    struct stat sb;
    if (stat(path, &sb) != 0)
        return EKM_FAIL(err, EKM_EIO, "%s: cannot open: %s", path, strerror(errno));
    if (!S_ISREG(sb.st_mode))
        return EKM_FAIL(err, EKM_EIO, "%s: cannot open: not a regular file", path);
    ekm_h5_file *f = NULL;
    ekm_status rc = ekm_h5_open(&f, path, err);
    if (!rc)
        rc = cg_h5kind_check(f, cmd, option, allowed, err);
    ekm_h5_close(f);
    return rc;
}
