# Run the program given as -DPROGRAM=... and check that standard error holds
# exactly one line, naming the element, point, slot, value and the bound, and
# that the host was told to give up (-1) and then to cut back (0.5).
execute_process(COMMAND ${PROGRAM} OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "umat_stderr_main failed (${rc}): ${err}")
endif()
string(REGEX MATCHALL "\n" newlines "${err}")
list(LENGTH newlines nlines)
if(NOT nlines EQUAL 1)
  message(FATAL_ERROR "expected exactly one line on standard error, got ${nlines}:\n${err}")
endif()
if(NOT err MATCHES "^wellposed UMAT error \\(element 7, point 3\\): PROPS\\(6\\) h = -1\\.0E\\+10 softens too strongly: the smallest dk/dz = -1\\.0E\\+10 must exceed -\\(G \\+ 9 K beta beta_p\\)/sqrt\\(1/2 \\+ 3 beta_p\\^2\\) = -2\\.1213203E\\+09 for a unique local return\n$")
  message(FATAL_ERROR "unexpected message on standard error:\n${err}")
endif()
if(NOT out MATCHES "PNEWDT +-1\\.00 +0\\.50")
  message(FATAL_ERROR "unexpected PNEWDT values: ${out}")
endif()
message(STATUS "one line on standard error: ${err}")
