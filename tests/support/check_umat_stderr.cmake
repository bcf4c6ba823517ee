# Run the program given as -DPROGRAM=... (tests/support/umat_stderr_main.f90)
# and check standard error: one line per material and kind (invalid PROPS,
# non-finite input), naming the material, element, point, slot, value and
# bound, none for the repeated fault; PNEWDT -1, 0.5, -1 for the host whose
# "no request" is 1, and 0.5, 0.5 (a cut-back request) for the one whose
# "no request" is -1. Then with WELLPOSED_UMAT_ON_ERROR=stop: the first
# line, the stop and a non-zero exit.
execute_process(COMMAND ${PROGRAM} OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "umat_stderr_main failed (${rc}): ${err}")
endif()
string(REGEX MATCHALL "\n" newlines "${err}")
list(LENGTH newlines nlines)
if(NOT nlines EQUAL 4)
  message(FATAL_ERROR "expected 4 lines on standard error, got ${nlines}:\n${err}")
endif()
set(h_text "PROPS\\(6\\) h = -1\\.0E\\+10 softens too strongly: the smallest dk/dz = -1\\.0E\\+10 must exceed -\\(G \\+ 9 K beta beta_p\\)/sqrt\\(1/2 \\+ 3 beta_p\\^2\\) = -2\\.1213203E\\+09 for a unique local return \\[reported once for this material\\]")
set(nan_text "non-finite STRESS, STRAN, DSTRAN or STATEV on input \\[reported once for this material\\]")
set(want
  "^wellposed UMAT error \\(material BAD, element 7, point 3\\): ${h_text}\n"
  "wellposed UMAT error \\(material BAD, element 7, point 3\\): ${nan_text}\n"
  "wellposed UMAT error \\(material OTHER, element 7, point 3\\): ${h_text}\n"
  "wellposed UMAT error \\(material OTHER, element 7, point 3\\): ${nan_text}\n$")
string(JOIN "" want ${want})
if(NOT err MATCHES "${want}")
  message(FATAL_ERROR "unexpected messages on standard error:\n${err}")
endif()
if(NOT out MATCHES "PNEWDT +-1\\.00 +0\\.50 +-1\\.00 +0\\.50 +0\\.50")
  message(FATAL_ERROR "unexpected PNEWDT values: ${out}")
endif()
message(STATUS "one line per material and kind on standard error:\n${err}")

execute_process(COMMAND ${CMAKE_COMMAND} -E env WELLPOSED_UMAT_ON_ERROR=stop ${PROGRAM}
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(rc EQUAL 0 OR out MATCHES "PNEWDT")
  message(FATAL_ERROR "WELLPOSED_UMAT_ON_ERROR=stop: the program ran on (${rc}): ${out}")
endif()
if(NOT err MATCHES "^wellposed UMAT error \\(material BAD, element 7, point 3\\): ${h_text}\nwellposed UMAT: stopping the analysis \\(WELLPOSED_UMAT_ON_ERROR=stop\\)\n")
  message(FATAL_ERROR "WELLPOSED_UMAT_ON_ERROR=stop: unexpected standard error:\n${err}")
endif()
message(STATUS "hard stop: exit ${rc}")
