# The scenario reader's promises (scenario/scenario.c, resolve.c): each
# case of reader/cases.sh is one test, named for the way the reader once
# broke the promise (issue 13).
set(EKM_READER_CASES ${CMAKE_CURRENT_SOURCE_DIR}/reader/cases.sh)
function(ekm_reader_case group name)
  ekm_promise_test(${group} ${name} TIMEOUT 60
    COMMAND bash ${EKM_READER_CASES} ${name} $<TARGET_FILE:ekm> ${CMAKE_SOURCE_DIR}
            ${CMAKE_CURRENT_BINARY_DIR}/reader/${name})
endfunction()

foreach(name duplicate_key duplicate_tool_key duplicate_section hex_number nul_in_value set_number_syntax
             set_integer_syntax output_dt_zero indented_continuation)
  ekm_reader_case(no_silent_values ${name})
endforeach()
foreach(name output_dt_tiny fifo_scenario fifo_material dev_zero_scenario dev_urandom_scenario
             directory_scenario huge_scenario)
  ekm_reader_case(no_hang ${name})
endforeach()
foreach(name unterminated_header nul_in_header long_header set_value_with_newline material_file_check_line
             cross_key_dt_max cross_key_phi_loose inflow_missing_key derived_default)
  ekm_reader_case(clear_errors ${name})
endforeach()

# The scenario reader's fuzz target (fuzz/fuzz_scenario.c): replayed over the
# shipped scenarios, the seeds and the corpus (under ASan/UBSan in the
# sanitizer build) with `ulimit -f 0`, so that a file written by the reader
# kills it (SIGXFSZ); and fuzzed for 20 s with clang's libFuzzer when clang
# is installed (skipped otherwise). Long runs:
# fuzz/run.sh --target scenario SECONDS.
add_executable(fuzz_scenario_replay ${CMAKE_SOURCE_DIR}/fuzz/fuzz_scenario.c ${CMAKE_SOURCE_DIR}/fuzz/replay.c)
target_compile_definitions(fuzz_scenario_replay PRIVATE EKM_FUZZ_MAIN)
target_link_libraries(fuzz_scenario_replay PRIVATE ekm_lib)
ekm_promise_test(fuzz scenario_replay
  COMMAND bash -c "ulimit -f 0 && exec \"$@\"" replay $<TARGET_FILE:fuzz_scenario_replay>
          ${CMAKE_SOURCE_DIR}/scenarios ${CMAKE_SOURCE_DIR}/tests/continuum/data
          ${CMAKE_SOURCE_DIR}/fuzz/scenario_seeds ${CMAKE_SOURCE_DIR}/fuzz/corpus_scenario
  LABELS fuzz)
ekm_promise_test(fuzz scenario_short TIMEOUT 300
  COMMAND bash ${CMAKE_SOURCE_DIR}/fuzz/run.sh --target scenario 20 ${CMAKE_CURRENT_BINARY_DIR}/fuzz_scenario
  ENVIRONMENT "CORPUS=${CMAKE_CURRENT_BINARY_DIR}/fuzz_scenario/corpus"
  LABELS fuzz)
