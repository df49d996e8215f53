# cmake -DEXE=... -DFORBIDDEN="opencv;ceres" -P check_no_link.cmake
# Fails if the dynamic loader resolves any library of EXE (transitively)
# whose name contains one of FORBIDDEN: proves what a consumer really links.
execute_process(COMMAND ldd ${EXE} OUTPUT_VARIABLE out RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "ldd ${EXE} failed (${rc})")
endif()
foreach(name ${FORBIDDEN})
  string(REGEX MATCHALL "[^\n]*${name}[^\n]*" hits "${out}")
  if(hits)
    message(FATAL_ERROR "${EXE} links ${name}: ${hits}")
  endif()
endforeach()
message(STATUS "${EXE}: no ${FORBIDDEN} among its libraries")
