# WellposedPfunit.cmake: register pFUnit 4 .pf test files as CTest tests.
#   wellposed_add_pf_test(NAME <name> SOURCES <file.pf>... [<helper.f90>...]
#                         [LINK_LIBRARIES <lib>...] [LABELS <label>...]
#                         [WORKING_DIRECTORY <dir>] [MAX_PES <n>])
# One executable and test <name> (run in CMAKE_CURRENT_BINARY_DIR unless
# WORKING_DIRECTORY is given); the module in each .pf is named after the
# file. With pFUnit found (find_package(PFUNIT 4 QUIET)) this is
# add_pfunit_ctest(); without it, tests/pfunit_lite: pf2f90.py translates
# the .pf files and gen_funit.py writes their `funit` module, at build
# time. MAX_PES <n>: the files hold MPI tests (@test(npes=[...])), run
# under mpirun on n ranks, through pFUnit when it was built with MPI, else
# through pfunit_lite's `pfunit` module. See docs/guide/testing.md.

include_guard(GLOBAL)

set(WELLPOSED_PFUNIT_LITE_DIR "${CMAKE_CURRENT_LIST_DIR}/../tests/pfunit_lite"
  CACHE INTERNAL "pfunit_lite sources")
get_filename_component(WELLPOSED_PFUNIT_LITE_DIR "${WELLPOSED_PFUNIT_LITE_DIR}" ABSOLUTE)

# pfunit_lite needs Python 3 (standard library only), as pFUnit itself does.
if(NOT Python3_Interpreter_FOUND)
  find_package(Python3 COMPONENTS Interpreter)
endif()

# mpirun as CI runs it: as root Open MPI needs to be told (environment), and
# more ranks than cores need --oversubscribe (Open MPI only; pFUnit adds it
# only when the launcher's path names openmpi).
set(WELLPOSED_MPI_TEST_ENVIRONMENT OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1)
function(_wellposed_mpiexec_preflags out)
  set(flags ${MPIEXEC_PREFLAGS})
  execute_process(COMMAND ${MPIEXEC_EXECUTABLE} --version OUTPUT_VARIABLE version ERROR_QUIET)
  if(version MATCHES "Open MPI|OpenRTE" AND NOT "--oversubscribe" IN_LIST flags)
    list(APPEND flags --oversubscribe)
  endif()
  set(${out} ${flags} PARENT_SCOPE)
endfunction()

