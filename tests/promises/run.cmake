# The solver's run loop (continuum/run.c, control.c).
ekm_promise_test(no_hang step_limit_below_dt_min
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/run/step_limit.sh $<TARGET_FILE:ekm> ${CMAKE_SOURCE_DIR}
          ${CMAKE_CURRENT_BINARY_DIR}/step_limit
  TIMEOUT 90)
