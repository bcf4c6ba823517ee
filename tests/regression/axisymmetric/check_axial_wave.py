#!/usr/bin/env python3
"""An elastic step wave along the axis of a laterally confined column.

check_axial_wave.py RUN_DIR --velocity V --plateau-tol T --front-tol F

Reads RUN_DIR/run.h5 and summary.txt of inputs/axisymmetric_axial_wave.nml
(the top pushed at V m/s): in every snapshot after the first, behind the
front (z above the front by 2 m and more), sigma_zz must equal the 1D
bar's -rho c |V| (c = sqrt(M/rho), M = K + 4G/3 from the deck's material)
within T relative; the half-level of sigma_zz must lie within F metres of
the front z = H - c t; sigma_rr and sigma_tt must be nu/(1 - nu) sigma_zz
(uniaxial strain: the hoop strain and the axis exact) within 1e-6
relative wherever sigma_zz is above 1 % of the plateau.
Exit status 0 when all hold.
"""
import argparse
import math
import os
import re
import sys

import h5py
import numpy as np


def deck_value(text, key):
    m = re.search(r"\b%s\s*=\s*([-+0-9.eE]+)" % key, text)
    return float(m.group(1))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("run_dir")
    ap.add_argument("--velocity", type=float, required=True)
    ap.add_argument("--plateau-tol", type=float, required=True)
    ap.add_argument("--front-tol", type=float, required=True)
    a = ap.parse_args()
    with h5py.File(os.path.join(a.run_dir, "run.h5"), "r") as h5:
        deck = h5.attrs["deck"]
        deck = deck.decode() if isinstance(deck, bytes) else str(deck)
        rho, k, g = (deck_value(deck, w) for w in ("density", "K", "G"))
        height = deck_value(deck, "height")
        m = k + 4.0 * g / 3.0
        c = math.sqrt(m / rho)
        plateau = -rho * c * abs(a.velocity)
        ratio = (k - 2.0 * g / 3.0) / m
        snaps = h5["snapshots"]
        names = sorted(snaps.keys(), key=lambda s: int(s.split("_")[1]))[1:]
        bad = []
        for name in names:
            s = snaps[name]
            t = float(s["time"][0])
            z = np.asarray(s["rz"]).reshape(-1, 2)[:, 1]
            zz = np.asarray(s["sigma_zz"]).ravel()
            rr = np.asarray(s["sigma_rr"]).ravel()
            tt = np.asarray(s["sigma_tt"]).ravel()
            front = height - c * t
            behind = z > front + 2.0
            mean = zz[behind].mean()
            o = np.argsort(z)
            zs, vs = z[o], zz[o]
            half = np.nonzero(vs < 0.5 * plateau)[0]
            z_half = zs[half[0]] if len(half) else float("nan")
            loaded = np.abs(zz) > 0.01 * abs(plateau)
            lateral = max(np.abs(rr[loaded] / zz[loaded] - ratio).max(),
                          np.abs(tt[loaded] / zz[loaded] - ratio).max()) / ratio
            print("%s t = %.3e s: plateau %.4e Pa (1D %.4e, %.2e rel), half level at z = %.3f m "
                  "(front %.3f m), lateral ratio off by %.1e"
                  % (name, t, mean, plateau, abs(mean / plateau - 1.0), z_half, front, lateral))
            if not abs(mean / plateau - 1.0) <= a.plateau_tol:
                bad.append("%s: plateau %.4e against %.4e" % (name, mean, plateau))
            if not abs(z_half - front) <= a.front_tol:
                bad.append("%s: half level at %.3f m, front at %.3f m" % (name, z_half, front))
            if not lateral <= 1e-6:
                bad.append("%s: sigma_rr/sigma_zz off nu/(1 - nu) by %.1e" % (name, lateral))
    for b in bad:
        print("FAIL " + b)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
