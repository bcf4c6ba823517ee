#!/usr/bin/env python3
"""An implicit plate run continued from a checkpoint (--restart-from).

usage: check_implicit_restart.py EXE OUT_DIR

Quasi-static (inputs/implicit_slow_platen_local.nml at h = 0.5 m,
checkpoints every 20 steps): the continued run must finish, and its
summary must say that its implicit keys count the steps since the restart
(h0.5.implicit_since_restart = true; the run's datasets are the first
run's bitwise, which parallel_mpm_keep_checkpoints_* check for the
explicit decks). Newmark (inputs/newmark_platen_local.nml, every 100
steps): refused, exit 1 with the reason (a checkpoint lacks the particles'
accelerations), and nothing written under its output folder.
"""
import glob
import os
import subprocess
import sys

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
    p, refused = continue_run(exe, root, "newmark_platen_local", "100", "nm")
    if p.returncode != 1 or "cannot continue from a checkpoint yet" not in p.stderr:
        bad.append("Newmark's restart was not refused with its reason (exit %d):\n%s"
                   % (p.returncode, p.stderr))
    elif os.path.exists(refused) and os.listdir(refused):
        bad.append("the refused restart wrote %s" % os.listdir(refused))
    else:
        print("Newmark: refused: " + p.stderr.strip().splitlines()[-1])
    for b in bad:
        print("FAIL: " + b)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
