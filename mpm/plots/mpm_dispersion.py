#!/usr/bin/env python3
"""Fig. 2.10 left: the dispersion relation of the overlocal model in
uniaxial strain, from the linearised equations, against wave speeds
measured in the 1D MPM (wellposed-mpm, nonlocal Algorithm 1).

usage: mpm_dispersion.py EXE OUTDIR [--deck DECK] [--freqs F1,F2,...]
                         [--cells N] [--oracle ORACLE]

EXE is wellposed-mpm; ORACLE (default: mpm_dispersion_oracle beside EXE,
built with the tests) prints the library's dispersion relation
(overlocal_uniaxial_modulus: rho c(kappa)^2 is the local uniaxial-strain
plastic modulus with h_eff = h_eta + h_zeta exp(-kappa^2 L^2/(4 k^2)), Di
Luzio and Bazant's perturbation of the Gaussian of eq. 2.15/4.27). DECK
(default inputs/fig2_10_left_overlocal.nml) gives the material, the state
and the load amplitude; for each frequency f the script sizes the scene by
the predicted wavelength lambda = c(f)/f and runs the deck with overrides:

  - load: pulse = 'ramp_sine', sigma_b = base + rate s + A sin(2 pi f s)
    with A from the deck and rate = 2 A (2 pi f): the surface stress rate
    stays between rate/2 and 3 rate/2, never unloading, so every particle the
    ramp has reached keeps loading plastically and the linearisation holds;
  - grid: dx = lambda / N (N = --cells, default 64; at most 0.125 m);
  - stations every lambda/4 from lambda to 4 lambda;
  - t_end = x_last / c_slow + 6 / f, c_slow the slowest group velocity of
    the relation (after it every transient of the ramp's start has passed);
    the body so long that the far end's reflection reaches no station
    before t_end.

The speed is measured from the phase of the drive frequency: at each
station a least-squares fit of a + b t + c t^2 + C cos(w t) + S sin(w t)
over the window t >= x / c_slow + 2 / f, then a straight-line fit of the
unwrapped phase against x, whose slope is -kappa; c = w / kappa. At the
same f and dx the local model with h_eta alone (h_zeta = 0), whose speed
is exactly its plastic wave speed, measures the grid's phase lag.

Writes OUTDIR/dispersion.md (the table), dispersion.csv, dispersion.png
(the curve, its bounds, C_E, the measured speeds as markers) and the runs
under OUTDIR/runs/. The default 8 frequencies take about 8 min on the
shared 2-core machine (45-65 s per overlocal run, 3-10 s per local one).
"""
import csv
import math
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
DEFAULT_DECK = os.path.join(ROOT, "inputs", "fig2_10_left_overlocal.nml")
DEFAULT_FREQS = (250.0, 500.0, 750.0, 1000.0, 1250.0, 1500.0, 2000.0, 3000.0)
#: ramp rate over the largest rate of the sinusoid, rate / (2 pi f A)
RATE_OVER_SINE = 2.0
#: stations from FIRST to LAST wavelengths, every STEP wavelengths
FIRST, LAST, STEP = 1.0, 4.0, 0.25


class RunError(Exception):
    pass


def run_mpm(exe, deck, outdir, name, over):
    """Run wellposed-mpm; returns (folder, wall time of the process in s)."""
    cmd = [exe, "--out", outdir, "--name", name, "--no-plot", deck] + over
    t0 = time.time()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.time() - t0
    if p.returncode != 0:
        raise RunError(" ".join(cmd) + "\n" + p.stdout[-2000:] + p.stderr[-2000:])
    return os.path.join(outdir, name), wall


def scene_of(folder):
    """density, initial stress (Abaqus order; sigma_zz = sigma_yy, the
    uniaxial-strain state of the decks) and PROPS 1-13 of a run."""
    import h5py
    import numpy as np
    with h5py.File(os.path.join(folder, "run.h5"), "r") as f:
        props = np.asarray(f.attrs["props"], dtype=float)
        names = f.attrs["numbers_names"]
        if isinstance(names, bytes):
            names = names.decode()
        nums = dict(zip(names.split(), f.attrs["numbers"]))
        sxx = float(f["stations/sigma_xx"][0, 0])
        syy = float(f["stations/sigma_yy"][0, 0])
        deck = f.attrs["deck"]
        if isinstance(deck, bytes):
            deck = deck.decode()
    p13 = list(props[:13]) + [0.0] * max(0, 13 - len(props))
    return float(nums["density"]), [sxx, syy, syy, 0.0, 0.0, 0.0], p13, deck


