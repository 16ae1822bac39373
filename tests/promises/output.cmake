# Outputs (HDF5, XDMF sidecars, ParaView): issue 13.  Scripts in output/.
set(EKM_PROMISE_OUT ${CMAKE_CURRENT_SOURCE_DIR}/output)
set(EKM_PROMISE_OUT_WORK ${CMAKE_CURRENT_BINARY_DIR}/output_work)

# A full disk: one error line naming the file and "No space left on
# device", exit 3, nothing left (a 16 kB tmpfs as root, else ulimit -f with
# SIGXFSZ ignored: "File too large"); write_fails_efbig: that failed-write
# path always, also as root; file_size_limit: ulimit -f with SIGXFSZ at its
# default (exit 153, nothing left).
foreach(tool ekm cg)
  ekm_promise_test(no_crash disk_full_${tool}
    COMMAND bash ${EKM_PROMISE_OUT}/disk_full.sh ${tool} $<TARGET_FILE:ekm> $<TARGET_FILE:ekmcompare>
            ${CMAKE_SOURCE_DIR} ${EKM_PROMISE_OUT_WORK}/disk_full_${tool} TIMEOUT 60)
  ekm_promise_test(no_crash write_fails_efbig_${tool}
    COMMAND bash ${EKM_PROMISE_OUT}/disk_full.sh ${tool} $<TARGET_FILE:ekm> $<TARGET_FILE:ekmcompare>
            ${CMAKE_SOURCE_DIR} ${EKM_PROMISE_OUT_WORK}/write_fails_efbig_${tool}
    ENVIRONMENT EKM_TEST_NO_MOUNT=1 TIMEOUT 60)
  ekm_promise_test(no_partial_output file_size_limit_${tool}
    COMMAND bash ${EKM_PROMISE_OUT}/disk_full.sh ${tool} $<TARGET_FILE:ekm> $<TARGET_FILE:ekmcompare>
            ${CMAKE_SOURCE_DIR} ${EKM_PROMISE_OUT_WORK}/file_size_limit_${tool}
    ENVIRONMENT EKM_TEST_XFSZ=1 TIMEOUT 60)
endforeach()

# Signals: no output, no temporary, status 128+N.
foreach(sig TERM INT HUP XFSZ)
  string(TOLOWER ${sig} lower)
  ekm_promise_test(no_partial_output ekm_sig${lower}
    COMMAND bash ${EKM_PROMISE_OUT}/signal.sh ekm ${sig} $<TARGET_FILE:ekm> $<TARGET_FILE:ekmcompare>
            ${CMAKE_SOURCE_DIR} ${EKM_PROMISE_OUT_WORK}/ekm_sig${lower} TIMEOUT 60)
endforeach()
ekm_promise_test(no_partial_output cg_sigterm
  COMMAND bash ${EKM_PROMISE_OUT}/signal.sh cg TERM $<TARGET_FILE:ekm> $<TARGET_FILE:ekmcompare>
          ${CMAKE_SOURCE_DIR} ${EKM_PROMISE_OUT_WORK}/cg_sigterm TIMEOUT 60)

# XML escaping of the scenario name in the sidecar.
ekm_promise_test(no_silent_values xdmf_name_escaped
  COMMAND bash ${EKM_PROMISE_OUT}/xdmf_escaped.sh $<TARGET_FILE:ekm> ${CMAKE_SOURCE_DIR}
          ${EKM_PROMISE_OUT_WORK}/xdmf_name_escaped TIMEOUT 60)

# An output name the XDMF sidecar cannot name: refused before the run.
foreach(tool ekm cg)
  ekm_promise_test(clear_errors xdmf_output_name_${tool}
    COMMAND bash ${EKM_PROMISE_OUT}/xdmf_output_name.sh ${tool} $<TARGET_FILE:ekm> $<TARGET_FILE:ekmcompare>
            ${CMAKE_SOURCE_DIR} ${EKM_PROMISE_OUT_WORK}/xdmf_output_name_${tool} TIMEOUT 60)
endforeach()

# ParaView (label paraview; skipped without pvpython).
foreach(kind ekm ekm_pwall cg)
  foreach(what readers plot_over_line)
    ekm_promise_test(paraview ${kind}_${what}
      COMMAND bash ${EKM_PROMISE_OUT}/paraview.sh ${kind} ${what} $<TARGET_FILE:ekm> $<TARGET_FILE:ekmcompare>
              ${CMAKE_SOURCE_DIR} ${EKM_PROMISE_OUT_WORK}/paraview_${kind}_${what}
      LABELS paraview TIMEOUT 120)
  endforeach()
endforeach()
