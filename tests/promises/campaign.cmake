# The campaign and the DEM runner (scripts/dem, scripts/campaign,
# workflow/Snakefile): inputs that changed after the step that used them
# are noticed, bad -s values refused. No DEM is run: the engines are
# stand-ins writing the fixture dumps of tests/compare/fixtures.
set(EKM_PROMISE_CAMPAIGN ${CMAKE_CURRENT_SOURCE_DIR}/campaign)
set(EKM_PROMISE_CAMPAIGN_WORK ${CMAKE_CURRENT_BINARY_DIR}/campaign)

# run.json records frames, bytes, sha256 of each dump; a finished run whose
# dump was cut is run again; check_run.sh refuses it
ekm_promise_test(campaign_inputs run_json_records_dumps
  COMMAND bash ${EKM_PROMISE_CAMPAIGN}/runner_inputs.sh dumps_recorded ${CMAKE_SOURCE_DIR} ${CMAKE_BINARY_DIR}
          ${EKM_PROMISE_CAMPAIGN_WORK}
  TIMEOUT 120 LABELS campaign)
# a dump truncated after its run (mtime kept): not "up to date", the CG
# step fails with exit 4 and one line naming the dump and what differs,
# the table marks the comparison missing (input gone)
ekm_promise_test(campaign_inputs dump_truncated_after_run
  COMMAND bash ${EKM_PROMISE_CAMPAIGN}/workflow_inputs.sh dump_truncated ${CMAKE_SOURCE_DIR} ${CMAKE_BINARY_DIR}
          ${EKM_PROMISE_CAMPAIGN_WORK}
  TIMEOUT 300 LABELS campaign)
# a score's cg input changed (mtime kept): the table marks it missing (input changed)
ekm_promise_test(campaign_inputs table_score_input_changed
  COMMAND bash ${EKM_PROMISE_CAMPAIGN}/workflow_inputs.sh table_input_changed ${CMAKE_SOURCE_DIR} ${CMAKE_BINARY_DIR}
          ${EKM_PROMISE_CAMPAIGN_WORK}
  TIMEOUT 300 LABELS campaign)
# a cg file deleted after a campaign (FROM_CG=1): the table is made again,
# the old row gone (missing, input gone)
ekm_promise_test(campaign_inputs table_score_input_gone
  COMMAND bash ${EKM_PROMISE_CAMPAIGN}/workflow_inputs.sh table_input_gone ${CMAKE_SOURCE_DIR} ${CMAKE_BINARY_DIR}
          ${EKM_PROMISE_CAMPAIGN_WORK}
  TIMEOUT 300 LABELS campaign)
# cg_liggghts.h5.tmp.PID of a killed step: removed and named
ekm_promise_test(campaign_inputs stale_step_temporaries
  COMMAND bash ${EKM_PROMISE_CAMPAIGN}/workflow_inputs.sh stale_tmp ${CMAKE_SOURCE_DIR} ${CMAKE_BINARY_DIR}
          ${EKM_PROMISE_CAMPAIGN_WORK}
  TIMEOUT 300 LABELS campaign)
# run.sh -s smoke.t_flow=nan, -s nosuchkey=1, -s foo: the reader's error, exit 2
ekm_promise_test(no_silent_values dem_run_set_values
  COMMAND bash ${EKM_PROMISE_CAMPAIGN}/runner_inputs.sh set_values ${CMAKE_SOURCE_DIR} ${CMAKE_BINARY_DIR}
          ${EKM_PROMISE_CAMPAIGN_WORK}
  TIMEOUT 60 LABELS campaign)

# campaign_smoke touches scenarios/chute.ini for a while (tests/campaign):
# these workflows use chute too, and must not run meanwhile.
set_tests_properties(promise.campaign_inputs.run_json_records_dumps promise.campaign_inputs.dump_truncated_after_run
  promise.campaign_inputs.table_score_input_changed promise.campaign_inputs.table_score_input_gone
  promise.campaign_inputs.stale_step_temporaries PROPERTIES RESOURCE_LOCK source_scenario_mtimes)