def oracle(path, density, stress, props, freqs):
    """The library's dispersion relation: (bounds, rows), bounds =
    (C_E, c low frequency, c high frequency), rows = dicts f, omega, kappa,
    c_phase, c_group per frequency."""
    cmd = [path] + ["%.17g" % v for v in [density] + list(stress) + list(props) + list(freqs)]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        raise RunError(" ".join(cmd) + "\n" + p.stderr)
    bounds, rows = None, []
    for line in p.stdout.splitlines():
        w = line.split()
        if w and w[0] == "bounds":
            bounds = tuple(float(v) for v in w[1:4])
        elif w and w[0] == "f":
            rows.append({w[i]: float(w[i + 1]) for i in range(0, len(w), 2)})
    return bounds, rows


def slowest_group_velocity(path, density, stress, props, f_max):
    """Smallest group velocity of the relation over 0 < f <= 4 f_max."""
    freqs = [4.0 * f_max * (i + 1) / 200.0 for i in range(200)]
    _, rows = oracle(path, density, stress, props, freqs)
    return min(r["c_group"] for r in rows)


def scene_overrides(f, c_pred, c_slow, c_fast, amplitude, cells, name, last=LAST,
                    periods=6.0):
    """Overrides sizing the measurement scene of frequency f (see the module
    doc; `last` wavelengths to the last station, `periods` periods after
    x_last / c_slow); returns (overrides, dx, stations)."""
    lam = c_pred / f
    dx = min(lam / cells, 0.125)
    dx = 1.0e-4 * math.floor(dx / 1.0e-4)
    first = FIRST * lam
    spacing = STEP * lam
    count = int(round((last - FIRST) / STEP)) + 1
    x_last = first + (count - 1) * spacing
    period = 1.0 / f
    t_end = x_last / c_slow + periods * period
    # the far end's reflection reaches x_last at (2 length - x_last)/c_fast
    length = 0.5 * (c_fast * (t_end + period) + x_last)
    ncell = int(math.ceil(length / dx))
    rate = RATE_OVER_SINE * 2.0 * math.pi * f * amplitude
    over = [f"scene.name='{name}'",
            f"grid.dx={dx:.6g}", f"grid.length={ncell * dx:.10g}",
            f"time.t_end={t_end:.6g}",
            "load.pulse='ramp_sine'", f"load.frequency={f:.10g}",
            f"load.amplitude={amplitude:.10g}", f"load.rate={rate:.10g}",
            f"stations.first={first:.10g}", f"stations.spacing={spacing:.10g}",
            f"stations.count={count}",
            f"output.sample_dt={period / 50.0:.6g}"]
    return over, dx, [first + i * spacing for i in range(count)]


def measure(folder, f, c_slow):
    """Phase velocity at frequency f from the station histories of a run:
    returns a dict with c, kappa, the phase residual (rad, RMS about the
    straight line), the least station amplitude over the drive's
    amplitude at the first station, the least sigma_xx rate and the least
    plastic-strain rate over the fit windows (both must stay > 0: the
    particles keep loading)."""
    import h5py
    import numpy as np
    with h5py.File(os.path.join(folder, "run.h5"), "r") as h:
        t = np.asarray(h["stations/time"][()])
        x = np.asarray(h["stations/x"][()])
        s = np.asarray(h["stations/sigma_xx"][()])
        z = np.asarray(h["stations/z"][()])
    w = 2.0 * math.pi * f
    phases, amps, min_rate, min_zrate = [], [], math.inf, math.inf
    for i, xi in enumerate(x):
        m = t >= xi / c_slow + 2.0 / f
        if np.count_nonzero(m) < 20:
            raise RunError(f"station x = {xi:g} m: fewer than 20 samples in its window")
        tt = t[m]
        u = tt - tt[0]
        a = np.column_stack([np.ones_like(tt), u, u * u, np.cos(w * tt), np.sin(w * tt)])
        coef, *_ = np.linalg.lstsq(a, s[i, m], rcond=None)
        phases.append(math.atan2(coef[3], coef[4]))
        amps.append(math.hypot(coef[3], coef[4]))
        dt = np.diff(tt)
        min_rate = min(min_rate, float(np.min(np.diff(s[i, m]) / dt)))
        min_zrate = min(min_zrate, float(np.min(np.diff(z[i, m]) / dt)))
    ph = np.unwrap(np.asarray(phases))
    slope, icpt = np.polyfit(x, ph, 1)
    kappa = -slope
    resid = float(np.sqrt(np.mean((ph - (slope * x + icpt)) ** 2)))
    return {"c": w / kappa, "kappa": kappa, "phase_rms": resid,
            "amp_ratio": min(amps) / amps[0], "min_rate": min_rate, "min_zrate": min_zrate,
            "nstations": len(x)}


