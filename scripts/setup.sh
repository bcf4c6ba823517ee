# shellcheck shell=bash
# Sourced by scripts/run.sh and scripts/test.sh (not run on its own).
#
# wellposed_setup            installs, on Debian 12, the packages that are missing
#                            (checks with dpkg-query first, so a ready machine
#                            never calls apt-get; never prompts)
# wellposed_configure_build  configures and builds build/ (Release), incrementally
#
# Afterwards WELLPOSED_ROOT is the repository root and WELLPOSED_BUILD its
# build/ folder.

WELLPOSED_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
WELLPOSED_BUILD="${WELLPOSED_ROOT}/build"
# Both HDF5 flavours: the build links the Open MPI one (CMake finds it
# through its wrapper h5pfc, which the Debian alternatives point at
# h5pfc.openmpi) so that many ranks write one file; the serial one is what
# python3-h5py-serial (the plots' h5py, named so apt never picks
# python3-h5py-mpi) reads the files with, and what a build with
# WELLPOSED_WITH_MPI=OFF uses. petsc-dev (PETSc 3.18 with MUMPS, on the
# same Open MPI) solves the MPM's implicit scheme's sparse, nonsymmetric
# tangent systems (mpm/implicit); CMake finds it through its pkg-config
# file, so pkgconf (Debian 12's pkg-config) comes too. A build without
# them still works, and its implicit scheme refuses with a message.
WELLPOSED_PACKAGES=(
  gfortran g++ cmake make
  liblapack-dev libblas-dev
  libhdf5-dev libhdf5-openmpi-dev
  libopenmpi-dev openmpi-bin
  petsc-dev pkgconf
  python3 python3-matplotlib python3-h5py python3-h5py-serial
  doxygen
)

wellposed_setup() {
  local pkg status
  local -a missing=() sudo=()

  if ! command -v dpkg-query >/dev/null 2>&1; then
    echo "setup: not a Debian system (no dpkg-query); make sure the equivalents of" \
         "these Debian 12 packages are installed: ${WELLPOSED_PACKAGES[*]}" >&2
    return 0
  fi
  for pkg in "${WELLPOSED_PACKAGES[@]}"; do
    status="$(dpkg-query -W -f='${Status}' "${pkg}" 2>/dev/null || true)"
    [[ "${status}" == "install ok installed" ]] || missing+=("${pkg}")
  done
  if ((${#missing[@]} == 0)); then
    return 0
  fi

  echo "setup: installing missing Debian packages: ${missing[*]}"
  if [[ "$(id -u)" -ne 0 ]]; then
    if command -v sudo >/dev/null 2>&1; then
      # Never prompt without a terminal (CI): sudo -n fails instead of asking.
      if [[ -t 0 && -z "${CI:-}" ]]; then sudo=(sudo); else sudo=(sudo -n); fi
    else
      echo "setup: not root and no sudo; as root, run:" >&2
      echo "  apt-get update && apt-get install -y ${missing[*]}" >&2
      return 1
    fi
  fi
  if ! "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -q \
     || ! "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive \
          apt-get install -y -q --no-install-recommends "${missing[@]}"; then
    echo "setup: could not install packages; as root, run:" >&2
    echo "  apt-get update && apt-get install -y ${missing[*]}" >&2
    return 1
  fi
}

wellposed_configure_build() {
  local -a args=(-S "${WELLPOSED_ROOT}" -B "${WELLPOSED_BUILD}" -DCMAKE_BUILD_TYPE=Release)
  # matplotlib and h5py install for Debian's python, which a pyenv shim
  # earlier on PATH would hide from CMake.
  if [[ -x /usr/bin/python3 ]]; then
    args+=(-DPython3_EXECUTABLE=/usr/bin/python3)
  fi
  cmake "${args[@]}"
  cmake --build "${WELLPOSED_BUILD}" --parallel "$(nproc 2>/dev/null || echo 2)"
}

# Open MPI refuses to run as root unless told; tests run MPI programs.
if [[ "$(id -u)" -eq 0 ]]; then
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
fi