# Absolute .pf files of SOURCES, and the other sources.
function(_wellposed_pf_split_sources sources pf_out other_out)
  set(pf_files)
  set(other_files)
  foreach(src IN LISTS sources)
    get_filename_component(abs "${src}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
    if(abs MATCHES "\\.pf$")
      list(APPEND pf_files "${abs}")
    else()
      list(APPEND other_files "${abs}")
    endif()
  endforeach()
  set(${pf_out} "${pf_files}" PARENT_SCOPE)
  set(${other_out} "${other_files}" PARENT_SCOPE)
endfunction()

# The assertion library of pfunit_lite, generated and built once per tree.
function(_wellposed_pfunit_lite_library)
  if(TARGET wellposed_funit)
    return()
  endif()
  set(dir "${CMAKE_BINARY_DIR}/pfunit_lite")
  add_custom_command(OUTPUT "${dir}/funit.f90"
    COMMAND "${Python3_EXECUTABLE}" "${WELLPOSED_PFUNIT_LITE_DIR}/gen_funit.py"
            "${WELLPOSED_PFUNIT_LITE_DIR}/funit.f90.in" "${dir}/funit.f90"
    DEPENDS "${WELLPOSED_PFUNIT_LITE_DIR}/gen_funit.py" "${WELLPOSED_PFUNIT_LITE_DIR}/funit.f90.in"
    COMMENT "pfunit_lite: writing the funit module"
    VERBATIM)
  add_library(wellposed_funit STATIC "${dir}/funit.f90")
  set_target_properties(wellposed_funit PROPERTIES
    Fortran_MODULE_DIRECTORY "${dir}/mod" ARCHIVE_OUTPUT_DIRECTORY "${dir}")
  target_include_directories(wellposed_funit PUBLIC "${dir}/mod")
endfunction()

# Its module `pfunit` for MPI tests, built once per tree.
function(_wellposed_pfunit_lite_mpi_library)
  if(TARGET wellposed_pfunit)
    return()
  endif()
  set(dir "${CMAKE_BINARY_DIR}/pfunit_lite")
  add_library(wellposed_pfunit STATIC "${WELLPOSED_PFUNIT_LITE_DIR}/pfunit.f90")
  set_target_properties(wellposed_pfunit PROPERTIES
    Fortran_MODULE_DIRECTORY "${dir}/mod" ARCHIVE_OUTPUT_DIRECTORY "${dir}")
  target_link_libraries(wellposed_pfunit PUBLIC wellposed_funit MPI::MPI_Fortran)
endfunction()

# The pfunit_lite path; the self-tests of tests/pfunit_lite call it directly.
function(wellposed_add_pf_test_lite)
  cmake_parse_arguments(PARSE_ARGV 0 arg "" "NAME;WORKING_DIRECTORY;MAX_PES"
                        "SOURCES;LINK_LIBRARIES;LABELS")
  if(NOT Python3_Interpreter_FOUND)
    message(FATAL_ERROR "wellposed_add_pf_test(${arg_NAME}): pFUnit 4 was not found and pfunit_lite "
      "needs a Python 3 interpreter: install python3, or pFUnit 4 (-DCMAKE_PREFIX_PATH=<prefix>).")
  endif()
  set(funit_lib wellposed_funit)
  set(max_pes)
  if(arg_MAX_PES)
    if(NOT TARGET MPI::MPI_Fortran)
      message(FATAL_ERROR "wellposed_add_pf_test(${arg_NAME} ... MAX_PES ${arg_MAX_PES}): an MPI "
        "test needs MPI (find_package(MPI COMPONENTS Fortran)); register it only with MPI on.")
    endif()
    set(funit_lib wellposed_pfunit)
    set(max_pes --max-pes ${arg_MAX_PES})
  endif()
  _wellposed_pf_split_sources("${arg_SOURCES}" pf_files other_files)
  _wellposed_pfunit_lite_library()
  if(arg_MAX_PES)
    _wellposed_pfunit_lite_mpi_library()
  endif()
  set(gen_dir "${CMAKE_CURRENT_BINARY_DIR}/${arg_NAME}_pflite")
  set(driver "${gen_dir}/${arg_NAME}_driver.F90")
  set(generated)
  foreach(pf IN LISTS pf_files)
    get_filename_component(stem "${pf}" NAME_WE)
    list(APPEND generated "${gen_dir}/${stem}.F90")
  endforeach()
  add_custom_command(OUTPUT ${generated} "${driver}"
    COMMAND "${Python3_EXECUTABLE}" "${WELLPOSED_PFUNIT_LITE_DIR}/pf2f90.py"
            --outdir "${gen_dir}" --driver "${driver}" ${max_pes} ${pf_files}
    DEPENDS ${pf_files} "${WELLPOSED_PFUNIT_LITE_DIR}/pf2f90.py"
    COMMENT "pfunit_lite: translating the .pf files of ${arg_NAME}"
    VERBATIM)
  add_executable(${arg_NAME} ${generated} ${other_files} "${driver}")
  set_target_properties(${arg_NAME} PROPERTIES Fortran_MODULE_DIRECTORY "${gen_dir}/mod")
  target_include_directories(${arg_NAME} PRIVATE "${gen_dir}/mod")
  # The plain signature, as add_pfunit_ctest uses: callers may add libraries
  # the same way under both paths.
  target_link_libraries(${arg_NAME} ${funit_lib} ${arg_LINK_LIBRARIES})
  set(workdir "${CMAKE_CURRENT_BINARY_DIR}")
  if(arg_WORKING_DIRECTORY)
    set(workdir "${arg_WORKING_DIRECTORY}")
  endif()
  if(arg_MAX_PES)
    _wellposed_mpiexec_preflags(preflags)
    add_test(NAME ${arg_NAME} COMMAND ${MPIEXEC_EXECUTABLE} ${preflags} ${MPIEXEC_NUMPROC_FLAG}
             ${arg_MAX_PES} $<TARGET_FILE:${arg_NAME}> WORKING_DIRECTORY "${workdir}")
    set_tests_properties(${arg_NAME} PROPERTIES PROCESSORS ${arg_MAX_PES}
                         ENVIRONMENT "${WELLPOSED_MPI_TEST_ENVIRONMENT}")
  else()
    add_test(NAME ${arg_NAME} COMMAND ${arg_NAME} WORKING_DIRECTORY "${workdir}")
  endif()
  set_tests_properties(${arg_NAME} PROPERTIES LABELS "${arg_LABELS}")
endfunction()

function(wellposed_add_pf_test)
  cmake_parse_arguments(PARSE_ARGV 0 arg "" "NAME;WORKING_DIRECTORY;MAX_PES"
                        "SOURCES;LINK_LIBRARIES;LABELS")
  if(arg_UNPARSED_ARGUMENTS OR NOT arg_NAME OR NOT arg_SOURCES
     OR (DEFINED arg_MAX_PES AND NOT arg_MAX_PES MATCHES "^[1-9][0-9]*$"))
    message(FATAL_ERROR "wellposed_add_pf_test(NAME <name> SOURCES <file.pf>... [LINK_LIBRARIES ...] "
      "[LABELS ...] [WORKING_DIRECTORY <dir>] [MAX_PES <n>]): got ${ARGN}")
  endif()
  _wellposed_pf_split_sources("${arg_SOURCES}" pf_files other_files)
  if(NOT pf_files)
    message(FATAL_ERROR "wellposed_add_pf_test(${arg_NAME}): no .pf file in SOURCES")
  endif()
  if(NOT PFUNIT_FOUND OR (arg_MAX_PES AND NOT PFUNIT_MPI_FOUND))
    wellposed_add_pf_test_lite(${ARGN})
    return()
  endif()
  # Relative TEST_SOURCES: add_pfunit_ctest writes each generated .F90 at the
  # same relative path in the build tree (absolute ones it takes for build files).
  set(pf_rel)
  foreach(pf IN LISTS pf_files)
    file(RELATIVE_PATH rel "${CMAKE_CURRENT_SOURCE_DIR}" "${pf}")
    list(APPEND pf_rel "${rel}")
  endforeach()
  set(extra)
  if(arg_WORKING_DIRECTORY)
    list(APPEND extra WORKING_DIRECTORY "${arg_WORKING_DIRECTORY}")
  endif()
  if(other_files)
    list(APPEND extra OTHER_SOURCES ${other_files})
  endif()
  if(arg_LABELS)
    list(APPEND extra LABELS ${arg_LABELS})
  endif()
  if(arg_MAX_PES)
    # add_pfunit_ctest reads MPIEXEC_* of this scope to write its mpirun line.
    _wellposed_mpiexec_preflags(MPIEXEC_PREFLAGS)
    list(APPEND extra MAX_PES ${arg_MAX_PES})
  endif()
  add_pfunit_ctest(${arg_NAME} TEST_SOURCES ${pf_rel} LINK_LIBRARIES ${arg_LINK_LIBRARIES} ${extra})
  if(arg_MAX_PES)
    # its mpirun line names the program in this binary folder
    set_target_properties(${arg_NAME} PROPERTIES RUNTIME_OUTPUT_DIRECTORY
                          "${CMAKE_CURRENT_BINARY_DIR}")
    set_tests_properties(${arg_NAME} PROPERTIES PROCESSORS ${arg_MAX_PES}
                         ENVIRONMENT "${WELLPOSED_MPI_TEST_ENVIRONMENT}")
  endif()
endfunction()
