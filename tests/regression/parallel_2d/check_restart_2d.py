#!/usr/bin/env python3
"""Kill -9 + --restart equals the uninterrupted run, for wellposed-mpm2d.

check_restart_2d.py --program wellposed-mpm2d --deck DECK --out DIR
                    [--launcher "mpirun --oversubscribe -np 2"]
                    [--restart-launcher "..."] [--every STEPS] [--kill-at STEP]
                    [--tolerance T] -- [ARGS]

Runs DECK uninterrupted into DIR/ref, then again into DIR/run in its own
session, kills every process of the session (launcher and ranks) with
SIGKILL as soon as a checkpoint of step STEP or later exists (steps count
over the cases of a deck; the newest checkpoint is always kept, so no poll
can miss it), runs it again with --restart (under --restart-launcher when
given, e.g. on another number of ranks), checks that it continued from a
checkpoint, and compares every run.h5 dataset (bitwise unless
a tolerance is given; then relative to the dataset's largest magnitude),
the CSV and XDMF files, and summary.txt but for its timing lines (wall
times and the measured cost of a nonlocal sweep).
Exit status 0 when equal. (The 1D program's test is
tests/regression/parallel/check_restart.py; this one also counts
checkpoints across the cases of a deck.)
"""
import argparse, glob, os, re, shlex, signal, subprocess, sys, time
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..'))
from rank_launch import kill_session, run  # noqa: E402
import h5py, numpy as np

ap = argparse.ArgumentParser()
ap.add_argument('--launcher', default='')
ap.add_argument('--restart-launcher', default=None)
ap.add_argument('--program', required=True)
ap.add_argument('--deck', required=True)
ap.add_argument('--out', required=True)
ap.add_argument('--every', default='100')
ap.add_argument('--kill-at', type=int, required=True)
ap.add_argument('--tolerance', type=float, default=0.0)
ap.add_argument('args', nargs='*')
a = ap.parse_args()
name = re.search(r"name\s*=\s*'([^']+)'", open(a.deck).read()).group(1)
launch = shlex.split(a.launcher)
relaunch = shlex.split(a.restart_launcher) if a.restart_launcher is not None else launch
common = ['--no-plot', '--checkpoint-every', a.every, a.deck] + a.args


subprocess.run(['rm', '-rf', a.out])
ref, out = os.path.join(a.out, 'ref'), os.path.join(a.out, 'run')
run(launch + [a.program, '--out', ref] + common)
proc = subprocess.Popen(launch + [a.program, '--out', out] + common, stdout=subprocess.DEVNULL,
                        stderr=subprocess.DEVNULL, start_new_session=True)
ckdir = os.path.join(out, name + '.checkpoints')
deadline = time.time() + 120
while True:
    steps = [int(os.path.basename(p)[11:21])
             for p in glob.glob(os.path.join(ckdir, 'checkpoint_??????????.h5'))]
    if steps and max(steps) >= a.kill_at:
        break
    if proc.poll() is not None:
        sys.exit('FAIL: the run ended before a checkpoint of step %d: use a longer run'
                 % a.kill_at)
    if time.time() > deadline:
        sys.exit('FAIL: no checkpoint of step %d within 120 s' % a.kill_at)
    time.sleep(0.005)
kill_session(proc.pid)
proc.wait()
if os.path.exists(os.path.join(out, name)):
    sys.exit('FAIL: the killed run left a finished-looking folder')
text = run(relaunch + [a.program, '--out', out, '--restart'] + common)
resumed = [l.strip() for l in text.splitlines() if 'restarted from' in l or 'continuing at' in l]
fa = h5py.File(os.path.join(ref, name, 'run.h5'))
fb = h5py.File(os.path.join(out, name, 'run.h5'))
names = []
fa.visit(lambda n: names.append(n) if isinstance(fa[n], h5py.Dataset) else None)
bad = [] if any('continuing at' in l for l in resumed) else ['(the restart did not resume)']
for n in names:
    if n not in fb:
        bad.append(n + ' (missing)')
        continue
    x, y = fa[n][()], fb[n][()]
    if x.shape != y.shape:
        bad.append(n + ' (shape)')
        continue
    if a.tolerance == 0.0:
        same = x.tobytes() == y.tobytes()
    else:
        s = np.max(np.abs(x)) if x.size else 0.0
        same = s == 0 or bool(np.max(np.abs(x - y)) <= a.tolerance * s)
    if not same:
        bad.append(n)
others = []
fb.visit(lambda n: others.append(n) if isinstance(fb[n], h5py.Dataset) else None)
bad += [n + ' (extra)' for n in others if n not in names]


def summary(d):
    with open(os.path.join(d, name, 'summary.txt')) as f:
        return [l for l in f if not re.match(r'(\S+\.)?(wall_time|ns_per_particle_step|'
                                             r'total_wall_time|sweep_cost_over_local_update) ',
                                             l)]


if a.tolerance == 0.0:
    if summary(ref) != summary(out):
        bad.append('summary.txt')
    for f in sorted(glob.glob(os.path.join(ref, name, '*.csv')) +
                    glob.glob(os.path.join(ref, name, '*.xdmf'))):
        g = os.path.join(out, name, os.path.basename(f))
        if not os.path.exists(g) or open(f, 'rb').read() != open(g, 'rb').read():
            bad.append(os.path.basename(f))
# a finished run leaves no checkpoints behind, interrupted or not
for d in (ref, out):
    if os.path.exists(os.path.join(d, name + '.checkpoints')):
        bad.append('(%s/%s.checkpoints left behind)' % (os.path.basename(d), name))
print('; '.join(resumed))
print('%d datasets compared (%s): %s' % (len(names), 'bitwise' if a.tolerance == 0 else
      'relative %g' % a.tolerance, 'all equal' if not bad else 'differ: ' + ', '.join(bad)))
sys.exit(1 if bad else 0)
