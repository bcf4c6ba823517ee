#!/usr/bin/env python3
"""The axial wave of the axisymmetric column against a run of the 1D bar.

check_axial_wave_bar.py --program wellposed-mpm --axi-deck DECK --bar-deck BAR
                        --out DIR --dx H1 H2 --bound B1 B2 --max-ratio R

Runs the column of DECK (inputs/axisymmetric_axial_wave.nml) with its top
velocity ramped over 1 ms and GIMP shapes, and the bar of BAR (the same
material, surface stress -rho c |v| t / 1 ms, stations at the same depths),
at each cell size H into DIR, and compares the column's sigma_zz histories
at its stations with the bar's sigma_xx at the same depth below the loaded
end (the stations are moved onto the particles: the column's nearest
particle, the bar's bracketing pair at weight 0): the RMS difference over
every station and sample, relative to the largest |sigma|, must stay
within B at each H, and fall by at least the factor R from H1 to H2.
Exit status 0 when all hold.
"""
import argparse
import os
import subprocess
import sys

import h5py
import numpy as np


def run(cmd, log):
    with open(log, "w") as f:
        if subprocess.call(cmd, stdout=f, stderr=subprocess.STDOUT) != 0:
            sys.exit("check_axial_wave_bar: %s failed (log %s)" % (cmd[1], log))


def stations(path, group):
    with h5py.File(path, "r") as h5:
        s = h5["stations"]
        return {k: np.asarray(s[k]) for k in s.keys()}, group


def main():
    ap = argparse.ArgumentParser()
    for k in ("--program", "--axi-deck", "--bar-deck", "--out"):
        ap.add_argument(k, required=True)
    ap.add_argument("--dx", type=float, nargs=2, required=True)
    ap.add_argument("--bound", type=float, nargs=2, required=True)
    ap.add_argument("--max-ratio", type=float, required=True)
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    height, depths = 10.0, np.array([2.5, 5.0, 7.5])
    errors = []
    for h, bound in zip(a.dx, a.bound):
        # the particle nearest each nominal depth: centres at h/4, 3h/4, ...
        # (2 per cell) below the top; the bar's start at the loaded end
        d = (np.floor(depths / (h / 2.0)) + 0.5) * (h / 2.0)
        tag = "h%g" % h
        axi_out, bar_out = (os.path.join(a.out, w + "_" + tag) for w in ("axi", "bar"))
        zs = ", ".join("%.10g" % z for z in height - d)
        run([a.program, a.axi_deck, "--out", axi_out, "--no-plot", "grid.dx=%g" % h,
             "grid.shape=gimp", "boundary.ramp_time=0.001", "stations.r=0, 0, 0",
             "stations.z=" + zs], os.path.join(a.out, "axi_%s.log" % tag))
        run([a.program, a.bar_deck, "--out", bar_out, "--no-plot", "grid.dx=%g" % h,
             "stations.first=%.10g" % d[0], "stations.spacing=2.5"],
            os.path.join(a.out, "bar_%s.log" % tag))
        axi = stations(os.path.join(axi_out, "axisymmetric_axial_wave", "run.h5"), "axi")[0]
        bar = stations(os.path.join(bar_out, "axial_wave_bar", "run.h5"), "bar")[0]
        at_axi = height - axi["z"]
        if not (np.allclose(at_axi, d, atol=1e-9) and np.allclose(bar["x"], d, atol=1e-9)
                and np.allclose(axi["r"], h / 4.0, atol=1e-9)):
            sys.exit("check_axial_wave_bar: stations at depths %s (column), %s (bar), "
                     "wanted %s" % (at_axi, bar["x"], d))
        if axi["time"].shape != bar["time"].shape or np.abs(axi["time"] - bar["time"]).max() > 0:
            sys.exit("check_axial_wave_bar: the two runs sample at different times")
        sa, sb = axi["sigma_zz"], bar["sigma_xx"]
        scale = np.abs(sb).max()
        rms = float(np.sqrt(np.mean((sa - sb) ** 2)) / scale)
        per = [float(np.sqrt(np.mean((sa[i] - sb[i]) ** 2)) / scale) for i in range(len(d))]
        print("h = %g m: largest |sigma| %.4f MPa, RMS difference %.5f of it (stations %s)"
              % (h, scale / 1e6, rms, ", ".join("%.5f" % e for e in per)))
        if not rms <= bound:
            sys.exit("check_axial_wave_bar: RMS difference %.5f above %.5f at h = %g m"
                     % (rms, bound, h))
        errors.append(rms)
    ratio = errors[1] / errors[0]
    print("difference ratio h = %g -> %g m: %.3f (at most %.3f)" % (a.dx[0], a.dx[1], ratio,
                                                                   a.max_ratio))
    if not ratio <= a.max_ratio:
        sys.exit("check_axial_wave_bar: the difference does not fall with the mesh")
    print("check_axial_wave_bar: ok")


if __name__ == "__main__":
    main()
