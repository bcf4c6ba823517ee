# Every test gets a TMPDIR of its own, build/tmp/<n>.
#
# Open MPI keeps one session directory per host and user under TMPDIR, and a
# job that finishes removes it while another job may be creating its own
# inside it ("A call to mkdir was unable to create the desired directory").
# MPI programs run side by side by `ctest -j` then fail at random. A private
# TMPDIR per test takes the race away; it is short because Open MPI puts Unix
# sockets there (at most 107 characters of path). ENVIRONMENT_MODIFICATION is
# used so that a test's own ENVIRONMENT property, set later, keeps it.
set_property(GLOBAL PROPERTY WELLPOSED_TEST_COUNT 0)

function(add_test)
  # forwarded one by one, bracket-quoted: ${ARGV} would drop empty arguments
  set(_args "")
  math(EXPR _last "${ARGC} - 1")
  foreach(_i RANGE ${_last})
    string(APPEND _args " [==[${ARGV${_i}}]==]")
  endforeach()
  cmake_language(EVAL CODE "_add_test(${_args})")
  if(ARGV0 STREQUAL "NAME")
    set(_name "${ARGV1}")
  else()
    set(_name "${ARGV0}")
  endif()
  get_property(_n GLOBAL PROPERTY WELLPOSED_TEST_COUNT)
  math(EXPR _n "${_n} + 1")
  set_property(GLOBAL PROPERTY WELLPOSED_TEST_COUNT ${_n})
  set(_dir "${PROJECT_BINARY_DIR}/tmp/${_n}")
  file(MAKE_DIRECTORY "${_dir}")
  set_property(TEST "${_name}" PROPERTY ENVIRONMENT_MODIFICATION "TMPDIR=set:${_dir}")
endfunction()
