#!/usr/bin/env python3
"""Speed against accuracy of wellposed-mpm.

usage: mpm_work_precision.py EXE OUTDIR [--quick] [--resume]

Runs the decks inputs/work_precision_elastic.nml, inputs/work_precision_efr.nml
(the 1D bar) and inputs/work_precision_plate.nml (the plane-strain plate) over
cell sizes dx and CFL fractions and reports, per run, the wall time of the
time loop (summary.txt wall_time) and an error:
  - elastic: relative L2 error of the station histories of sigma_xx against
    d'Alembert, sigma_b(t - x / C_E) (raised cosine);
  - EFR: RMS difference of the station histories to a reference run of the
    same deck at dx = 0.0625 m, CFL 0.1, over the load peak (no closed form;
    the pulse decays to ~1 % of the load by 100 m, so a relative norm would
    divide by almost nothing);
  - plate: RMS difference of the applied stress history (the case's
    _curve.csv, interpolated to the reference's times) to a reference run at
    dx = 0.0625 m, CFL 0.1, over the reference's largest applied stress.
Writes OUTDIR/work_precision.md (one table), .csv and .png (error against
wall time, one panel per case, one line per CFL fraction, dx along each
line). --quick: coarser meshes and references (a check of the script).
--resume: a run whose folder in OUTDIR already holds a summary.txt is not
run again (its figures and wall time are read from it), so an interrupted
study goes on where it stopped.
"""
import csv
import math
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
RESUME = False
ROOT = os.path.abspath(os.path.join(HERE, "..", "..", ".."))


def run(exe, deck, outdir, name, over):
    folder = os.path.join(outdir, name)
    if not (RESUME and os.path.exists(os.path.join(folder, "summary.txt"))):
        cmd = [exe, "--out", outdir, "--name", name, "--no-plot", deck] + over
        p = subprocess.run(cmd, capture_output=True, text=True)
        if p.returncode != 0:
            sys.stderr.write(p.stderr)
            raise SystemExit(1)
    vals = {}
    with open(os.path.join(folder, "summary.txt")) as f:
        for line in f:
            line = line.split("#", 1)[0]
            if "=" in line:
                k, v = line.split("=", 1)
                vals[k.strip()] = v.strip()
    wall = vals.get("wall_time", vals.get("total_wall_time"))
    return folder, float(wall)


def histories(folder):
    import h5py
    import numpy as np
    with h5py.File(os.path.join(folder, "run.h5"), "r") as f:
        t = np.asarray(f["stations/time"][()])
        x = np.asarray(f["stations/x"][()])
        s = np.asarray(f["stations/sigma_xx"][()])
        names = f.attrs["numbers_names"]
        if isinstance(names, bytes):
            names = names.decode()
        nums = dict(zip(names.split(), f.attrs["numbers"]))
    return t, x, s - s[:, :1], nums


def dalembert_error(folder):
    import numpy as np
    t, x, ds, nums = histories(folder)
    c, peak, dur = nums["c_elastic"], nums["load_peak"], nums["load_duration"]
    e2 = r2 = 0.0
    for i, xi in enumerate(x):
        u = np.clip((t - xi / c) / dur, 0.0, 1.0)
        exact = peak * 0.5 * (1.0 - np.cos(2.0 * np.pi * u))
        e2 += float(np.sum((ds[i] - exact) ** 2))
        r2 += float(np.sum(exact ** 2))
    return math.sqrt(e2 / r2)


def ref_error(folder, ref):
    import numpy as np
    _, _, ds, nums = histories(folder)
    _, _, dr, _ = ref
    n = min(ds.shape[1], dr.shape[1])
    return math.sqrt(float(np.mean((ds[:, :n] - dr[:, :n]) ** 2))) / abs(nums["load_peak"])


def plate_curve(folder):
    import glob
    import numpy as np
    path = glob.glob(os.path.join(folder, "*_curve.csv"))[0]
    d = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return d[:, 0], d[:, 2]


def plate_error(folder, ref):
    import numpy as np
    t, s = plate_curve(folder)
    tr, sr = ref
    keep = tr <= t[-1]
    return math.sqrt(float(np.mean((np.interp(tr[keep], t, s) - sr[keep]) ** 2))) / \
        float(np.max(np.abs(sr)))


