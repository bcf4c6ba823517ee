#!/usr/bin/env python3
"""The triaxial specimen between frictionless platens against the point path.

check_triaxial.py --mpm wellposed-mpm --point wellposed-point --deck DECK
                  --point-deck POINT_DECK --out DIR --tolerance T --lateral-tol L
                  [-- ARGS]

Runs the axisymmetric DECK (with ARGS) and wellposed-point on POINT_DECK (the
same material, confinement and axial-strain path at one point) into DIR,
then compares the specimen's deviator q = axial - lateral stress
(curve.csv, compression +) with the point's -(s11 - s22) at the same axial
strain (the point's -e11, interpolated), over the specimen's curve: the
largest difference must stay within T of the point's largest q; and the
specimen's lateral stress must stay within L of the confinement (the
point's -s22). Exit status 0 when both hold.
"""
import argparse
import csv
import os
import subprocess
import sys

import numpy as np


def read_csv(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k.strip(): np.array([float(r[k]) for r in rows]) for k in rows[0]}


def main():
    argv = sys.argv[1:]
    extra = []
    if "--" in argv:
        i = argv.index("--")
        argv, extra = argv[:i], argv[i + 1:]
    ap = argparse.ArgumentParser()
    for k in ("--mpm", "--point", "--deck", "--point-deck", "--out"):
        ap.add_argument(k, required=True)
    ap.add_argument("--tolerance", type=float, required=True)
    ap.add_argument("--lateral-tol", type=float, required=True)
    a = ap.parse_args(argv)
    os.makedirs(a.out, exist_ok=True)
    runs = [[a.mpm, a.deck, "--out", a.out, "--name", "specimen", "--no-plot"] + extra,
            [a.point, a.point_deck]]
    for cmd in runs:
        p = subprocess.run(cmd, cwd=a.out, capture_output=True, text=True)
        if p.returncode != 0:
            sys.exit("failed: %s\n%s%s" % (" ".join(cmd), p.stdout, p.stderr))
    mpm = read_csv(os.path.join(a.out, "specimen", "curve.csv"))
    pt = read_csv(os.path.join(a.out, "out", "triaxial_point", "associative_path.csv"))
    e_pt = -pt["e11"]
    q_pt = -(pt["s11"] - pt["s22"])
    o = np.argsort(e_pt)
    e_pt, q_pt, lat_pt = e_pt[o], q_pt[o], -pt["s22"][o]
    strain = mpm["axial_strain"]
    q = mpm["axial_stress_Pa"] - mpm["lateral_stress_Pa"]
    keep = strain <= e_pt[-1]
    diff = np.abs(q[keep] - np.interp(strain[keep], e_pt, q_pt))
    worst = diff.max() / np.abs(q_pt).max()
    j = np.argmax(diff)
    lateral = np.abs(mpm["lateral_stress_Pa"] - lat_pt[0]).max() / lat_pt[0]
    print("specimen against the point path over axial strain 0 .. %.4f: largest deviator "
          "difference %.3e of the point's peak %.4e Pa (at strain %.4f); lateral stress "
          "within %.3e of %.4e Pa" % (strain[keep].max(), worst, np.abs(q_pt).max(),
                                      strain[keep][j], lateral, lat_pt[0]))
    bad = []
    if not worst <= a.tolerance:
        bad.append("deviator off the point path by %.3e > %g" % (worst, a.tolerance))
    if not lateral <= a.lateral_tol:
        bad.append("lateral stress off the confinement by %.3e > %g" % (lateral, a.lateral_tol))
    for b in bad:
        print("FAIL " + b)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
