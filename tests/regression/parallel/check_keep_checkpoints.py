#!/usr/bin/env python3
"""check_keep_checkpoints.py --program EXE --deck DECK --name NAME --every STEPS --out DIR
[-- group.key=value ...]

A finished run leaves no ROOT/NAME.checkpoints folder unless --keep-checkpoints: runs the
deck with checkpoints every STEPS steps without the flag (no folder may be left) and with it
(the folder must hold checkpoints), then continues from the newest kept one with
--restart-from into a third folder, which must equal the first run bitwise (every run.h5
dataset and summary.txt, wall-time lines aside) and leave no folder itself."""
import argparse, glob, os, subprocess, sys
import h5py

ap = argparse.ArgumentParser()
ap.add_argument('--program', required=True)
ap.add_argument('--deck', required=True)
ap.add_argument('--name', required=True)
ap.add_argument('--every', required=True)
ap.add_argument('--out', required=True)
ap.add_argument('args', nargs='*')
a = ap.parse_args()
subprocess.run(['rm', '-rf', a.out])
common = ['--no-plot', '--name', a.name, '--checkpoint-every', a.every, a.deck] + a.args
plain, kept, again = (os.path.join(a.out, d) for d in ('plain', 'kept', 'again'))


def run(root, *extra):
    r = subprocess.run([a.program, '--out', root] + list(extra) + common,
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if r.returncode != 0:
        sys.exit('FAIL: %s exited %d:\n%s' % (root, r.returncode, r.stdout[-2000:]))


def checkpoints(root):
    return sorted(glob.glob(os.path.join(root, a.name + '.checkpoints', 'checkpoint_*.h5')))


bad = []
run(plain)
if os.path.exists(os.path.join(plain, a.name + '.checkpoints')):
    bad.append('the run without --keep-checkpoints left its checkpoint folder')
run(kept, '--keep-checkpoints')
files = checkpoints(kept)
if not files:
    sys.exit('FAIL: the run with --keep-checkpoints left no checkpoints')
print('kept: ' + ', '.join(os.path.basename(f) for f in files))
run(again, '--restart-from', files[-1])
if os.path.exists(os.path.join(again, a.name + '.checkpoints')):
    bad.append('the restarted run left its checkpoint folder')
with h5py.File(os.path.join(plain, a.name, 'run.h5')) as fa, \
        h5py.File(os.path.join(again, a.name, 'run.h5')) as fb:
    names = []
    fa.visit(lambda n: names.append(n) if isinstance(fa[n], h5py.Dataset) else None)
    for n in names:
        if n not in fb or fa[n][()].tobytes() != fb[n][()].tobytes():
            bad.append(n)


def summary(root):
    with open(os.path.join(root, a.name, 'summary.txt')) as f:
        return [l for l in f if 'wall_time' not in l
                and not l.startswith(('ns_per', 'share_', 'bytes_per_particle'))
                and '.ns_per' not in l]


if summary(plain) != summary(again):
    bad.append('summary.txt')
print('%d datasets compared (bitwise): %s' % (len(names), 'all equal' if not bad else
                                              'differ: ' + ', '.join(bad)))
sys.exit(1 if bad else 0)
