#!/usr/bin/env python3
"""An implicit plate run continued from a checkpoint (--restart-from).

usage: check_implicit_restart.py EXE OUT_DIR

Quasi-static (inputs/implicit_slow_platen_local.nml at h = 0.5 m,
checkpoints every 20 steps): the continued run must finish, and its
summary must say that its implicit keys count the steps since the restart
(h0.5.implicit_since_restart = true; the run's datasets are the first
run's bitwise, which parallel_mpm_keep_checkpoints_* check for the
explicit decks). Newmark (inputs/newmark_platen_local.nml, every 100
steps; the checkpoints carry the particles' accelerations): continued from
step 300, every run.h5 dataset bitwise the uninterrupted run's and the
summary saying so; the same checkpoint continued by the quasi-static
scheme is refused with the reason (its particles carry accelerations).
"""
import glob
import os
import subprocess
import sys

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
INPUTS = os.path.join(HERE, "..", "..", "..", "inputs")


def run(exe, deck, out, *extra):
    return subprocess.run([exe, os.path.join(INPUTS, deck), "--out", out, "--no-plot",
                           "grid.dx=0.5"] + list(extra), capture_output=True, text=True)


def newest_checkpoint(out, name):
    files = sorted(glob.glob(os.path.join(out, name + ".checkpoints", "*.h5")))
    if not files:
        sys.exit("FAIL: %s kept no checkpoint" % out)
    return files[-1]


def continue_run(exe, root, name, every, tag):
    """Run deck NAME with checkpoints every EVERY steps into ROOT/TAG_first,
    then continue from its newest into ROOT/TAG_again: (process, folder)."""
    first = run(exe, name + ".nml", os.path.join(root, tag + "_first"), "--checkpoint-every",
                every, "--keep-checkpoints")
    if first.returncode != 0:
        sys.exit("FAIL: the %s run failed:\n%s" % (name, first.stderr))
    again = os.path.join(root, tag + "_again")
    return run(exe, name + ".nml", again, "--restart-from",
               newest_checkpoint(os.path.join(root, tag + "_first"), name)), again


def main(argv):
    if len(argv) != 3:
        print(__doc__)
        return 2
    exe, root = argv[1], argv[2]
    subprocess.run(["rm", "-rf", root])
    bad = []
    name = "implicit_slow_platen_local"
    p, again = continue_run(exe, root, name, "20", "qs")
    summary = os.path.join(again, name, "summary.txt")
    if p.returncode != 0 or not os.path.exists(summary):
        bad.append("the continued quasi-static run failed:\n" + p.stderr)
    else:
        with open(summary, encoding="utf-8") as f:
            text = f.read()
        if "h0.5.implicit_since_restart = true" not in text:
            bad.append("the continued run's summary does not say its implicit keys count "
                       "the steps since the restart")
        else:
            print("quasi-static: continued, the summary says so")
    name = "newmark_platen_local"
    p, again = continue_run(exe, root, name, "100", "nm")
    if p.returncode != 0:
        bad.append("the continued Newmark run failed:\n" + p.stderr)
    else:
        a = h5py.File(os.path.join(root, "nm_first", name, "run.h5"), "r")
        b = h5py.File(os.path.join(again, name, "run.h5"), "r")
        names = []
        a.visit(lambda n: names.append(n) if isinstance(a[n], h5py.Dataset) else None)
        differ = [n for n in names if n not in b or a[n].shape != b[n].shape
                  or not np.array_equal(a[n][()], b[n][()])]
        with open(os.path.join(again, name, "summary.txt"), encoding="utf-8") as f:
            said = "h0.5.implicit_since_restart = true" in f.read()
        if differ or not said:
            bad.append("the continued Newmark run differs in %s%s" % (
                differ[:5], "" if said else "; its summary does not say it continued"))
        else:
            print("Newmark: continued, %d datasets bitwise the uninterrupted run's" % len(names))
    ck = newest_checkpoint(os.path.join(root, "nm_first"), name)
    p = run(exe, name + ".nml", os.path.join(root, "nm_static"), "time.scheme=implicit",
            "--restart-from", ck)
    if p.returncode != 1 or "acceleration components" not in p.stderr:
        bad.append("the quasi-static scheme continued a Newmark checkpoint (exit %d):\n%s"
                   % (p.returncode, p.stderr))
    else:
        print("quasi-static from a Newmark checkpoint: refused: "
              + p.stderr.strip().splitlines()[0])
    for b in bad:
        print("FAIL: " + b)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
