#!/usr/bin/env bash
# Install what is missing, build build/ (Release), run the whole test suite.
# The exit code is ctest's. Extra arguments go to ctest (e.g. -R host).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
cd "${WELLPOSED_ROOT}"

wellposed_setup
wellposed_configure_build

exec ctest --test-dir "${WELLPOSED_BUILD}" --output-on-failure -j2 "$@"
