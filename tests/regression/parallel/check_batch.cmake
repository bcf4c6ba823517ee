# cmake -DMPIRUN=<launcher;args> -DBATCH=<wellposed-batch> -DDRIVER=<driver>
#       -DLIST=<batch file> -DOUT=<folder> -P check_batch.cmake
# Runs the batch of decks/batch_one_bad.txt and checks: exit status 1, the
# two good jobs finished with their figures, the bad one is named with the
# driver's error, and nothing is left under a .partial name.
file(REMOVE_RECURSE "${OUT}")
if(NOT MPIRUN)
  set(MPIRUN "")
endif()
execute_process(COMMAND ${MPIRUN} ${BATCH} --out ${OUT} ${DRIVER} ${LIST}
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message(STATUS "stdout:\n${out}")
if(NOT rc EQUAL 1)
  message(FATAL_ERROR "exit status ${rc}, expected 1 (one job failed)\n${err}")
endif()
set(dir "${OUT}/batch_one_bad")
foreach(f batch_summary.txt batch_summary.csv batch_one_bad.txt
          jobs/0001/wave_a/summary.txt jobs/0003/wave_b/summary.txt)
  if(NOT EXISTS "${dir}/${f}")
    message(FATAL_ERROR "missing ${dir}/${f}")
  endif()
endforeach()
if(EXISTS "${OUT}/batch_one_bad.partial")
  message(FATAL_ERROR "the batch folder was left under its .partial name")
endif()
file(READ "${dir}/batch_summary.txt" text)
foreach(pattern "3 jobs, 2 ok, 1 failed" "job 0002  failed" "bad_cfl.nml"
                "error: wellposed-mpm: error: .*bad_cfl.nml: &time cfl" "steps = 409")
  if(NOT text MATCHES "${pattern}")
    message(FATAL_ERROR "batch_summary.txt lacks \"${pattern}\":\n${text}")
  endif()
endforeach()
file(READ "${dir}/batch_summary.csv" csv)
string(REGEX MATCHALL "\n" newlines "${csv}")
list(LENGTH newlines n)
if(NOT n EQUAL 4)
  message(FATAL_ERROR "batch_summary.csv has ${n} lines, expected 4:\n${csv}")
endif()
foreach(pattern
    "^job,line,deck,args,status,exit_code,wall_time_s,rank,run_dir,steps,"
    "\n2,3,[^\n]*bad_cfl.nml,,failed,1,[^\n]*CFL fraction"
    "\n3,4,[^\n]*,ok,0,[^\n]*,jobs/0003/wave_b,818,800,")
  if(NOT csv MATCHES "${pattern}")
    message(FATAL_ERROR "batch_summary.csv does not match \"${pattern}\":\n${csv}")
  endif()
endforeach()
