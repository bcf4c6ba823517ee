#!/usr/bin/env python3
"""The axisymmetric kind against a closed form, under refinement.

check_closed_form.py --form lame|hill --program wellposed-mpm --deck DECK --out DIR
                     --dx H1 H2 [...] --stress-bound B1 B2 [...] --hoop-bound C1 C2 [...]
                     --min-order P [--u-bound U] [--radius-tol R] [--override KEY=VALUE ...]

Runs DECK once per cell size H (overrides grid.dx=H, --no-plot) into DIR and
reads each summary.txt: <form>_stress_error (relative L2 of the normal
stresses) and <form>_hoop_error (of sigma_tt) must stay within their
bounds and fall at least at order P from each mesh to the next (log2 of
the ratio per halving); Lame: lame_u_outer_error within U; Hill: the
MPM's plastic radius within R of the exact one. Exit status 0 when all hold.
"""
import argparse
import math
import os
import subprocess
import sys
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..",
                                "common"))
from summary_text import read_summary  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--form", choices=("lame", "hill"), required=True)
    ap.add_argument("--program", required=True)
    ap.add_argument("--deck", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--dx", type=float, nargs="+", required=True)
    ap.add_argument("--stress-bound", type=float, nargs="+", required=True)
    ap.add_argument("--hoop-bound", type=float, nargs="+", required=True)
    ap.add_argument("--min-order", type=float, required=True)
    ap.add_argument("--u-bound", type=float)
    ap.add_argument("--radius-tol", type=float)
    ap.add_argument("--override", nargs="+", default=[])
    a = ap.parse_args()
    if not (len(a.dx) == len(a.stress_bound) == len(a.hoop_bound)):
        sys.exit("check_closed_form.py: give one stress and one hoop bound per --dx")
    if (a.form == "lame") != (a.u_bound is not None) or \
            (a.form == "hill") != (a.radius_tol is not None):
        sys.exit("check_closed_form.py: --u-bound goes with lame, --radius-tol with hill")
    bad, rows = [], []
    for h in a.dx:
        name = "%s_dx%g" % (a.form, h)
        p = subprocess.run([a.program, a.deck, "--out", a.out, "--name", name, "--no-plot",
                            "grid.dx=%r" % h] + a.override, capture_output=True, text=True)
        if p.returncode != 0:
            sys.exit("run at dx = %g failed:\n%s%s" % (h, p.stdout, p.stderr))
        s = read_summary(os.path.join(a.out, name))
        rows.append((h, float(s[a.form + "_stress_error"]), float(s[a.form + "_hoop_error"]), s))
    for (h, es, eh, s), bs, bh in zip(rows, a.stress_bound, a.hoop_bound):
        line = "dx = %-8g stress %.4f (<= %g)  hoop %.4f (<= %g)" % (h, es, bs, eh, bh)
        if not es <= bs:
            bad.append("dx = %g: stress error %.4f > %g" % (h, es, bs))
        if not eh <= bh:
            bad.append("dx = %g: hoop error %.4f > %g" % (h, eh, bh))
        if a.form == "lame":
            eu = float(s["lame_u_outer_error"])
            line += "  u_outer %.4f (<= %g)" % (eu, a.u_bound)
            if not eu <= a.u_bound:
                bad.append("dx = %g: outer displacement error %.4f > %g" % (h, eu, a.u_bound))
        else:
            c, cm = float(s["hill_plastic_radius"]), float(s["hill_plastic_radius_mpm"])
            line += "  plastic radius %.4f m (exact %.4f, within %g)" % (cm, c, a.radius_tol)
            if not abs(cm - c) <= a.radius_tol:
                bad.append("dx = %g: plastic radius %.4f m, exact %.4f m" % (h, cm, c))
        print(line)
    for (h1, s1, t1, _), (h2, s2, t2, _) in zip(rows, rows[1:]):
        for what, e1, e2 in (("stress", s1, s2), ("hoop", t1, t2)):
            order = math.log(e1 / e2) / math.log(h1 / h2)
            print("dx %g -> %g: %s error order %.2f (>= %g)" % (h1, h2, what, order, a.min_order))
            if not order >= a.min_order:
                bad.append("%s error order %.2f < %g from dx %g to %g"
                           % (what, order, a.min_order, h1, h2))
    for b in bad:
        print("FAIL " + b)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
