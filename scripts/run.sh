#!/usr/bin/env bash
# The main job: install what is missing, build build/ (Release), and run the
# default scene (wellposed-demo). Extra arguments go to the demo.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
cd "${WELLPOSED_ROOT}"

wellposed_setup
wellposed_configure_build

demo="${WELLPOSED_BUILD}/bin/wellposed-demo"
if [[ ! -x "${demo}" ]]; then
  echo "run: ${demo} was not built (no target wellposed-demo; driver/demo not in yet?)" >&2
  exit 1
fi
exec "${demo}" "$@"