def probe(exe, deck, outdir):
    """density, stress, PROPS of the deck, from a run of a few steps (0.1 ms)."""
    folder, _ = run_mpm(exe, deck, outdir, "probe",
                        ["time.t_end=1e-4", "output.sample_dt=1e-4", "stations.first=0.5",
                         "stations.count=1"])
    return scene_of(folder)


def deck_amplitude(deck_text):
    """The &load amplitude (Pa) given in the deck text (comments dropped)."""
    import re
    code = "\n".join(line.split("!", 1)[0] for line in deck_text.splitlines())
    m = re.search(r"\bamplitude\s*=\s*([-+0-9.eEdD]+)", code)
    if not m:
        raise RunError("the deck has no &load amplitude (pulse = 'ramp_sine')")
    return float(m.group(1).replace("d", "e").replace("D", "e"))


def main(argv):
    args = list(argv[1:])
    opts = {"--deck": DEFAULT_DECK, "--freqs": None, "--cells": "64", "--oracle": None}
    pos = []
    while args:
        a = args.pop(0)
        if a in opts:
            if not args:
                sys.stderr.write(f"{a} needs a value\n")
                return 2
            opts[a] = args.pop(0)
        else:
            pos.append(a)
    if len(pos) != 2:
        sys.stderr.write(__doc__)
        return 2
    exe, outdir = os.path.abspath(pos[0]), os.path.abspath(pos[1])
    deck = os.path.abspath(opts["--deck"])
    freqs = [float(v) for v in opts["--freqs"].split(",")] if opts["--freqs"] else \
        list(DEFAULT_FREQS)
    cells = float(opts["--cells"])
    orc = opts["--oracle"] or os.path.join(os.path.dirname(exe), "mpm_dispersion_oracle")
    if not os.path.exists(orc):
        sys.stderr.write(f"{orc} not found: build the tests (BUILD_TESTING=ON) or give "
                         "--oracle\n")
        return 1
    runs = os.path.join(outdir, "runs")
    os.makedirs(runs, exist_ok=True)
    try:
        rows, curve = sweep(exe, deck, runs, orc, freqs, cells)
    except RunError as e:
        sys.stderr.write(f"mpm_dispersion: {e}\n")
        return 1
    write_outputs(outdir, rows, curve)
    return 0


def sweep(exe, deck, runs, orc, freqs, cells):
    """Predict, run and measure every frequency; returns the table rows and
    the dense curve (f, c_phase, c_group) of the relation."""
    import numpy as np
    density, stress, props, deck_text = probe(exe, deck, runs)
    if props[12] <= 0.0 or props[11] == 0.0:
        raise RunError("the deck is not overlocal: give &material h_zeta /= 0 and L > 0")
    amplitude = deck_amplitude(deck_text)
    bounds, pred = oracle(orc, density, stress, props, freqs)
    c_e, c_lo, c_hi = bounds
    c_fast = max(c_lo, c_hi)
    c_slow = min(slowest_group_velocity(orc, density, stress, props, max(freqs)), c_lo, c_hi)
    c_local_exact = c_hi  # the local model with h_eta alone: the high-frequency bound
    rows = []
    for f, pr in zip(freqs, pred):
        tag = f"f{f:g}"
        over, dx, _ = scene_overrides(f, pr["c_phase"], c_slow, c_fast, amplitude, cells,
                                      "overlocal_" + tag)
        folder, wall = run_mpm(exe, deck, runs, "overlocal_" + tag, over)
        meas = measure(folder, f, c_slow)
        over_l = [o for o in over if not o.startswith("scene.name")] + \
            [f"scene.name='local_{tag}'", "material.h_zeta=0"]
        folder_l, wall_l = run_mpm(exe, deck, runs, "local_" + tag, over_l)
        meas_l = measure(folder_l, f, c_slow)
        row = {"f": f, "kappa": pr["kappa"], "c_pred": pr["c_phase"], "c_group": pr["c_group"],
               "c_mpm": meas["c"], "rel": meas["c"] / pr["c_phase"] - 1.0,
               "lag_local": meas_l["c"] / c_local_exact - 1.0, "dx": dx,
               "cells": pr["c_phase"] / f / dx, "phase_rms": meas["phase_rms"],
               "min_rate": meas["min_rate"], "min_zrate": meas["min_zrate"],
               "wall": wall, "wall_local": wall_l,
               "c_e": c_e, "c_lo": c_lo, "c_hi": c_hi}
        rows.append(row)
        print(f"f = {f:7.1f} Hz: c predicted {row['c_pred']:8.2f} m/s, MPM {row['c_mpm']:8.2f} "
              f"({100 * row['rel']:+.3f} %), local h_eta at the same dx: "
              f"{100 * row['lag_local']:+.3f} %, {wall:.1f} s + {wall_l:.1f} s", flush=True)
    dense = list(np.geomspace(min(freqs) / 4.0, max(freqs) * 4.0, 200))
    _, rel = oracle(orc, density, stress, props, dense)
    curve = ([r["f"] for r in rel], [r["c_phase"] for r in rel], [r["c_group"] for r in rel])
    return rows, curve


