# cmake -DMPIRUN=<launcher;args> -DDRIVER=<wellposed-point> -DLIST=<batch file>
#       -DOUT=<folder> -P check_point_batch.cmake
# `wellposed-point --batch` with one bad deck of three: exit status 1, the
# other two finished, the summary names the bad one and its error.
set(batch_dir point_batch_one_bad)
set(expect_files jobs/0001/fig2_4_directional_stiffness/summary.txt
    jobs/0003/table3_2_chapter3/summary.txt)
set(expect_patterns "3 jobs, 2 ok, 1 failed" "job 0002  failed[^\n]*point_bad.nml"
    "error: wellposed-point: error: [^\n]*no_such_key" "n_materials = 2")
include(${CMAKE_CURRENT_LIST_DIR}/batch_expect.cmake)
