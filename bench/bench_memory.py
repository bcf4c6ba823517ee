#!/usr/bin/env python3
"""Memory per particle of an MPM deck, at the margin, against 1 kB.

usage: bench_memory.py PROGRAM [DECK] [--dx DX] [--out DIR]

Runs DECK (default: inputs/sandler_rubin_default.nml, the default scene) at
its grid and at half its cell size (--dx DX: the coarser cell, default
0.25 m), with its outputs (snapshots and checkpoints) and without them
(output.snapshot_dt=0 --checkpoint-every 0), and reads each summary's
particles and bytes_per_particle (the growth of the peak resident size
over the run, every buffer counted). The slope between the two particle
counts is what a particle costs; the intercept is what does not grow with
them (the libraries' buffers and code pages, the grid, the histories).
Prints the CPU (lscpu) and one row per case; no pass or fail.
"""
import argparse
import os
import subprocess
import sys

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(here)
sys.path.insert(0, os.path.join(root, "common"))
from summary_text import read_summary  # noqa: E402
TARGET = 1024.0


def cpu():
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
    except OSError:
        return "unknown (no lscpu)"
    for line in out.splitlines():
        if line.startswith("Model name:"):
            return line.split(":", 1)[1].strip()
    return "unknown"


def run(program, deck, out, name, extra):
    cmd = [program, deck, "--out", out, "--name", name, "--no-plot"] + extra
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("bench_memory: %s failed (exit %d): %s"
                 % (" ".join(cmd), p.returncode, p.stderr.strip()[-400:]))
    s = read_summary(os.path.join(out, name))
    if "particles" not in s or "bytes_per_particle" not in s:
        sys.exit("bench_memory: %s has no particles or bytes_per_particle"
                 % os.path.join(out, name, "summary.txt"))
    n = int(s["particles"])
    return n, int(s["bytes_per_particle"]) * n


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("program")
    ap.add_argument("deck", nargs="?",
                    default=os.path.join(root, "inputs", "sandler_rubin_default.nml"))
    ap.add_argument("--dx", type=float, default=0.25)
    ap.add_argument("--out", default="out/bench_memory")
    a = ap.parse_args()
    if not (a.dx > 0.0 and a.dx < 1e3):
        sys.exit("bench_memory: --dx must be a cell size in m, above 0, not %r" % a.dx)
    if not os.path.isfile(a.deck):
        sys.exit("bench_memory: no deck %s" % a.deck)
    print("bench_memory: %s at dx = %g and %g m (CPU: %s)"
          % (os.path.basename(a.deck), a.dx, a.dx / 2, cpu()))
    print("  %-12s %17s %21s %12s %11s %7s" % ("case", "particles", "growth (B)",
                                             "B/particle", "fixed (MB)", "/1 kB"))
    cases = [("outputs on", []),
             ("outputs off", ["output.snapshot_dt=0", "--checkpoint-every", "0"])]
    for label, extra in cases:
        rows = []
        for k, dx in enumerate((a.dx, a.dx / 2)):
            name = "%s_%d" % (label.replace(" ", "_"), k)
            rows.append(run(a.program, a.deck, a.out, name, extra + ["grid.dx=%r" % dx]))
        (n1, g1), (n2, g2) = rows
        slope = (g2 - g1) / (n2 - n1)
        fixed = g1 - slope * n1
        print("  %-12s %8d / %-8d %10d / %-10d %12.0f %11.1f %7.2f"
              % (label, n1, n2, g1, g2, slope, fixed / 1e6, slope / TARGET))
    print("  (growth: the summary's bytes_per_particle times the particles; B/particle: the"
          " slope between the two runs, at the margin; target 1 kB)")


if __name__ == "__main__":
    main()
