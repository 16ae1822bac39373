/* error.c: the one-line error record (see error.h). */
#include "error.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

int cg_error_set(cg_error *e, int status, const char *src, int line,
                 const char *fmt, ...)
{
  if (e) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(e->msg, sizeof e->msg, fmt, ap);
    va_end(ap);
    e->status = status;
    e->src = src;
    e->src_line = line;
  }
  return status;
}

void cg_error_clear(cg_error *e)
{
  if (e) {
    e->status = CG_OK;
    e->msg[0] = '\0';
    e->src = NULL;
    e->src_line = 0;
  }
}
