# cmake -DMPIRUN=<launcher;args> -DDRIVER=<wellposed-mpm> -DLIST=<batch file>
#       -DOUT=<folder> -P check_mpm_batch_2d.cmake
# `wellposed-mpm --batch` with a bar, a plate and a bad plate: exit status 1,
# the bar and the plate finished (the plate's case files beside its
# summary), the summary names the bad plate and its error.
set(batch_dir batch_bar_and_plate)
set(expect_files jobs/0001/wave/summary.txt jobs/0002/plate/summary.txt
    jobs/0002/plate/h0.5_curve.csv jobs/0002/plate/run.h5)
set(expect_patterns "3 jobs, 2 ok, 1 failed" "job 0003  failed[^\n]*bad_dx.nml"
    "error: wellposed-mpm: error: [^\n]*width and height must be whole numbers"
    "steps = 409")
include(${CMAKE_CURRENT_LIST_DIR}/batch_expect.cmake)
