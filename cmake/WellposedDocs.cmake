# The API reference: Doxygen over the library's sources (src/, umat/) and
# docs/api/mainpage.dox, into build/docs/api/html, by the `docs` target
# (not part of `all`). A Doxygen warning fails the target
# (WARN_AS_ERROR = FAIL_ON_WARNINGS, Doxygen 1.9 and later), and the ctest
# `docs_api` builds it, so a comment Doxygen cannot read fails the suite.
# Without Doxygen there is neither the target nor the test.
find_package(Doxygen 1.9 QUIET)
if(NOT DOXYGEN_FOUND)
  message(STATUS "Doxygen 1.9 or later not found: no `docs` target (Debian: apt-get install doxygen)")
  return()
endif()

set(WELLPOSED_API_DIR "${PROJECT_BINARY_DIR}/docs/api")
file(MAKE_DIRECTORY "${WELLPOSED_API_DIR}")
configure_file("${PROJECT_SOURCE_DIR}/docs/api/Doxyfile.in"
               "${WELLPOSED_API_DIR}/Doxyfile" @ONLY)
add_custom_target(docs
  COMMAND Doxygen::doxygen "${WELLPOSED_API_DIR}/Doxyfile"
  WORKING_DIRECTORY "${WELLPOSED_API_DIR}"
  COMMENT "API reference into ${WELLPOSED_API_DIR}/html"
  VERBATIM)

if(BUILD_TESTING)
  add_test(NAME docs_api
           COMMAND ${CMAKE_COMMAND} --build ${PROJECT_BINARY_DIR} --target docs)
  set_tests_properties(docs_api PROPERTIES LABELS docs TIMEOUT 300)
endif()
