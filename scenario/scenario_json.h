/* scenario_json.h: write the resolved scenario (resolve.h) as one JSON
 * object, docs/resolved-scenario.md. */
#ifndef EKM_SCENARIO_JSON_H
#define EKM_SCENARIO_JSON_H

#include <stdio.h>

#include "resolve.h"
#include "scenario.h"
#include "status.h"

#define EKM_JSON_RESOLVED_FORMAT  "ekmbench-resolved-scenario"
#define EKM_JSON_RESOLVED_VERSION 1

/* Write the JSON object and a newline to out; nothing is written on an
 * out-of-memory failure. */
ekm_status ekm_json_write_resolved(FILE *out, const ekm_scenario *s, const ekm_resolved *r, ekm_error *err);

#endif
