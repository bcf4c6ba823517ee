# WellposedPfunit.cmake: register pFUnit 4 .pf test files as CTest tests.
#   wellposed_add_pf_test(NAME <name> SOURCES <file.pf>... [<helper.f90>...]
#                         [LINK_LIBRARIES <lib>...] [LABELS <label>...]
#                         [WORKING_DIRECTORY <dir>])
# One executable and test <name> (run in CMAKE_CURRENT_BINARY_DIR unless
# WORKING_DIRECTORY is given); the module in each .pf is named after the
# file. With pFUnit found (find_package(PFUNIT 4 QUIET)) this is
# add_pfunit_ctest(); without it, tests/pfunit_lite: pf2f90.py translates
# the .pf files and gen_funit.py writes their `funit` module, at build
# time. See docs/testing.md.

include_guard(GLOBAL)

set(WELLPOSED_PFUNIT_LITE_DIR "${CMAKE_CURRENT_LIST_DIR}/../tests/pfunit_lite"
  CACHE INTERNAL "pfunit_lite sources")
get_filename_component(WELLPOSED_PFUNIT_LITE_DIR "${WELLPOSED_PFUNIT_LITE_DIR}" ABSOLUTE)

# pfunit_lite needs Python 3 (standard library only), as pFUnit itself does.
if(NOT Python3_Interpreter_FOUND)
  find_package(Python3 COMPONENTS Interpreter)
endif()

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

# The pfunit_lite path; the self-tests of tests/pfunit_lite call it directly.
function(wellposed_add_pf_test_lite)
  cmake_parse_arguments(PARSE_ARGV 0 arg "" "NAME;WORKING_DIRECTORY" "SOURCES;LINK_LIBRARIES;LABELS")
  if(NOT Python3_Interpreter_FOUND)
    message(FATAL_ERROR "wellposed_add_pf_test(${arg_NAME}): pFUnit 4 was not found and pfunit_lite "
      "needs a Python 3 interpreter: install python3, or pFUnit 4 (-DCMAKE_PREFIX_PATH=<prefix>).")
  endif()
  _wellposed_pf_split_sources("${arg_SOURCES}" pf_files other_files)
  _wellposed_pfunit_lite_library()
  set(gen_dir "${CMAKE_CURRENT_BINARY_DIR}/${arg_NAME}_pflite")
  set(driver "${gen_dir}/${arg_NAME}_driver.F90")
  set(generated)
  foreach(pf IN LISTS pf_files)
    get_filename_component(stem "${pf}" NAME_WE)
    list(APPEND generated "${gen_dir}/${stem}.F90")
  endforeach()
  add_custom_command(OUTPUT ${generated} "${driver}"
    COMMAND "${Python3_EXECUTABLE}" "${WELLPOSED_PFUNIT_LITE_DIR}/pf2f90.py"
            --outdir "${gen_dir}" --driver "${driver}" ${pf_files}
    DEPENDS ${pf_files} "${WELLPOSED_PFUNIT_LITE_DIR}/pf2f90.py"
    COMMENT "pfunit_lite: translating the .pf files of ${arg_NAME}"
    VERBATIM)
  add_executable(${arg_NAME} ${generated} ${other_files} "${driver}")
  set_target_properties(${arg_NAME} PROPERTIES Fortran_MODULE_DIRECTORY "${gen_dir}/mod")
  target_include_directories(${arg_NAME} PRIVATE "${gen_dir}/mod")
  # The plain signature, as add_pfunit_ctest uses: callers may add libraries
  # the same way under both paths.
  target_link_libraries(${arg_NAME} wellposed_funit ${arg_LINK_LIBRARIES})
  set(workdir "${CMAKE_CURRENT_BINARY_DIR}")
  if(arg_WORKING_DIRECTORY)
    set(workdir "${arg_WORKING_DIRECTORY}")
  endif()
  add_test(NAME ${arg_NAME} COMMAND ${arg_NAME} WORKING_DIRECTORY "${workdir}")
  set_tests_properties(${arg_NAME} PROPERTIES LABELS "${arg_LABELS}")
endfunction()

function(wellposed_add_pf_test)
  cmake_parse_arguments(PARSE_ARGV 0 arg "" "NAME;WORKING_DIRECTORY" "SOURCES;LINK_LIBRARIES;LABELS")
  if(arg_UNPARSED_ARGUMENTS OR NOT arg_NAME OR NOT arg_SOURCES)
    message(FATAL_ERROR "wellposed_add_pf_test(NAME <name> SOURCES <file.pf>... [LINK_LIBRARIES ...] "
      "[LABELS ...] [WORKING_DIRECTORY <dir>]): got ${ARGN}")
  endif()
  _wellposed_pf_split_sources("${arg_SOURCES}" pf_files other_files)
  if(NOT pf_files)
    message(FATAL_ERROR "wellposed_add_pf_test(${arg_NAME}): no .pf file in SOURCES")
  endif()
  if(NOT PFUNIT_FOUND)
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
  add_pfunit_ctest(${arg_NAME} TEST_SOURCES ${pf_rel} LINK_LIBRARIES ${arg_LINK_LIBRARIES} ${extra})
endfunction()
