# WellposedPfunit.cmake: register pFUnit 4 .pf test files as CTest tests.
#   wellposed_add_pf_test(NAME <name> SOURCES <file.pf>... [<helper.f90>...]
#                         [LINK_LIBRARIES <lib>...] [LABELS <label>...]
#                         [WORKING_DIRECTORY <dir>])
# With pFUnit found (find_package(PFUNIT 4 QUIET)) this is add_pfunit_ctest();
# without it, tests/pfunit_lite translates the .pf files at build time.
# The module in each .pf is named after the file. See docs/testing.md.

include_guard(GLOBAL)

set(WELLPOSED_PFUNIT_LITE_DIR "${CMAKE_CURRENT_LIST_DIR}/../tests/pfunit_lite"
  CACHE INTERNAL "pfunit_lite sources")
get_filename_component(WELLPOSED_PFUNIT_LITE_DIR "${WELLPOSED_PFUNIT_LITE_DIR}" ABSOLUTE)

# pfunit_lite needs a Python 3 interpreter (standard library only). pFUnit 4
# itself needs one too, so this is no new requirement.
if(NOT Python3_Interpreter_FOUND)
  find_package(Python3 COMPONENTS Interpreter)
endif()

# Split SOURCES into absolute .pf files and other sources.
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

# The assertion library of pfunit_lite, built once per build tree.
function(_wellposed_pfunit_lite_library)
  if(TARGET wellposed_funit)
    return()
  endif()
  set(mod_dir "${CMAKE_BINARY_DIR}/pfunit_lite/mod")
  add_library(wellposed_funit STATIC "${WELLPOSED_PFUNIT_LITE_DIR}/funit.f90")
  set_target_properties(wellposed_funit PROPERTIES
    Fortran_MODULE_DIRECTORY "${mod_dir}"
    ARCHIVE_OUTPUT_DIRECTORY "${CMAKE_BINARY_DIR}/pfunit_lite")
  target_include_directories(wellposed_funit PUBLIC "${mod_dir}")
endfunction()

# pfunit_lite path; also used directly by the pfunit_lite self-tests.
function(wellposed_add_pf_test_lite)
  cmake_parse_arguments(PARSE_ARGV 0 arg "" "NAME;WORKING_DIRECTORY" "SOURCES;LINK_LIBRARIES;LABELS")
  if(NOT arg_NAME OR NOT arg_SOURCES)
    message(FATAL_ERROR "wellposed_add_pf_test_lite: NAME and SOURCES are required")
  endif()
  if(NOT Python3_Interpreter_FOUND)
    message(FATAL_ERROR "wellposed_add_pf_test(${arg_NAME}): pFUnit 4 was not found and pfunit_lite "
      "needs a Python 3 interpreter (find_package(Python3 COMPONENTS Interpreter) failed). "
      "Install python3 or pFUnit 4.")
  endif()
  _wellposed_pf_split_sources("${arg_SOURCES}" pf_files other_files)
  if(NOT pf_files)
    message(FATAL_ERROR "wellposed_add_pf_test(${arg_NAME}): no .pf file in SOURCES")
  endif()
  _wellposed_pfunit_lite_library()

  set(gen_dir "${CMAKE_CURRENT_BINARY_DIR}/${arg_NAME}_pflite")
  set(driver "${gen_dir}/${arg_NAME}_driver.F90")
  set(generated)
  foreach(pf IN LISTS pf_files)
    # pFUnit rule: module name == file base name (pf2f90.py checks it).
    get_filename_component(stem "${pf}" NAME_WE)
    list(APPEND generated "${gen_dir}/${stem}.F90")
  endforeach()
  add_custom_command(
    OUTPUT ${generated} "${driver}"
    COMMAND "${Python3_EXECUTABLE}" "${WELLPOSED_PFUNIT_LITE_DIR}/pf2f90.py"
            --outdir "${gen_dir}" --driver "${driver}" ${pf_files}
    DEPENDS ${pf_files} "${WELLPOSED_PFUNIT_LITE_DIR}/pf2f90.py"
    COMMENT "pfunit_lite: translating .pf files of ${arg_NAME}"
    VERBATIM)

  add_executable(${arg_NAME} ${generated} ${other_files} "${driver}")
  set(mod_dir "${gen_dir}/mod")
  set_target_properties(${arg_NAME} PROPERTIES Fortran_MODULE_DIRECTORY "${mod_dir}")
  target_include_directories(${arg_NAME} PRIVATE "${mod_dir}")
  # No -ffree-line-length-none: pf2f90.py wraps what it generates below 132
  # columns, and users' own lines stay under the same limit as with pFUnit.
  target_link_libraries(${arg_NAME} PRIVATE wellposed_funit ${arg_LINK_LIBRARIES})

  if(arg_WORKING_DIRECTORY)
    set(workdir "${arg_WORKING_DIRECTORY}")
  else()
    set(workdir "${CMAKE_CURRENT_BINARY_DIR}")
  endif()
  add_test(NAME ${arg_NAME} COMMAND ${arg_NAME} WORKING_DIRECTORY "${workdir}")
  if(arg_LABELS)
    set_tests_properties(${arg_NAME} PROPERTIES LABELS "${arg_LABELS}")
  endif()
endfunction()

function(wellposed_add_pf_test)
  cmake_parse_arguments(PARSE_ARGV 0 arg "" "NAME;WORKING_DIRECTORY" "SOURCES;LINK_LIBRARIES;LABELS")
  if(arg_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "wellposed_add_pf_test: unexpected arguments: ${arg_UNPARSED_ARGUMENTS}")
  endif()
  if(NOT arg_NAME OR NOT arg_SOURCES)
    message(FATAL_ERROR "wellposed_add_pf_test: NAME and SOURCES are required")
  endif()

  if(NOT PFUNIT_FOUND)
    wellposed_add_pf_test_lite(${ARGN})
    return()
  endif()

  _wellposed_pf_split_sources("${arg_SOURCES}" pf_files other_files)
  # add_pfunit_ctest treats absolute TEST_SOURCES as build-tree files and
  # writes the generated .F90 next to them; pass paths relative to the
  # current source directory so generated files land in the binary dir.
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
  add_pfunit_ctest(${arg_NAME}
    TEST_SOURCES ${pf_rel}
    LINK_LIBRARIES ${arg_LINK_LIBRARIES}
    ${extra})
  if(arg_LABELS)
    set_tests_properties(${arg_NAME} PROPERTIES LABELS "${arg_LABELS}")
  endif()
endfunction()
