# cmake -DMPIRUN=<launcher;args> -DDRIVER=<wellposed-mpm> -DLIST=<batch file>
#       -DOUT=<folder> -P check_mpm_batch.cmake
# `wellposed-mpm --batch` with one impossible deck of three (cfl > 1): exit
# status 1, the other two finished, the summary names the bad one and its
# error.
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
set(dir "${OUT}/batch_one_bad")
foreach(f batch_summary.txt batch_summary.csv jobs/0001/wave_a/summary.txt
          jobs/0003/wave_b/summary.txt)
  if(NOT EXISTS "${dir}/${f}")
    message(FATAL_ERROR "missing ${dir}/${f}")
  endif()
endforeach()
file(READ "${dir}/batch_summary.txt" text)
foreach(pattern "3 jobs, 2 ok, 1 failed" "job 0002  failed[^\n]*bad_cfl.nml"
                "error: wellposed-mpm: error: [^\n]*cfl the CFL fraction must lie in"
                "steps = 409" "steps = 818")
  if(NOT text MATCHES "${pattern}")
    message(FATAL_ERROR "batch_summary.txt lacks \"${pattern}\":\n${text}")
  endif()
endforeach()
