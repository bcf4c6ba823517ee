#!/usr/bin/env python3
"""Mesh study of the Sandler-Rubin wave (fig. 2.9 study).

usage: mpm_mesh_study.py EXE DECK OUTDIR [--dx 2,1,0.5,0.25,0.125] [--models a,b]
                         [--jobs 1] [group.key=value ...]

--jobs N runs N of the independent runs at a time (wall times then include
the competition for cores: compare them only within one --jobs setting).

Runs wellposed-mpm on DECK for every model and cell size dx, then reports,
per model, the norm of the difference between the station histories of
successive resolutions,

    d(dx) = sqrt(mean over stations and samples of
                 (sigma_xx[dx] - sigma_xx[dx/2])^2) / load peak,

(all runs sample the stations at the same times, so no interpolation is
needed). A well-posed model converges: d falls as dx falls. The local
nonassociative model does not: its pulse keeps growing with refinement.
Writes OUTDIR/mesh_study.md (the table), OUTDIR/mesh_study.csv and
OUTDIR/mesh_study.png. Extra group.key=value overrides go to every run.

Models (overrides on top of DECK, the reference-A material):
  nonassociative   beta_p = 0, perfectly plastic (the deck as given)
  elastic          k0 = 1e12 Pa: never yields
  hardening_assoc  beta_p = beta = 0.315, h = +0.5 GPa
  efr              beta_p = beta = 0.315, P_v = 0.5 (section 2.5.2)
  dl_de10          Duvaut-Lions, tau = 10 x 2 ms (high De)
"""
import csv
import math
import os
import subprocess
import sys
import time

MODELS = {
    "nonassociative": [],
    "elastic": ["material.k0=1e12"],
    "hardening_assoc": ["material.beta_p=0.315", "material.h=0.5e9"],
    "efr": ["material.beta_p=0.315", "material.p_v=0.5"],
    "dl_de10": ["material.tau=0.02"],
}


def histories(folder):
    import h5py
    import numpy as np
    with h5py.File(os.path.join(folder, "run.h5"), "r") as f:
        s = np.asarray(f["stations/sigma_xx"][()])
        names = f.attrs["numbers_names"]
        if isinstance(names, bytes):
            names = names.decode()
        nums = dict(zip(names.split(), f.attrs["numbers"]))
    return s, nums


def main(argv):
    if len(argv) < 4:
        sys.stderr.write(__doc__)
        return 2
    exe, deck, outdir = argv[1:4]
    dxs = [2.0, 1.0, 0.5, 0.25, 0.125]
    models = list(MODELS)
    jobs = 1
    extra = []
    k = 4
    while k < len(argv):
        if argv[k] in ("--dx", "--models", "--jobs") and k + 1 >= len(argv):
            sys.stderr.write(f"mpm_mesh_study: {argv[k]} needs a value\n")
            return 2
        if argv[k] == "--dx":
            dxs = [float(v) for v in argv[k + 1].split(",")]
            k += 2
        elif argv[k] == "--models":
            models = argv[k + 1].split(",")
            k += 2
        elif argv[k] == "--jobs":
            jobs = max(1, int(argv[k + 1]))
            k += 2
        elif argv[k].startswith("--"):
            sys.stderr.write(f"mpm_mesh_study: unknown option {argv[k]}\n{__doc__}")
            return 2
        else:
            extra.append(argv[k])
            k += 1
    unknown = [m for m in models if m not in MODELS]
    if unknown:
        sys.stderr.write(f"mpm_mesh_study: unknown model(s) {', '.join(unknown)}; "
                         f"known: {', '.join(MODELS)}\n")
        return 2
    os.makedirs(outdir, exist_ok=True)

    def one_run(model, dx):
        name = f"{model}_dx{dx:g}"
        cmd = [exe, "--out", outdir, "--name", name, "--no-plot", deck,
               f"grid.dx={dx:g}"] + MODELS[model] + extra
        t0 = time.time()
        p = subprocess.run(cmd, capture_output=True, text=True)
        wall = time.time() - t0
        print(f"{model:16s} dx = {dx:6g} m: {'done' if p.returncode == 0 else 'FAILED'} "
              f"in {wall:6.1f} s", flush=True)
        return p, name, wall

    # Independent runs, `jobs` at a time (each run is one process on one core)
    from concurrent.futures import ThreadPoolExecutor
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = {(m, dx): pool.submit(one_run, m, dx) for m in models for dx in dxs}
    rows = []
    import numpy as np
    for model in models:
        prev = None
        for dx in dxs:
            p, name, wall = futures[(model, dx)].result()
            if p.returncode != 0:
                sys.stderr.write(p.stderr)
                return 1
            s, nums = histories(os.path.join(outdir, name))
            d = float("nan")
            if prev is not None:
                n = min(s.shape[1], prev.shape[1])
                d = math.sqrt(float(np.mean((s[:, :n] - prev[:, :n]) ** 2))) / abs(nums["load_peak"])
            peak = float((s - s[:, :1]).max(axis=1)[-1]) / 1e6
            rows.append((model, dx, d, peak, wall))
            print(f"{model:16s} dx = {dx:6g} m: d = {d:.4e}, last-station peak {peak:7.3f} MPa, "
                  f"{wall:6.1f} s", flush=True)
            prev = s
    with open(os.path.join(outdir, "mesh_study.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["model", "dx_m", "diff_to_previous", "peak_last_station_MPa", "wall_s"])
        w.writerows(rows)
    with open(os.path.join(outdir, "mesh_study.md"), "w") as f:
        f.write("| model | dx (m) | d(dx): diff. to dx*2, / load peak | peak at last station (MPa) | wall (s) |\n")
        f.write("|---|---|---|---|---|\n")
        for model, dx, d, peak, wall in rows:
            ds = "-" if math.isnan(d) else f"{d:.3e}"
            f.write(f"| {model} | {dx:g} | {ds} | {peak:.3f} | {wall:.1f} |\n")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6, 4.5))
        for model in models:
            pts = [(dx, d) for m, dx, d, _, _ in rows if m == model and not math.isnan(d)]
            if pts:
                ax.loglog(*zip(*pts), "o-", label=model)
        ax.set_xlabel("dx (m)")
        ax.set_ylabel("||sigma(dx) - sigma(2 dx)|| / load peak")
        ax.set_title("Mesh study: differences between successive resolutions", fontsize=9)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(outdir, "mesh_study.png"), dpi=120)
    except ImportError:
        pass
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
