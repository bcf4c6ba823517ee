#!/usr/bin/env python3
"""The rough-platen specimen on two meshes: does the plastic zone follow the mesh?

check_rough_meshes.py --program wellposed-mpm --deck DECK --coarse RUN_DIR
                      --out DIR --dx H (--narrows R | --holds T)

RUN_DIR is DECK's run on its own mesh (inputs/axisymmetric_rough_*.nml,
h = 0.25 m); the deck is run again at cell size H into DIR. For each run
the zone where the cones from the clamped corners meet is measured as
mpm/plots/mpm_axisymmetric.py --compare measures it (the last snapshot's
largest ||eps^p||, the FWHM of ||eps^p|| along the axis and across at its
height). --narrows R: the zone along the axis on the finer mesh must be at
most R times the coarser's (the local softening continuum); --holds T: both
widths and the largest ||eps^p|| must change by at most T relative (the
overlocal one, whose width L sets). Exit status 0 when it holds.
"""
import argparse
import os
import subprocess
import sys

import h5py
import numpy as np

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, "..", "..", "..", "mpm", "plots"))
sys.path.insert(0, os.path.join(here, "..", "..", "..", "common"))
from mpm_axisymmetric import last_snapshot, zone  # noqa: E402
from summary_text import read_summary  # noqa: E402


def measure(run_dir):
    with h5py.File(os.path.join(run_dir, "run.h5"), "r") as h5:
        snap = last_snapshot(h5)
        rz = np.asarray(snap["rz"]).reshape(-1, 2)
        ep = np.asarray(snap["plastic_strain"]).ravel()
    peak, at, along, across = zone(rz, ep, float(read_summary(run_dir)["dx"]))
    print("%s: largest ||eps^p|| %.4f at (%.2f, %.2f) m, FWHM along the axis %.3f m, "
          "across %.3f m" % (run_dir, peak, at[0], at[1], along, across))
    return peak, along, across


def main():
    ap = argparse.ArgumentParser()
    for k in ("--program", "--deck", "--coarse", "--out"):
        ap.add_argument(k, required=True)
    ap.add_argument("--dx", type=float, required=True)
    group = ap.add_mutually_exclusive_group(required=True)
    group.add_argument("--narrows", type=float)
    group.add_argument("--holds", type=float)
    a = ap.parse_args()
    name = "fine"
    with open(os.path.join(a.out + ".log"), "w") as log:
        if subprocess.call([a.program, a.deck, "--out", a.out, "--name", name, "--no-plot",
                            "grid.dx=%g" % a.dx], stdout=log, stderr=subprocess.STDOUT) != 0:
            sys.exit("check_rough_meshes: the run at h = %g m failed (%s.log)" % (a.dx, a.out))
    coarse = measure(a.coarse)
    fine = measure(os.path.join(a.out, name))
    change = [f / c - 1.0 for f, c in zip(fine, coarse)]
    print("finer against coarser: largest ||eps^p|| %+.1f %%, along %+.1f %%, across %+.1f %%"
          % tuple(100.0 * x for x in change))
    if a.narrows is not None:
        ratio = fine[1] / coarse[1]
        if not ratio <= a.narrows:
            sys.exit("check_rough_meshes: the zone along the axis is %.3f of the coarser "
                     "mesh's, not at most %.3f" % (ratio, a.narrows))
    elif not max(abs(x) for x in change) <= a.holds:
        sys.exit("check_rough_meshes: the zone changed by more than %.3f" % a.holds)
    print("check_rough_meshes: ok")


if __name__ == "__main__":
    main()
