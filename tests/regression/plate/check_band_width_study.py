#!/usr/bin/env python3
"""mpm/plots/mpm_band_width_study.py on the reduced overlocal deck.

usage: check_band_width_study.py EXE DECK WORKDIR

h = 0.25 m, L = 0.5 and 1.0 m, to 9.5 ms (past both stages, 8.24 and 8.57
ms): the widths normal to the band are the deck's own summary figures
(1.1053 m: plate_convergence_overlocal_reduced), the table and the fit
w = c L are the least squares of the CSV's rows, the plot is written; bad
options and a failing run are refused with a message and exit status 1 or 2.
"""
import csv
import math
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(HERE, "..", "..", "..", "mpm", "plots", "mpm_band_width_study.py")


def study(exe, deck, out, *args):
    shutil.rmtree(out, ignore_errors=True)
    return subprocess.run([sys.executable, SCRIPT, exe, deck, out] + list(args),
                          capture_output=True, text=True, timeout=600)


def main(argv):
    exe, deck, work = argv[1:4]
    fails = []

    def check(cond, what):
        print(("ok   " if cond else "FAIL ") + what)
        if not cond:
            fails.append(what)

    out = os.path.join(work, "width")
    p = study(exe, deck, out, "--dx", "0.25", "--length", "0.5,1.0", "--t-end", "0.0095",
              "--jobs", "2")
    check(p.returncode == 0, f"the study runs (exit {p.returncode}: {p.stderr[-300:]})")
    rows = list(csv.DictReader(open(os.path.join(out, "band_width.csv"))))
    check(len(rows) == 2, "one row per L")
    w = {float(r["L"]): float(r["w"]) for r in rows if r["w"]}
    check(abs(w.get(0.5, 0) - 1.1053) <= 0.0011, f"L = 0.5 m: the deck's width 1.1053 m ({w})")
    check(w.get(1.0, 0) > w.get(0.5, 0) * 1.1, "a longer L gives a wider band")
    for L in w:
        ratio = next(float(r["w_over_L"]) for r in rows if float(r["L"]) == L)
        check(math.isclose(ratio, w[L] / L, rel_tol=1e-9), f"w / L at L = {L}")
    c = sum(L * w[L] for L in w) / sum(L * L for L in w)
    md = open(os.path.join(out, "band_width.md")).read()
    check(f"c = {c:.4f}" in md, f"the fit through the origin is the least squares c = {c:.4f}")
    try:
        import matplotlib  # noqa: F401
        check(os.path.getsize(os.path.join(out, "band_width.png")) > 10000, "the plot")
    except ImportError:
        print("skip the plot (no matplotlib)")

    for args, want, code in [(["--length", "-1"], "must be finite and > 0", 1),
                             (["--dx", "a"], "must be numbers", 1),
                             (["--jobs", "0"], "whole number >= 1", 1),
                             (["--bogus"], "unknown option", 1)]:
        p = study(exe, deck, os.path.join(work, "bad"), *args)
        check(p.returncode == code and want in p.stderr, f"{args} refused: {p.stderr.strip()}")
    p = study(exe, deck, os.path.join(work, "failing"), "--dx", "0.5", "--length", "0.5",
              "time.cfl=-1")
    check(p.returncode == 1 and "failed or missing: L0.5_v7.5" in p.stdout,
          "a failing run is named and fails the study")
    md = open(os.path.join(work, "failing", "band_width.md")).read()
    check(md.startswith("INCOMPLETE: failed or missing runs L0.5_v7.5"),
          "its table says it is incomplete")
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
