#!/usr/bin/env bash
# Build CalculiX ccx 2.20 from Debian's source package with our UMAT linked in.
#   contrib/calculix/build_ccx.sh PREFIX LIBRARY [LINK_ARGS...]
# PREFIX   where ccx goes (PREFIX/bin/ccx); its objects are cached in PREFIX/ccx,
#          compiled once per machine (minutes), so later calls only relink.
# LIBRARY  the archive holding umat_ (libwellposed_plain.a: no LTO bytecode).
# LINK_ARGS  more link inputs, e.g. -L/usr/lib/x86_64-linux-gnu -llapack.
# Relinks when LIBRARY or LINK_ARGS changed (their sha256 is kept beside ccx),
# otherwise does nothing. apt (a deb-src entry for the archive of
# /etc/apt/sources.list.d/debian.sources when none exists, the build
# packages) runs as root or through sudo, only when something is missing.
set -euo pipefail
prefix=${1:?usage: build_ccx.sh PREFIX LIBRARY [LINK_ARGS...]}
library=${2:?usage: build_ccx.sh PREFIX LIBRARY [LINK_ARGS...]}
shift 2
version=2.20
objects="$prefix/ccx/ccx_$version-objects.a"

sudo=()
[ "$(id -u)" -eq 0 ] || sudo=(sudo)

apt_install() {
  local missing=()
  for p in "$@"; do dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p"); done
  [ ${#missing[@]} -eq 0 ] && return 0
  "${sudo[@]}" apt-get update -q
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -q "${missing[@]}"
}

# A deb-src entry for the same archive as the binary entries, when there is none.
add_deb_src() {
  local src=/etc/apt/sources.list.d/debian.sources
  local out=/etc/apt/sources.list.d/wellposed-deb-src.sources
  if grep -rqs '^Types:.*deb-src' /etc/apt/sources.list.d/ ||
     grep -qs '^deb-src' /etc/apt/sources.list; then return 0; fi
  [ -f "$src" ] || { echo "build_ccx.sh: no $src to copy a deb-src entry from" >&2; exit 1; }
  sed 's/^Types: deb$/Types: deb-src/' "$src" | "${sudo[@]}" tee "$out" >/dev/null
  "${sudo[@]}" apt-get update -q
}

# Debian's build of ccx (debian/rules flags), minus the example umat.f: left in,
# it would be linked instead of ours without a word.
build_objects() {
  [ -f "$objects" ] && return 0
  apt_install dpkg-dev gfortran gcc make libarpack2-dev libspooles-dev liblapack-dev libblas-dev
  add_deb_src
  local work="$prefix/ccx/src"
  rm -rf "$work" && mkdir -p "$work"
  (cd "$work" && apt-get source -q "calculix-ccx=$version-1")
  local dir="$work/calculix-ccx-$version/ccx_$version/src"
  local cflags="-Wall -O2 -I/usr/include/spooles -DARCH=\"Linux\" -DSPOOLES -DARPACK -DMATRIXSTORAGE -DUSE_MT=1"
  local fflags="-fallow-argument-mismatch -O2"
  make -C "$dir" -j"$(nproc)" -s CFLAGS="$cflags" FFLAGS="$fflags" "ccx_$version.a" "ccx_$version.o"
  ar d "$dir/ccx_$version.a" umat.o
  cp "$dir/ccx_$version.o" "$prefix/ccx/ccx_$version-main.o"
  cp "$dir/ccx_$version.a" "$objects.tmp" && mv "$objects.tmp" "$objects"
}

link_ccx() {
  local stamp="$prefix/bin/ccx.inputs"
  local want
  want=$( { sha256sum "$library" "$objects"; printf '%s\n' "$@"; } )
  if [ -x "$prefix/bin/ccx" ] && [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ]; then
    return 0
  fi
  mkdir -p "$prefix/bin"
  gfortran -O2 -fopenmp -o "$prefix/bin/ccx.tmp" "$prefix/ccx/ccx_$version-main.o" \
    "$objects" "$library" "$@" -lspooles -lpthread -larpack -llapack -lblas -lm -lc
  mv "$prefix/bin/ccx.tmp" "$prefix/bin/ccx"
  printf '%s\n' "$want" > "$stamp"
  echo "build_ccx.sh: linked $prefix/bin/ccx with $library"
}

build_objects
link_ccx "$@"