def main(argv):
    if len(argv) < 3:
        sys.stderr.write(__doc__)
        return 2
    exe, outdir = argv[1], argv[2]
    global RESUME
    quick = "--quick" in argv
    RESUME = "--resume" in argv
    os.makedirs(outdir, exist_ok=True)
    cfls = [0.1, 0.2, 0.5, 0.9]
    rows = []
    deck = os.path.join(ROOT, "inputs", "work_precision_elastic.nml")
    for dx in ([0.2, 0.1] if quick else [0.2, 0.1, 0.05, 0.025]):
        for cfl in cfls:
            name = f"elastic_dx{dx:g}_cfl{cfl:g}"
            folder, wall = run(exe, deck, outdir, name, [f"grid.dx={dx:g}", f"time.cfl={cfl:g}"])
            rows.append(("elastic", dx, cfl, wall, dalembert_error(folder)))
            print(*rows[-1], flush=True)
    deck = os.path.join(ROOT, "inputs", "work_precision_efr.nml")
    rdx = 0.25 if quick else 0.0625
    folder, wall = run(exe, deck, outdir, "efr_reference", [f"grid.dx={rdx:g}", "time.cfl=0.1"])
    ref = histories(folder)
    print("efr reference", rdx, 0.1, wall, flush=True)
    for dx in ([1.0, 0.5] if quick else [1.0, 0.5, 0.25, 0.125]):
        for cfl in cfls:
            name = f"efr_dx{dx:g}_cfl{cfl:g}"
            folder, wall = run(exe, deck, outdir, name, [f"grid.dx={dx:g}", f"time.cfl={cfl:g}"])
            rows.append(("efr", dx, cfl, wall, ref_error(folder, ref)))
            print(*rows[-1], flush=True)
    deck = os.path.join(ROOT, "inputs", "work_precision_plate.nml")
    pdx = 0.125 if quick else 0.0625
    folder, wall = run(exe, deck, outdir, "plate_reference", [f"grid.dx={pdx:g}", "time.cfl=0.1"])
    pref = plate_curve(folder)
    print("plate reference", pdx, 0.1, wall, flush=True)
    pcfls = [0.1, 0.2, 0.5]
    for dx in ([0.5, 0.25] if quick else [0.5, 0.25, 0.125]):
        for cfl in pcfls:
            name = f"plate_dx{dx:g}_cfl{cfl:g}"
            folder, wall = run(exe, deck, outdir, name, [f"grid.dx={dx:g}", f"time.cfl={cfl:g}"])
            rows.append(("plate", dx, cfl, wall, plate_error(folder, pref)))
            print(*rows[-1], flush=True)
    with open(os.path.join(outdir, "work_precision.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["case", "dx_m", "cfl", "wall_s", "error"])
        w.writerows(rows)
    with open(os.path.join(outdir, "work_precision.md"), "w") as f:
        f.write("| case | dx (m) | CFL | wall (s) | error (elastic: rel. L2 vs d'Alembert; "
                "EFR: RMS vs reference / load peak; plate: RMS of the applied stress vs "
                "reference / its peak) |\n|---|---|---|---|---|\n")
        for case, dx, cfl, wall, e in rows:
            f.write(f"| {case} | {dx:g} | {cfl:g} | {wall:.3f} | {e:.3e} |\n")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, axs = plt.subplots(1, 3, figsize=(15, 4.2))
        for ax, case in zip(axs, ["elastic", "efr", "plate"]):
            for cfl in cfls:
                pts = [(wall, e) for c, dx, cf, wall, e in rows if c == case and cf == cfl]
                if pts:
                    ax.loglog(*zip(*sorted(pts)), "o-", label=f"CFL {cfl:g}")
            ax.set_xlabel("wall time of the time loop (s)")
            ax.set_ylabel("error of the histories")
            if case == "elastic":
                title = "elastic bar: against d'Alembert"
            elif case == "efr":
                title = f"EFR bar: against dx = {rdx:g} m, CFL 0.1"
            else:
                title = f"hardening plate (CPDI): against dx = {pdx:g} m, CFL 0.1"
            ax.set_title(title, fontsize=9)
            ax.grid(alpha=0.3, which="both")
            ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(outdir, "work_precision.png"), dpi=120)
    except ImportError:
        pass
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
