# The solver's run loop (continuum/run.c, control.c).
ekm_promise_test(no_hang step_limit_below_dt_min
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/run/step_limit.sh $<TARGET_FILE:ekm> ${CMAKE_SOURCE_DIR}
          ${CMAKE_CURRENT_BINARY_DIR}/step_limit
  TIMEOUT 90)

# An output is built in memory (common/h5.c): a run whose frames would not
# fit in EKM_H5OUT_MAX_BYTES (here 64 GB: 50002 frames x 20000 cells) is
# refused before it starts, exit 2, nothing written; it used to start and
# would have exhausted the memory.
ekm_promise_test(no_crash output_larger_than_memory_limit
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/run/output_size.sh $<TARGET_FILE:ekm>
          ${CMAKE_SOURCE_DIR}/scenarios/cooling.ini ${CMAKE_CURRENT_BINARY_DIR}/output_size
  TIMEOUT 60)
