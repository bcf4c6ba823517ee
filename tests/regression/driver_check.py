#!/usr/bin/env python3
"""Run a driver (wellposed-point, wellposed-mpm) on a deck and check its
outcome: the regressions of tests/regression/point and tests/regression/plate.

usage:
  driver_check.py [--expect FILE ...] [--expect-suffix SUFFIX ...]
                  EXE DECK RUN_NAME [--no-plot] [--png NAME ...] [--arg ARG ...] CHECK ...
      CHECK is key=expected:tolerance (absolute), or key=word (true, false,
      usl: the summary's value exactly);
      runs in the current folder, reads out/RUN_NAME/summary.txt. The run
      folder must hold summary.txt, the deck, every --expect FILE and a file
      ending in every --expect-suffix (e.g. the XDMF beside the HDF5).
      --arg ARG passes ARG to the driver (an override, --name NAME).
  driver_check.py --fail REGEX EXE DECK RUN_NAME [ARG ...]
      the run (with the extra command-line ARGs) must exit non-zero, print
      REGEX (Python re) on stderr and leave no finished folder out/RUN_NAME.
"""
import os
import re
import shutil
import subprocess
import sys


def run(exe, deck, extra):
    p = subprocess.run([exe, deck] + extra, capture_output=True, text=True, timeout=600)
    return p.returncode, p.stdout, p.stderr


def summary(path):
    values = {}
    with open(path) as f:
        for line in f:
            line = line.split("#", 1)[0].strip()
            if "=" in line:
                k, v = line.split("=", 1)
                values[k.strip()] = v.strip()
    return values


def main(argv):
    expect, suffixes = [], []
    while argv and argv[0] in ("--expect", "--expect-suffix"):
        (expect if argv[0] == "--expect" else suffixes).append(argv[1])
        argv = argv[2:]
    if argv and argv[0] == "--fail":
        regex, exe, deck, name = argv[1:5]
        shutil.rmtree(os.path.join("out", name), ignore_errors=True)
        rc, out, err = run(exe, deck, ["--no-plot"] + argv[5:])
        ok = True
        if rc == 0:
            print(f"FAIL: exit status 0 for a bad deck {deck}")
            ok = False
        if not re.search(regex, err, re.S):
            print(f"FAIL: stderr does not match {regex!r}:\n{err}")
            ok = False
        if os.path.exists(os.path.join("out", name)):
            print(f"FAIL: a finished-looking folder out/{name} exists")
            ok = False
        print(err.strip())
        return 0 if ok else 1
    exe, deck, name = argv[0:3]
    rest = argv[3:]
    extra, pngs, checks = [], [], []
    i = 0
    while i < len(rest):
        if rest[i] == "--no-plot":
            extra.append("--no-plot")
        elif rest[i] == "--png":
            i += 1
            pngs.append(rest[i])
        elif rest[i] == "--arg":
            i += 1
            extra.append(rest[i])
        else:
            checks.append(rest[i])
        i += 1
    rc, out, err = run(exe, deck, extra)
    print(out)
    if rc != 0:
        print(f"FAIL: exit status {rc}\n{err}")
        return 1
    folder = os.path.join("out", name)
    if os.path.exists(folder + ".partial"):
        print(f"FAIL: {folder}.partial left behind by a successful run")
        return 1
    values = summary(os.path.join(folder, "summary.txt"))
    ok = True
    for c in checks:
        key, want = c.split("=", 1)
        got = values.get(key)
        if got is None:
            print(f"FAIL: {key} missing from summary.txt")
            ok = False
            continue
        if want in ("true", "false") or ":" not in want:
            good = got == want
            print(f"{'ok  ' if good else 'FAIL'} {key} = {got} (expected {want})")
        else:
            exp, tol = (float(x) for x in want.split(":"))
            good = abs(float(got) - exp) <= tol
            print(f"{'ok  ' if good else 'FAIL'} {key} = {got} (expected {exp} +- {tol})")
        ok = ok and good
    for p in pngs:
        path = os.path.join(folder, p)
        if not os.path.exists(path) or os.path.getsize(path) < 10000:
            print(f"FAIL: plot {path} missing or empty")
            ok = False
    for f in ["summary.txt", os.path.basename(deck)] + expect:
        if not os.path.exists(os.path.join(folder, f)):
            print(f"FAIL: {f} missing from {folder}")
            ok = False
    for suffix in suffixes:
        if not any(x.endswith(suffix) for x in os.listdir(folder)):
            print(f"FAIL: no file ending in {suffix} in {folder}")
            ok = False
    if ".xdmf" in suffixes:
        import xdmf_check
        for msg in xdmf_check.problems(folder):
            print("FAIL: " + msg)
            ok = False
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
