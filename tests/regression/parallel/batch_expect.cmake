# Included by check_mpm_batch.cmake and check_point_batch.cmake, which set
#   batch_dir        the batch's folder under OUT (the batch file's name)
#   expect_files     files (relative to batch_dir) the good jobs must leave
#   expect_patterns  regular expressions batch_summary.txt must match
# and are run as cmake -DMPIRUN=<launcher;args> -DDRIVER=<program>
# -DLIST=<batch file> -DOUT=<folder> -P <script>. The batch holds one bad
# job: the exit status must be 1, the other jobs' files must exist and the
# summary must name the bad job and its error.
file(REMOVE_RECURSE "${OUT}")
if(NOT MPIRUN)
  set(MPIRUN "")
endif()
execute_process(COMMAND ${MPIRUN} ${DRIVER} --batch ${LIST} --out ${OUT} --no-plot
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message(STATUS "stdout:\n${out}")
if(NOT rc EQUAL 1)
  message(FATAL_ERROR "exit status ${rc}, expected 1 (one job failed)\n${err}")
endif()
set(dir "${OUT}/${batch_dir}")
foreach(f batch_summary.txt batch_summary.csv ${expect_files})
  if(NOT EXISTS "${dir}/${f}")
    message(FATAL_ERROR "missing ${dir}/${f}")
  endif()
endforeach()
file(READ "${dir}/batch_summary.txt" text)
foreach(pattern IN LISTS expect_patterns)
  if(NOT text MATCHES "${pattern}")
    message(FATAL_ERROR "batch_summary.txt lacks \"${pattern}\":\n${text}")
  endif()
endforeach()
