#!/usr/bin/env python3
"""CalculiX as a host of our UMAT (docs/guide/calculix.md).

Runs the decks of contrib/calculix/decks in ccx and compares, increment by
increment, every integration point's stress with wellposed-point's twin
deck (and our von Mises UMAT with ccx's own *PLASTIC), to the digits ccx
prints: |difference| <= 1e-6 times the largest |component| of that state,
which is one unit in the last of the 7 digits of ccx's .dat file. It also
checks that the decks with invalid or non-finite input do not finish: ccx
exits non-zero and our message appears exactly once. Prints a table with
the Newton iterations per increment (ccx's .sta file); exits 1 on any
failure.

    run_checks.py --ccx CCX --point WELLPOSED_POINT [--work DIR]
"""
import argparse
import csv
import math
import os
import re
import shutil
import subprocess
import sys

DECKS = os.path.join(os.path.dirname(os.path.abspath(__file__)),
                     "..", "..", "..", "contrib", "calculix", "decks")
REL_TOL = 1.0e-6


def run_ccx(ccx, work, job):
    """Run job.inp in work; return (exit code, stdout + stderr)."""
    env = dict(os.environ, OMP_NUM_THREADS="1", CCX_NPROC_STIFFNESS="1",
               CCX_NPROC_RESULTS="1", CCX_NPROC_EQUATION_SOLVER="1")
    proc = subprocess.run([ccx, "-i", job], cwd=work, env=env, capture_output=True,
                          text=True, timeout=300)
    return proc.returncode, proc.stdout + proc.stderr


def read_dat(path, what="stresses"):
    """The blocks of a ccx .dat file whose header starts with `what`
    ("stresses", "internal state variables", "total force"), one per print
    time: {(element, point): values}, or {(0, 0): totals}."""
    blocks, current = [], None
    with open(path) as f:
        for line in f:
            text = line.strip()
            if not text:
                continue
            if text[0].isalpha():
                current = {} if text.startswith(what) else None
                if current is not None:
                    blocks.append(current)
            elif current is not None:
                parts = text.split()
                if what.startswith("total"):
                    current[(0, 0)] = [float(v) for v in parts]
                else:
                    current[(int(parts[0]), int(parts[1]))] = [float(v) for v in parts[2:]]
    return blocks


def read_sta(path):
    """Newton iterations of each converged increment, from ccx's .sta file."""
    its = []
    with open(path) as f:
        for line in f:
            parts = line.split()
            if len(parts) >= 7 and parts[0].isdigit():
                its.append(int(parts[3]))
    return its


def read_point(point, work, deck):
    """Stress rows (s11..s23) of wellposed-point's run of deck, past row 0."""
    subprocess.run([point, os.path.join(work, deck + ".nml"), "--no-plot", "--out", work],
                   check=True, capture_output=True, text=True)
    rows = []
    folder = os.path.join(work, deck)
    name = [f for f in os.listdir(folder) if f.endswith("_path.csv")][0]
    with open(os.path.join(folder, name)) as f:
        for row in csv.DictReader(f):
            if int(row["increment"]) > 0:
                rows.append([float(row[k]) for k in ("s11", "s22", "s33", "s12", "s13", "s23")])
    return rows


def worst(a_blocks, b_blocks):
    """Largest |a - b| / (largest |component| of the state) over all
    increments and points, b_blocks being per-point or one row per increment."""
    if len(a_blocks) != len(b_blocks):
        return math.inf, "%d against %d increments" % (len(a_blocks), len(b_blocks))
    err = 0.0
    for a, b in zip(a_blocks, b_blocks):
        scale = max(max(abs(v) for v in vals) for vals in a.values()) or 1.0
        for key, vals in a.items():
            ref = b[key] if isinstance(b, dict) else b
            err = max(err, max(abs(x - y) for x, y in zip(vals, ref)) / scale)
    return err, ""


