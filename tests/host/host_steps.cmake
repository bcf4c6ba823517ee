# Steps of the installed-tree link test, run as  cmake -D... -P host_steps.cmake
#   STEP=install     BUILD_DIR, PREFIX, CONFIG, LIBDIR, MODDIR
#   STEP=cmake_host  SOURCE, WORK, PREFIX, CONFIG, FC, GENERATOR, MAKE_PROGRAM
#   STEP=f77_host    SOURCE, WORK, PREFIX, LIBDIR, FC
#   STEP=cxx_host    SOURCE, WORK, PREFIX, CONFIG, CXX, GENERATOR, MAKE_PROGRAM
#   STEP=wrap_host   SOURCE, WORK, PREFIX, LIBDIR, FC, NM, OBJCOPY (and f77_host/host.f)
cmake_minimum_required(VERSION 3.25)

# Run a command; stop the test with its output when it fails.
function(host_run out_var)
  execute_process(COMMAND ${ARGN}
    OUTPUT_VARIABLE _out ERROR_VARIABLE _err RESULT_VARIABLE _rc)
  string(JOIN " " _cmd ${ARGN})
  if(NOT _rc EQUAL 0)
    message(FATAL_ERROR "command failed (${_rc}): ${_cmd}\n--- stdout\n${_out}\n--- stderr\n${_err}")
  endif()
  message(STATUS "ok: ${_cmd}")
  set(${out_var} "${_out}" PARENT_SCOPE)
endfunction()

# Check a host's printout of one elastic increment:
# K = 4e9, G = 1.5e9, dstran = (1e-6, 0, ...): stress = (K + 4G/3, K - 2G/3,
# K - 2G/3, 0, 0, 0) * 1e-6 = (6000, 3000, 3000, 0, 0, 0) Pa, tangent
# D11 = 6e9, D12 = 3e9, status 0 (elastic), PNEWDT untouched.
function(host_check name output)
  message(STATUS "${name} printed:\n${output}")
  set(_expect
    "STRESS\\(1\\) = +6000\\.0000\n"
    "STRESS\\(2\\) = +3000\\.0000\n"
    "STRESS\\(3\\) = +3000\\.0000\n"
    "STRESS\\(4\\) = +-?0\\.0000\n"
    "STRESS\\(5\\) = +-?0\\.0000\n"
    "STRESS\\(6\\) = +-?0\\.0000\n"
    "DDSDDE\\(1,1\\) = +6\\.000000E\\+09\n"
    "DDSDDE\\(1,2\\) = +3\\.000000E\\+09\n"
    "STATUS = +-?0\\.000\n"
    "PNEWDT = +1\\.000\n")
  foreach(_re IN LISTS _expect)
    if(NOT output MATCHES "${_re}")
      string(REPLACE "\\" "" _want "${_re}")
      string(REPLACE " +" " " _want "${_want}")
      string(REPLACE "-?" "" _want "${_want}")
      string(STRIP "${_want}" _want)
      message(FATAL_ERROR "${name}: expected a line like '${_want}' in its output")
    endif()
  endforeach()
endfunction()

# Configure and build the host project SOURCE in WORK against PREFIX with
# the given compiler setting.
function(host_project compiler)
  file(REMOVE_RECURSE "${WORK}")
  set(_gen -G "${GENERATOR}")
  if(MAKE_PROGRAM)
    list(APPEND _gen "-DCMAKE_MAKE_PROGRAM=${MAKE_PROGRAM}")
  endif()
  host_run(_out "${CMAKE_COMMAND}" -S "${SOURCE}" -B "${WORK}" ${_gen}
    "-DCMAKE_PREFIX_PATH=${PREFIX}" "${compiler}" "-DCMAKE_BUILD_TYPE=${CONFIG}")
  host_run(_out "${CMAKE_COMMAND}" --build "${WORK}" --config "${CONFIG}")
endfunction()

if(STEP STREQUAL "install")
  file(REMOVE_RECURSE "${PREFIX}")
  host_run(_out "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${PREFIX}" --config "${CONFIG}")
  foreach(_f IN ITEMS
      "${LIBDIR}/libwellposed.a"
      "${LIBDIR}/libwellposed.so"
      "${LIBDIR}/libwellposed_nolto.a"
      "${LIBDIR}/cmake/wellposed/wellposedConfig.cmake"
      "${LIBDIR}/cmake/wellposed/wellposedConfigVersion.cmake"
      "${LIBDIR}/cmake/wellposed/wellposedTargets.cmake"
      "${MODDIR}/wellposed_kinds.mod")
    if(NOT EXISTS "${PREFIX}/${_f}")
      message(FATAL_ERROR "install: ${PREFIX}/${_f} is missing")
    endif()
  endforeach()

