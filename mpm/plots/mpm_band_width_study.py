#!/usr/bin/env python3
"""What sets the overlocal band width: the plate against L and the platen speed.

usage: mpm_band_width_study.py EXE DECK OUTDIR [--dx 0.0625,0.03125]
                               [--length 0.25,0.5,0.75,1.0] [--velocity 7.5]
                               [--t-end T] [--jobs 1] [--np 1] [--no-run]
                               [group.key=value ...]

Runs wellposed-mpm on the plate DECK (inputs/fig4_4_overlocal_convergence.nml)
once per nonlocal length L (`--length`, m: every &material group's L) and
platen speed (`--velocity`, m/s: top_velocity = -v, t_end and band_time
scaled by v0 / v so every run reaches the same apparent strain, v0 the
deck's speed; `--t-end T` replaces the deck's t_end at v0), each run over the meshes `--dx` (its &study). Reads each
case's band_fwhm_normal (the band's FWHM normal to itself at the stage 5 %
below the peak; docs/research/bands.md) and writes OUTDIR/band_width.md (the
table and the fits), OUTDIR/band_width.csv and OUTDIR/band_width.png (w / L
against L and against v, one line per mesh). The fits, per mesh, at the
deck's speed: w = c L through the origin and w = a + b L by least squares,
with their standard errors. --jobs N runs N runs at a time (wall times then
include the competition for cores), --np N runs each through mpirun -np N,
--no-run reads the run folders already in OUTDIR/runs. Extra overrides go
to every run. Exit status 1 when a run fails or gives no width.
"""
import csv
import math
import os
import re
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "common"))
from summary_text import read_summary  # noqa: E402


