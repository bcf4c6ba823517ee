# Runs the pflite_selftest_fail executable and checks its failure report:
# non-zero exit, one report per `! mark: <name>` in the .pf naming the .pf file
# and the line after the mark, the expected/actual/tolerance values, and the
# closing line. Usage:
#   cmake -DEXE=<pflite_selftest_fail> -DPF=<pflite_selftest_fail.pf> -P check_failure_report.cmake

execute_process(COMMAND "${EXE}" OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
set(out "${out}${err}")
set(problems "")

if(rc EQUAL 0)
  string(APPEND problems "exit code is 0, expected non-zero\n")
endif()

# Line numbers of the directives tagged by `! mark: <name>`.
file(STRINGS "${PF}" pf_lines)
get_filename_component(pf_name "${PF}" NAME)
set(n 0)
foreach(text IN LISTS pf_lines)
  math(EXPR n "${n} + 1")
  if(text MATCHES "! mark: ([a-z0-9_]+)")
    math(EXPR line_${CMAKE_MATCH_1} "${n} + 1")
  endif()
endforeach()

# The report block of a mark: from its header to the end of its test.
function(report_block name out_var)
  set(header "at ${pf_name}:${line_${name}}: ")
  string(FIND "${out}" "${header}" pos)
  if(pos EQUAL -1)
    set(${out_var} "<no report with '${header}'>" PARENT_SCOPE)
    return()
  endif()
  string(SUBSTRING "${out}" ${pos} -1 rest)
  string(FIND "${rest}" "\n  FAILED" end)
  string(SUBSTRING "${rest}" 0 ${end} rest)
  set(${out_var} "${rest}" PARENT_SCOPE)
endfunction()

# name | regular expression the block must match
set(checks
  "real_scalar|assertEqual failed"
  "real_scalar|message: +scalar, with comma"
  "real_scalar|expected: +1\\.0000000000000000E\\+000"
  "real_scalar|actual: +1\\.5000000000000000E\\+000"
  "real_scalar|tolerance: +2\\.5000000000000000E-001 \\(absolute\\)"
  "real_array|index: +\\(2\\) \\(first of 2 mismatching of 3 elements\\)"
  "real_array|expected: +2\\.0+E\\+000"
  "real_array|actual: +2\\.50+E\\+000"
  "real_array|tolerance: +0\\.0+E\\+000"
  "real_2d|index: +\\(2,1\\)"
  "real_2d|actual: +1\\.0+E\\+000"
  "shape|expected shape \\(2\\) but actual shape \\(3\\)"
  "integer|expected: +3\n +actual: +4"
  "character|expected: +\"abc\"\n +actual: +\"abd\""
  "logical|expected: +\\.true\\.\n +actual: +\\.false\\."
  "relative|tolerance: +1\\.0+E-003 \\(relative"
  "relative_zero|zero denominator"
  "less_than|actual: +lhs = 2\\.0+E\\+000, rhs = 1\\.0+E\\+000"
  "is_finite|assertIsFinite failed"
  "is_finite|actual: +Infinity"
  "is_nan|actual: +1\\.0+E\\+000"
  "all|index: +\\(2\\) \\(first of 1 mismatching of 3 elements\\)"
  "any|assertAny failed"
  "nan_equal|actual: +NaN"
)
foreach(check IN LISTS checks)
  string(FIND "${check}" "|" bar)
  string(SUBSTRING "${check}" 0 ${bar} name)
  math(EXPR bar "${bar} + 1")
  string(SUBSTRING "${check}" ${bar} -1 regex)
  if(NOT DEFINED line_${name})
    string(APPEND problems "no '! mark: ${name}' in ${PF}\n")
    continue()
  endif()
  report_block(${name} text)
  if(NOT text MATCHES "${regex}")
    string(APPEND problems "report for mark '${name}' (${pf_name}:${line_${name}}) does not match '${regex}':\n${text}\n")
  endif()
endforeach()

# An assertion after a failed one must not run (return after failure).
if(out MATCHES "${pf_name}:${line_not_reached}:")
  string(APPEND problems "the assertion after a failure ran (line ${line_not_reached})\n")
endif()

if(NOT out MATCHES "\n1 passed, 15 failed\n")
  string(APPEND problems "closing line '1 passed, 15 failed' missing\n")
endif()

if(problems)
  message(FATAL_ERROR "pfunit_lite failure report check failed:\n${problems}\n--- output ---\n${out}")
endif()
message(STATUS "pfunit_lite failure report OK")