elseif(STEP STREQUAL "cmake_host")
  host_project("-DCMAKE_Fortran_COMPILER=${FC}")
  foreach(_exe IN ITEMS host_static host_shared)
    host_run(_out "${WORK}/bin/${_exe}")
    host_check("${_exe}" "${_out}")
  endforeach()

elseif(STEP STREQUAL "cxx_host")
  # A C++-only project: no Fortran compiler is named or enabled, so the
  # Fortran runtime must come with wellposed::wellposed.
  host_project("-DCMAKE_CXX_COMPILER=${CXX}")
  host_run(_out "${WORK}/bin/host_cxx")
  host_check(host_cxx "${_out}")

elseif(STEP STREQUAL "f77_host")
  file(REMOVE_RECURSE "${WORK}")
  file(MAKE_DIRECTORY "${WORK}")
  # The plain line a Makefile would hold; -lwellposed finds the shared
  # library first, so the run needs LD_LIBRARY_PATH (or -Wl,-rpath).
  host_run(_out "${FC}" "${SOURCE}/host.f" -o "${WORK}/host_f77_shared"
    "-L${PREFIX}/${LIBDIR}" -lwellposed -llapack -lblas)
  set(_ldpath "${PREFIX}/${LIBDIR}")
  if(DEFINED ENV{LD_LIBRARY_PATH} AND NOT "$ENV{LD_LIBRARY_PATH}" STREQUAL "")
    string(APPEND _ldpath ":$ENV{LD_LIBRARY_PATH}")
  endif()
  host_run(_out "${CMAKE_COMMAND}" -E env "LD_LIBRARY_PATH=${_ldpath}"
    "${WORK}/host_f77_shared")
  host_check(host_f77_shared "${_out}")
  # The same host against the static archive.
  host_run(_out "${FC}" "${SOURCE}/host.f" -o "${WORK}/host_f77_static"
    "${PREFIX}/${LIBDIR}/libwellposed.a" -llapack -lblas)
  host_run(_out "${WORK}/host_f77_static")
  host_check(host_f77_static "${_out}")

elseif(STEP STREQUAL "wrap_host")
  # Both static archives define no global symbol outside our modules
  # (__wellposed_*) but umat_ and vumat_, so nothing of ours can clash
  # with a host's names.
  foreach(_lib IN ITEMS libwellposed.a libwellposed_nolto.a)
    host_run(_syms "${NM}" -g --defined-only "${PREFIX}/${LIBDIR}/${_lib}")
    string(REGEX MATCHALL "[0-9a-fA-F]+ [A-Za-z] [^\n]+" _defs "${_syms}")
    set(_names)
    foreach(_d IN LISTS _defs)
      string(REGEX REPLACE "^[0-9a-fA-F]+ [A-Za-z] " "" _n "${_d}")
      if(NOT _n MATCHES "^__wellposed_")
        list(APPEND _names "${_n}")
      endif()
    endforeach()
    list(SORT _names)
    if(NOT _names STREQUAL "umat_;vumat_")
      message(FATAL_ERROR "${_lib}: global symbols outside our modules: ${_names}")
    endif()
  endforeach()
  # A host wraps our UMAT: rename it in a copy of the plain archive, link
  # its own UMAT (tests/host/wrap_host/wrapper.f) that calls ours.
  file(REMOVE_RECURSE "${WORK}")
  file(MAKE_DIRECTORY "${WORK}")
  host_run(_out "${OBJCOPY}" --redefine-sym umat_=wellposed_umat_
    "${PREFIX}/${LIBDIR}/libwellposed_nolto.a" "${WORK}/libwrapped.a")
  host_run(_out "${FC}" "${SOURCE}/../f77_host/host.f" "${SOURCE}/wrapper.f"
    -o "${WORK}/host_wrapped" "${WORK}/libwrapped.a" -llapack -lblas)
  host_run(_out "${WORK}/host_wrapped")
  host_check(host_wrapped "${_out}")

else()
  message(FATAL_ERROR "host_steps.cmake: unknown STEP '${STEP}'")
endif()
