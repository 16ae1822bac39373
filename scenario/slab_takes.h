/* slab_takes.h: does the 1D solver of a scenario's closure take it?
 *
 * The EKM's styles (ekm_transport) run on the EKM's time stepper, which
 * takes every 1D scenario the reader accepts. A closure with a local
 * stress and a dilatancy law (mu_i) runs on the dense slab solver
 * (continuum/local_slab.h), which takes a no-slip wall at the bottom and a
 * free surface (gravity into the bed) or a top wall held at a pressure,
 * without [hypo] or a tilting base, and needs [numerics] gdot_min. Any
 * other closure has no slab solver. Here, in the scenario service, so that
 * the resolved scenario can say it (docs/resolved-scenario.md, the
 * campaign's closure sets).
 */
#ifndef EKM_SLAB_TAKES_H
#define EKM_SLAB_TAKES_H

#include "scenario.h"
#include "status.h"

/* EKM_OK when the 1D solver of sc's closure takes sc; else EKM_EINPUT (a
 * key it needs is missing: gdot_min) or EKM_EUNAVAILABLE (no slab solver,
 * or a boundary or option it does not solve), one line naming the file
 * and the key. */
ekm_status ekm_scenario_slab_takes(const ekm_scenario *sc, ekm_error *err);

#endif
