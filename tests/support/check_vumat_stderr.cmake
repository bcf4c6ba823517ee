# Run the program given as -DPROGRAM=... and check that the VUMAT stopped the
# analysis (non-zero exit, nothing after the call) with the message naming
# the material, the slot, the value and the bound on standard error.
execute_process(COMMAND ${PROGRAM} OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(rc EQUAL 0)
  message(FATAL_ERROR "vumat_stderr_main exited 0: the VUMAT did not stop the analysis\n${out}")
endif()
if(out MATCHES "returned")
  message(FATAL_ERROR "the VUMAT returned from invalid PROPS:\n${out}")
endif()
if(NOT err MATCHES "^wellposed VUMAT error \\(material ROCK\\): PROPS\\(6\\) h = -1\\.0E\\+10 softens too strongly")
  message(FATAL_ERROR "unexpected message on standard error:\n${err}")
endif()
message(STATUS "the VUMAT stopped with: ${err}")
