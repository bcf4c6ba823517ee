#!/usr/bin/env python3
"""Station histories of a wellposed-mpm run, like fig. 2.3-2.9.

usage: mpm_stations.py RUN.h5 OUT.png [--reference OTHER.h5 [LABEL]]

Plots the axial stress increment sigma_xx - sigma_xx(0) (MPa, tension
positive) against time (ms) at every station, with the ideal head arrival
x/C_P and tail end x/C_E + tau (thin grey lines; C_E and C_P from the run's
metadata, i.e. the UMAT's moduli at the initial state), and the measured
head and tail of summary.txt (ticks at half the load peak). A reference run, if
given and present, is drawn dashed (the dissertation's convention).
"""
import sys
import os

import h5py
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def load(path):
    with h5py.File(path, "r") as f:
        t = f["stations/time"][()] * 1e3
        x = f["stations/x"][()]
        s = f["stations/sigma_xx"][()]
        names = f.attrs["numbers_names"]
        if isinstance(names, bytes):
            names = names.decode()
        nums = dict(zip(names.split(), f.attrs["numbers"]))
        heads = f["measures/t_head"][()] * 1e3 if "measures/t_head" in f else None
        tails = f["measures/t_tail"][()] * 1e3 if "measures/t_tail" in f else None
        title = f.attrs["title"]
        if isinstance(title, bytes):
            title = title.decode()
    ds = (s - s[:, :1]) / 1e6
    nums["heads"], nums["tails"] = heads, tails
    return t, x, ds, nums, title


def main(argv):
    if len(argv) < 3:
        sys.stderr.write(__doc__)
        return 2
    t, x, ds, nums, title = load(argv[1])
    ref = None
    if "--reference" in argv:
        k = argv.index("--reference")
        rpath = argv[k + 1]
        rlabel = argv[k + 2] if len(argv) > k + 2 else os.path.basename(rpath)
        if os.path.exists(rpath):
            ref = load(rpath), rlabel
    fig, ax = plt.subplots(figsize=(9, 4.8))
    tau = nums["load_duration"] * 1e3
    for i, xi in enumerate(x):
        line, = ax.plot(t, ds[i], lw=1.0, label=f"x = {xi:.0f} m")
        if ref is not None:
            (rt, rx, rds, _, _), _ = ref
            if i < len(rx):
                ax.plot(rt, rds[i], "--", lw=0.8, color=line.get_color())
        if nums["heads"] is not None:
            # measured head and tail: half the load peak around the station's peak
            half = 0.5 * nums["load_peak"] / 1e6
            ax.plot([nums["heads"][i], nums["tails"][i]], [half, half], "|",
                    color=line.get_color(), ms=8)
        for tt in (xi / nums["c_plastic"] * 1e3, xi / nums["c_elastic"] * 1e3 + tau):
            ax.axvline(tt, color="0.75", lw=0.5, zorder=0)
    ax.axhline(nums["load_peak"] / 1e6, color="0.5", lw=0.5, ls=":")
    ax.set_xlabel("time (ms)")
    ax.set_ylabel(r"$\sigma_{xx} - \sigma_{xx}^0$ (MPa, tension +)")
    sub = (f"dx = {nums['dx']:g} m, CFL {nums['cfl']:g}; ticks: measured head/tail; grey: x/C_P and x/C_E + tau "
           f"(C_E = {nums['c_elastic']:.0f}, C_P = {nums['c_plastic']:.0f} m/s)")
    if ref is not None:
        sub += f"; dashed: {ref[1]}"
    ax.set_title(title + "\n" + sub, fontsize=9)
    ax.legend(fontsize=8, loc="upper left")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(argv[2], dpi=120)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