def write_outputs(outdir, rows, curve):
    keys = ["f", "kappa", "c_pred", "c_group", "c_mpm", "rel", "lag_local", "dx", "cells",
            "phase_rms", "min_rate", "min_zrate", "wall", "wall_local"]
    with open(os.path.join(outdir, "dispersion.csv"), "w", newline="") as f:
        wr = csv.writer(f)
        wr.writerow(keys)
        for r in rows:
            wr.writerow([f"{r[k]:.8g}" for k in keys])
    r0 = rows[0]
    with open(os.path.join(outdir, "dispersion.md"), "w") as f:
        f.write(f"Bounds: local h_eta + h_zeta (low frequency) {r0['c_lo']:.2f} m/s, "
                f"local h_eta (high frequency) {r0['c_hi']:.2f} m/s; C_E = {r0['c_e']:.2f} m/s.\n\n")
        f.write("| f (Hz) | kappa (rad/m) | c predicted (m/s) | c MPM (m/s) | MPM / predicted - 1 "
                "| local h_eta, same dx: MPM / exact - 1 | dx (m) | cells per wavelength "
                "| wall (s) |\n|---|---|---|---|---|---|---|---|---|\n")
        for r in rows:
            f.write(f"| {r['f']:g} | {r['kappa']:.3f} | {r['c_pred']:.2f} | {r['c_mpm']:.2f} | "
                    f"{100 * r['rel']:+.3f} % | {100 * r['lag_local']:+.3f} % | {r['dx']:.4g} | "
                    f"{r['cells']:.0f} | {r['wall']:.0f} |\n")
    plot(outdir, rows, curve)


def plot(outdir, rows, curve):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    r0 = rows[0]
    c_lo, c_hi, c_e = r0["c_lo"], r0["c_hi"], r0["c_e"]
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    fs = np.array([r["f"] for r in rows])
    ax.plot(curve[0], curve[1], "k-", lw=1.5, label="overlocal, linearised (library): phase")
    ax.plot(curve[0], curve[2], "k:", lw=1.0, label="group velocity")
    ax.axhline(c_lo, color="tab:red", ls="--", lw=1.0,
               label=f"local, h_eta + h_zeta ({c_lo:.0f} m/s)")
    ax.axhline(c_hi, color="tab:blue", ls="--", lw=1.0, label=f"local, h_eta ({c_hi:.0f} m/s)")
    ax.axhline(c_e, color="0.5", ls="-.", lw=1.0, label=f"elastic C_E ({c_e:.0f} m/s)")
    ax.plot(fs, [r["c_mpm"] for r in rows], "o", mfc="none", mec="tab:green", ms=7,
            label="MPM, ramp + sinusoid (phase)")
    ax.set_xlabel("frequency f (Hz)")
    ax.set_ylabel("wave speed (m/s)")
    ax.set_xscale("log")
    ax.set_title("Overlocal DP, uniaxial strain: dispersion (fig. 2.10 left)", fontsize=10)
    ax.legend(fontsize=8, loc="lower left", bbox_to_anchor=(0.0, 0.07))
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "dispersion.png"), dpi=150)


if __name__ == "__main__":
    sys.exit(main(sys.argv))
