#!/usr/bin/env bash
# The main job: install what is missing, build build/ (Release), and run the
# default scene: `wellposed-mpm` with no deck, i.e. the Sandler-Rubin wave of
# inputs/sandler_rubin_default.nml (fig. 2.3 left). The run is made from
# the repository root, so its results land in out/sandler_rubin_default/
# of the repository (summary.txt, run.h5, stations.png) wherever this script
# is called from. Extra arguments go to wellposed-mpm (a deck, overrides
# group.key=value, --out ROOT, --no-plot).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
cd "${WELLPOSED_ROOT}"

wellposed_setup
wellposed_configure_build

mpm="${WELLPOSED_BUILD}/bin/wellposed-mpm"
if [[ ! -x "${mpm}" ]]; then
  echo "run: ${mpm} was not built (no target wellposed-mpm; mpm not configured?)" >&2
  exit 1
fi
exec "${mpm}" "$@"
