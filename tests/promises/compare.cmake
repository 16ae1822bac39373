# ekmcompare's inputs (issue 13): dump values and gzip streams that make no
# sense are the dump's error at its line (and column, or byte offset), a
# cut-off dump an error when the snapshot count is known, score's inputs
# checked for their kind and for points in common, no output over an input.
# Each case is tests/promises/compare/case.sh CASE (the comments there say
# what it reproduces).
set(_cmp_case ${CMAKE_CURRENT_SOURCE_DIR}/compare/case.sh)
function(ekm_compare_promise group name)
  ekm_promise_test(${group} ${name}
    COMMAND bash ${_cmp_case} ${name} $<TARGET_FILE:ekmcompare> ${CMAKE_SOURCE_DIR}
            ${CMAKE_CURRENT_BINARY_DIR}/compare/${name}
    LABELS compare ${ARGN})
endfunction()

foreach(name dump_negative_radius dump_all_radii_negative dump_huge_radius dump_huge_box
             dump_box_infinite_length dump_wide_particles gzip_corrupt_byte gzip_corrupt_check
             gzip_truncated_offset dump_type_not_integer)
  ekm_compare_promise(clear_errors ${name})
endforeach()
foreach(name cut_dump_expect_snapshots dump_cut_inside_number dump_velocity_overflow dump_time_not_increasing
             score_shift_no_points score_swapped_files fit_rheology_ekm_file)
  ekm_compare_promise(no_silent_values ${name})
endforeach()
foreach(name cg_output_is_dump cg_output_is_pair_dump score_output_is_input fit_output_is_input
             fit_scenario_output_is_case_file)
  ekm_compare_promise(inputs_kept ${name})
endforeach()