def floats(text, what):
    try:
        vals = [float(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise SystemExit(f"mpm_band_width_study.py: {what} must be numbers with commas, "
                         f"got {text!r}")
    if not vals or not all(math.isfinite(v) and v > 0 for v in vals):
        raise SystemExit(f"mpm_band_width_study.py: {what} must be finite and > 0, got {text!r}")
    return vals


def deck_settings(deck):
    """(number of &material groups, top_velocity, t_end, band_time) of DECK."""
    text = open(deck).read()
    body = "\n".join(line.split("!", 1)[0] for line in text.splitlines())
    ngroups = len(re.findall(r"&material\b", body, re.I))

    def key(name, default):
        m = re.search(r"\b" + name + r"\s*=\s*([-+0-9.eEdD]+)", body, re.I)
        return float(m.group(1).lower().replace("d", "e")) if m else default
    return ngroups, key("top_velocity", -7.5), key("t_end", 0.02), key("band_time", 0.0)


def fit_origin(x, y):
    """c and its standard error for y = c x (least squares)."""
    sxx = sum(a * a for a in x)
    c = sum(a * b for a, b in zip(x, y)) / sxx
    n = len(x)
    if n < 2:
        return c, float("nan")
    s2 = sum((b - c * a) ** 2 for a, b in zip(x, y)) / (n - 1)
    return c, math.sqrt(s2 / sxx)


def fit_line(x, y):
    """a, b and their standard errors for y = a + b x (least squares)."""
    n = len(x)
    mx, my = sum(x) / n, sum(y) / n
    sxx = sum((a - mx) ** 2 for a in x)
    b = sum((a - mx) * (c - my) for a, c in zip(x, y)) / sxx
    a = my - b * mx
    if n < 3:
        return a, b, float("nan"), float("nan")
    s2 = sum((c - a - b * t) ** 2 for t, c in zip(x, y)) / (n - 2)
    return a, b, math.sqrt(s2 * (1.0 / n + mx * mx / sxx)), math.sqrt(s2 / sxx)


# The standard deviation of eq. 4.27's Gaussian exp(-(k r / L)^2) over L,
# 1 / (k sqrt 2) with k = (6 sqrt pi)^(1/3) (docs/research/bands.md).
SIGMA_PER_L = 1.0 / ((6.0 * math.sqrt(math.pi)) ** (1.0 / 3.0) * math.sqrt(2.0))


def number(v):
    try:
        return float(v)
    except (TypeError, ValueError):
        return None


def main(argv):
    if len(argv) < 4 or argv[1] in ("-h", "--help"):
        sys.stderr.write(__doc__)
        return 2
    exe, deck, outdir = argv[1:4]
    dxs, lengths, speeds = [0.0625, 0.03125], [0.25, 0.5, 0.75, 1.0], None
    jobs, np_, run, extra, t_end_at_v0 = 1, 1, True, [], None
    rest = argv[4:]
    i = 0
    while i < len(rest):
        a = rest[i]
        if a in ("--dx", "--length", "--velocity", "--jobs", "--np", "--t-end"):
            if i + 1 >= len(rest):
                raise SystemExit(f"mpm_band_width_study.py: {a} needs a value")
            v = rest[i + 1]
            if a == "--dx":
                dxs = floats(v, "--dx")
            elif a == "--length":
                lengths = floats(v, "--length")
            elif a == "--velocity":
                speeds = floats(v, "--velocity")
            elif a == "--t-end":
                t_end_at_v0 = floats(v, "--t-end")[0]
            else:
                if not v.isdigit() or int(v) < 1:
                    raise SystemExit(f"mpm_band_width_study.py: {a} must be a whole number >= 1")
                jobs, np_ = (int(v), np_) if a == "--jobs" else (jobs, int(v))
            i += 2
            continue
        if a == "--no-run":
            run = False
        elif a.startswith("--") or "=" not in a:
            raise SystemExit(f"mpm_band_width_study.py: unknown option {a!r} (see --help)")
        else:
            extra.append(a)
        i += 1
    if not os.path.isfile(deck):
        raise SystemExit(f"mpm_band_width_study.py: no deck {deck}")
    ngroups, v0, t_end, band_time = deck_settings(deck)
    if ngroups < 1:
        raise SystemExit(f"mpm_band_width_study.py: {deck} has no &material group")
    v0 = abs(v0)
    speeds = speeds or [v0]
    t_end = t_end_at_v0 or t_end
    runs = []
    for v in speeds:
        for L in lengths:
            name = f"L{L:g}_v{v:g}"
            args = [f"study.dx={','.join(f'{d:g}' for d in dxs)}"]
            args += [f"material{'' if g == 1 else g}.L={L:g}" for g in range(1, ngroups + 1)]
            s = v0 / v
            if v != v0:
                args.append(f"boundary.top_velocity={-v:g}")
            if v != v0 or t_end_at_v0:
                args.append(f"time.t_end={t_end * s:.6g}")
            if band_time > 0 and (v != v0 or band_time > t_end):
                args.append(f"output.band_time={min(band_time, t_end) * s:.6g}")
            runs.append((name, L, v, args))
    root = os.path.join(outdir, "runs")
    os.makedirs(root, exist_ok=True)
    failed = []
    if run:
        pending, active = list(runs), []
        while pending or active:
            while pending and len(active) < jobs:
                name, L, v, args = pending.pop(0)
                pre = ["mpirun", "--allow-run-as-root", "-np", str(np_)] if np_ > 1 else []
                cmd = pre + [exe, deck, "--out", root, "--name", name, "--no-plot", "--force",
                             "--checkpoint-every", "0"] + args + extra
                log = open(os.path.join(root, name + ".log"), "w")
                print("running", " ".join(cmd), flush=True)
                active.append((name, subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT),
                               log, time.time()))
            time.sleep(0.5)
            for item in list(active):
                name, p, log, t0 = item
                if p.poll() is not None:
                    log.close()
                    active.remove(item)
                    print(f"  {name}: exit {p.returncode}, {time.time() - t0:.1f} s", flush=True)
                    if p.returncode != 0:
                        failed.append(name)
    rows = []
    for name, L, v, _ in runs:
        summ = read_summary(os.path.join(root, name))
        if not summ:
            failed.append(name)
            continue
        for d in dxs:
            h = f"h{d:g}"
            w = number(summ.get(h + ".band_fwhm_normal"))
            stage = number(summ.get(h + ".band_stage_time"))
            rows.append({"L": L, "v": v, "dx": d, "w": w, "w_over_L": None if w is None else w / L,
                         "angle": number(summ.get(h + ".band_angle_deg")),
                         "stage_ms": None if stage is None else stage * 1e3,
                         "peak": number(summ.get(h + ".peak_stress")),
                         "wall": number(summ.get(h + ".wall_time"))})
            if w is None:
                print(f"{name} {h}: no band width ({summ.get(h + '.band_fwhm_normal')})")
    failed = sorted(set(failed))
    write_outputs(outdir, rows, dxs, v0, failed)
    if failed:
        print("failed or missing: " + ", ".join(failed))
    ok = not failed and all(r["w"] is not None for r in rows)
    return 0 if ok else 1


def fmt(x, spec):
    return "-" if x is None else format(x, spec)


def write_outputs(outdir, rows, dxs, v0, failed):
    with open(os.path.join(outdir, "band_width.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()) if rows else ["L"])
        w.writeheader()
        w.writerows(rows)
    lines = [f"INCOMPLETE: failed or missing runs {', '.join(failed)} (their logs in runs/)", ""]
    lines = lines if failed else []
    lines += ["| L (m) | v (m/s) | h (m) | band_fwhm_normal (m) | w / L | angle (deg) "
              "| stage (ms) | peak (MPa) | wall (s) |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['L']:g} | {r['v']:g} | {r['dx']:g} | {fmt(r['w'], '.4f')} | "
                     f"{fmt(r['w_over_L'], '.3f')} | {fmt(r['angle'], '.1f')} | "
                     f"{fmt(r['stage_ms'], '.2f')} | {fmt(r['peak'], '.1f')} | "
                     f"{fmt(r['wall'], '.1f')} |")
    lines.append("")
    for d in dxs:
        pts = [(r["L"], r["w"]) for r in rows if r["dx"] == d and r["v"] == v0 and r["w"]]
        if len(pts) < 2:
            continue
        x, y = zip(*pts)
        c, sc = fit_origin(x, y)
        line = f"h = {d:g} m, v = {v0:g} m/s: w = c L with c = {c:.4f} +- {sc:.4f}"
        if len(pts) >= 3:
            a, b, sa, sb = fit_line(x, y)
            line += f"; w = a + b L with a = {a:.4f} +- {sa:.4f} m, b = {b:.4f} +- {sb:.4f}"
        lines.append(line)
    with open(os.path.join(outdir, "band_width.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))
    plot(outdir, rows, dxs, v0)


def plot(outdir, rows, dxs, v0):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib missing: no band_width.png")
        return
    speeds = sorted({r["v"] for r in rows})
    lengths = sorted({r["L"] for r in rows})
    panels = (["L", "cells"] if len(lengths) > 1 else []) + (["v"] if len(speeds) > 1 else [])
    if not panels:
        print("one L and one speed: no band_width.png")
        return
    fig, axes = plt.subplots(1, len(panels), figsize=(5.5 * len(panels), 4), squeeze=False)
    for ax, panel in zip(axes[0], panels):
        if panel == "cells":
            for L in lengths:
                pts = sorted((SIGMA_PER_L * L / r["dx"], r["w_over_L"]) for r in rows
                             if r["L"] == L and r["v"] == v0 and r["w_over_L"])
                if pts:
                    ax.plot(*zip(*pts), "d-", label=f"L = {L:g} m")
            ax.set_xscale("log")
            ax.set_xlabel("Gaussian's standard deviation L / (k sqrt 2) in cells")
        for d in dxs if panel != "cells" else []:
            if panel == "L":
                pts = sorted((r["L"], r["w_over_L"]) for r in rows
                             if r["dx"] == d and r["v"] == v0 and r["w_over_L"])
                if pts:
                    ax.plot(*zip(*pts), "o-", label=f"h = {d:g} m")
                continue
            for L in lengths:
                pts = sorted((r["v"], r["w_over_L"]) for r in rows
                             if r["dx"] == d and r["L"] == L and r["w_over_L"])
                if len(pts) > 1:
                    ax.plot(*zip(*pts), "s-", label=f"h = {d:g} m, L = {L:g} m")
        if panel == "L":
            ax.set_xlabel("nonlocal length L (m)")
        if panel != "v":
            ax.set_title(f"platen at {v0:g} m/s")
        if panel == "v":
            ax.set_xlabel("platen speed (m/s)")
        ax.set_ylabel("band FWHM normal to the band / L")
        ax.grid(alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "band_width.png"), dpi=120)


if __name__ == "__main__":
    sys.exit(main(sys.argv))
