# cmake -DMPIRUN=<launcher;args> -DDRIVER=<wellposed-mpm> -DLIST=<batch file>
#       -DOUT=<folder> -P check_mpm_batch.cmake
# `wellposed-mpm --batch` with one impossible deck of three (cfl > 1): exit
# status 1, the other two finished, the summary names the bad one and its
# error.
set(batch_dir batch_one_bad)
set(expect_files jobs/0001/wave_a/summary.txt jobs/0003/wave_b/summary.txt)
set(expect_patterns "3 jobs, 2 ok, 1 failed" "job 0002  failed[^\n]*bad_cfl.nml"
    "error: wellposed-mpm: error: [^\n]*cfl the CFL fraction must lie in"
    "steps = 409" "steps = 818")
include(${CMAKE_CURRENT_LIST_DIR}/batch_expect.cmake)