def compress(its):
    """Iterations per increment as runs: 1x5 2 3x14."""
    out, i = [], 0
    while i < len(its):
        j = i
        while j < len(its) and its[j] == its[i]:
            j += 1
        out.append("%d" % its[i] if j - i == 1 else "%dx%d" % (its[i], j - i))
        i = j
    return " ".join(out)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--ccx", required=True)
    ap.add_argument("--point", required=True)
    ap.add_argument("--work", default="calculix-checks")
    args = ap.parse_args()
    work = os.path.abspath(args.work)
    shutil.rmtree(work, ignore_errors=True)
    shutil.copytree(DECKS, work)
    table, failed = [], False

    def record(case, err, note, its, ok):
        nonlocal failed
        failed |= not ok
        table.append((case, err, note, compress(its), "ok" if ok else "FAIL"))

    ccx_runs = {}
    for job in ("uniaxial_strain", "exponential", "shear", "triaxial", "triaxial_nonassoc",
                "mises_umat",
                "mises_plastic", "block_umat", "block_plastic"):
        rc, out = run_ccx(args.ccx, work, job)
        ccx_runs[job] = rc
        if rc != 0:
            print("ccx %s failed (%d):\n%s" % (job, rc, out[-2000:]))

    for deck, job in (("uniaxial_strain", "uniaxial_strain"), ("exponential", "exponential"),
                      ("shear", "shear"), ("triaxial", "triaxial"),
                      ("triaxial_nonassoc", "triaxial_nonassoc"), ("mises", "mises_umat"),
                      ("mises", "mises_plastic")):
        if ccx_runs[job] != 0:
            record(job + " vs point", math.inf, "ccx failed", [], False)
            continue
        err, note = worst(read_dat(os.path.join(work, job + ".dat")),
                          read_point(args.point, work, deck))
        record(job + " vs point", err, note, read_sta(os.path.join(work, job + ".sta")),
               err <= REL_TOL)

    # The example umat.f of ccx, linked instead of ours, writes no STATEV:
    # our status slot 12 must be non-zero (plastic, apex) at the end of
    # uniaxial strain.
    if ccx_runs["uniaxial_strain"] == 0:
        sdv = read_dat(os.path.join(work, "uniaxial_strain.dat"), "internal state variables")
        status = sdv[-1][(1, 1)][11] if sdv else math.nan
        ok = status in (1.0, 2.0)
        record("our umat linked (SDV12 > 0)", 0.0 if ok else math.inf,
               "" if ok else "SDV12 = %s: ccx's example umat.f linked instead of ours?" % status,
               [], ok)

    for pair in (("mises_umat", "mises_plastic"), ("block_umat", "block_plastic")):
        if ccx_runs[pair[0]] or ccx_runs[pair[1]]:
            record(" vs ".join(pair), math.inf, "ccx failed", [], False)
            continue
        a, b = (read_dat(os.path.join(work, j + ".dat")) for j in pair)
        err, note = worst(a, b)
        its_a, its_b = (read_sta(os.path.join(work, j + ".sta")) for j in pair)
        if pair[0] == "block_umat":
            fa, fb = (read_dat(os.path.join(work, j + ".dat"), "total force") for j in pair)
            ferr, _ = worst(fa, [blk[(0, 0)] for blk in fb])
            note = "reaction force %.1e" % ferr
            err = max(err, ferr)
        same = its_a == its_b
        if not same:
            note += " iterations differ: *PLASTIC %s" % compress(its_b)
        record(" vs ".join(pair), err, note, its_a, err <= REL_TOL and same)

    # Associative Drucker-Prager in the block: the symmetric tangent must
    # give quadratic convergence, at most 6 iterations per increment.
    rc, _ = run_ccx(args.ccx, work, "block_dp")
    its = read_sta(os.path.join(work, "block_dp.sta")) if rc == 0 else []
    record("block_dp converges", 0.0 if rc == 0 else math.inf, "exit %d" % rc, its,
           rc == 0 and len(its) == 20 and max(its) <= 6)

    for job in ("bad_k0", "no_depvar", "nan_statev"):
        rc, out = run_ccx(args.ccx, work, job)
        n = len(re.findall(r"^wellposed UMAT error", out, re.M))
        finished = "Job finished" in out
        ok = rc != 0 and n == 1 and not finished
        note = "exit %d, our message %d time(s)%s" % (rc, n, ", finished" if finished else "")
        its = read_sta(os.path.join(work, job + ".sta")) if os.path.exists(
            os.path.join(work, job + ".sta")) else []
        record(job + " stops", 0.0 if ok else math.inf, note, its, ok)

    print("CalculiX checks (tolerance %.0e of the state's largest |stress|)" % REL_TOL)
    print("%-28s %-9s %-5s %-22s %s" % ("case", "max diff", "", "iterations/increment", "note"))
    for case, err, note, its, verdict in table:
        print("%-28s %-9s %-5s %-22s %s" % (case, "%.1e" % err if err != math.inf else "-",
                                            verdict, its, note))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
