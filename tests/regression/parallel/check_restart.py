#!/usr/bin/env python3
"""Kill -9 + --restart equals the uninterrupted run.

check_restart.py --launcher "mpirun -np 2 --oversubscribe" --restart-launcher "..."
                 --program wellposed-mpm --deck DECK --out DIR [--tolerance T]
                 [--kill-at STEP] -- [ARGS]

Runs DECK uninterrupted into DIR/ref, then again into DIR/run in its own
session, kills every process of it (launcher and ranks) with SIGKILL once two
checkpoints exist (with --kill-at, once a checkpoint of step STEP or later
exists: late enough that snapshots were taken before it, which the restart
must write again from the checkpoint), runs it again with --restart, checks
that it continued from such a checkpoint, and compares every run.h5 dataset (bitwise unless a
tolerance is given; then relative to the dataset's largest value, with the
conservation residual energy/momentum_minus_impulse exempt; the particle
snapshots taken before the checkpoint, which the restart reads back from the
checkpoint folder's snapshot files, bitwise all the same) and summary.txt
(wall-clock lines and the measured bytes_per_particle excepted), and run.xdmf
byte for byte. Exit status 0 when equal.

--edit-deck: the restart reads a copy of DECK edited after the kill (a comment
added, the blanks around "=" removed), which must be accepted (a checkpoint's
deck is compared as its namelists read it); a copy with its cfl value changed
is tried first and must be refused, naming the deck, with no finished folder.
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
ap.add_argument('--name', default='short_wave')
ap.add_argument('--every', default='500')
ap.add_argument('--tolerance', type=float, default=0.0)
ap.add_argument('--kill-at', type=int, default=0)
ap.add_argument('--edit-deck', action='store_true')
ap.add_argument('args', nargs='*')
a = ap.parse_args()
launch = shlex.split(a.launcher)
relaunch = shlex.split(a.restart_launcher) if a.restart_launcher is not None else launch
common = ['--no-plot', '--checkpoint-every', a.every, a.deck] + a.args


subprocess.run(['rm', '-rf', a.out])
ref, out = os.path.join(a.out, 'ref'), os.path.join(a.out, 'run')
run(launch + [a.program, '--out', ref] + common)
proc = subprocess.Popen(launch + [a.program, '--out', out] + common, stdout=subprocess.DEVNULL,
                        stderr=subprocess.DEVNULL, start_new_session=True)
ckdir = os.path.join(out, a.name + '.checkpoints')
deadline = time.time() + 120
while True:
    steps = [int(os.path.basename(p)[11:21])
             for p in glob.glob(os.path.join(ckdir, 'checkpoint_??????????.h5'))]
    if len(steps) >= 2 and max(steps) >= a.kill_at:
        break
    if proc.poll() is not None:
        sys.exit('FAIL: the run ended before its checkpoint of step %d: use a longer run'
                 % max(a.kill_at, 1))
    if time.time() > deadline:
        sys.exit('FAIL: no such checkpoint within 120 s')
    time.sleep(0.005)
kill_session(proc.pid)
proc.wait()
if os.path.exists(os.path.join(out, a.name)):
    sys.exit('FAIL: the killed run left a finished-looking folder')
if a.edit_deck:
    deck_text = open(a.deck).read()
    if not re.search(r'cfl\s*=\s*0\.2\b', deck_text):
        sys.exit('FAIL: --edit-deck needs a deck with cfl = 0.2')
    edited = os.path.join(a.out, 'edited_' + os.path.basename(a.deck))
    changed = os.path.join(a.out, 'changed_' + os.path.basename(a.deck))
    with open(changed, 'w') as f:
        f.write(re.sub(r'cfl\s*=\s*0\.2\b', 'cfl = 0.19', deck_text, count=1))
    r = subprocess.run(relaunch + [a.program, '--out', out, '--restart'] + common[:3] +
                       [changed] + a.args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                       text=True)
    if r.returncode == 0 or 'was written for another deck than ' + changed not in r.stdout:
        sys.exit('FAIL: a restart with a changed cfl was not refused as another deck:\n' +
                 r.stdout[-2000:])
    if os.path.exists(os.path.join(out, a.name)):
        sys.exit('FAIL: the refused restart left a finished-looking folder')
    print('refused as it should: ' + [l for l in r.stdout.splitlines() if 'another deck' in l][0])
    with open(edited, 'w') as f:
        f.write('! edited after the run began: a comment and spacing do not count\n' +
                deck_text.replace(' = ', '='))
    common = common[:3] + [edited] + a.args
text = run(relaunch + [a.program, '--out', out, '--restart'] + common)
resumed = re.search(r'restarted from .* \(step (\d+), t = (\S+) s.*', text)
print(resumed.group(0).strip() if resumed else text.strip().splitlines()[-1])
if not resumed or int(resumed.group(1)) < a.kill_at:
    sys.exit('FAIL: the restart did not continue from a checkpoint of step %d or later'
             % a.kill_at)
again = re.search(r'(\d+) snapshots written again', text)
if a.kill_at > 0 and (not again or int(again.group(1)) < 2):
    sys.exit('FAIL: the checkpoint held fewer than two snapshots: kill it later')
fa, fb = h5py.File(os.path.join(ref, a.name, 'run.h5')), h5py.File(os.path.join(out, a.name, 'run.h5'))
names = []
fa.visit(lambda n: names.append(n) if isinstance(fa[n], h5py.Dataset) else None)
t_restart = float(resumed.group(2))


def written_again(n):
    """Dataset n belongs to a snapshot (a group with a one-value `time`) taken
    before the restart: read back from the snapshot files, so bitwise."""
    group = n.rsplit('/', 1)[0] if '/' in n else ''
    t = group + '/time'
    return bool(group) and t in fa and fa[t].shape == (1,) and fa[t][0] <= t_restart * (1 + 1e-12)


bad = []
n_again = 0
for n in names:
    if n not in fb:
        bad.append(n + ' (missing)'); continue
    x, y = fa[n][()], fb[n][()]
    if x.shape != y.shape:
        bad.append(n + ' (shape)'); continue
    if written_again(n):
        n_again += 1
    if a.tolerance == 0.0 or written_again(n):
        same = x.tobytes() == y.tobytes()
    else:
        if n == 'energy/momentum_minus_impulse':
            continue
        s = np.nanmax(np.abs(x)) if x.size else 0.0
        same = s == 0 or bool(np.nanmax(np.abs(x - y)) <= a.tolerance * s)
    if not same:
        bad.append(n)
def summary(d):
    with open(os.path.join(d, a.name, 'summary.txt')) as f:
        return [l for l in f if not l.startswith(('wall_time', 'ns_per', 'share_',
                                                   'bytes_per_particle'))]
if a.tolerance == 0.0 and summary(ref) != summary(out):
    bad.append('summary.txt')
# the snapshots' XDMF (names, shapes, times) is the uninterrupted run's, to the byte
xdmf_ref, xdmf_out = (os.path.join(d, a.name, 'run.xdmf') for d in (ref, out))
if os.path.exists(xdmf_ref) and (not os.path.exists(xdmf_out) or
                                 open(xdmf_ref, 'rb').read() != open(xdmf_out, 'rb').read()):
    bad.append('run.xdmf')
# a finished run leaves no checkpoints behind, interrupted or not
for d in (ref, out):
    if os.path.exists(os.path.join(d, a.name + '.checkpoints')):
        bad.append('(%s/%s.checkpoints left behind)' % (os.path.basename(d), a.name))
print('%d datasets compared (%s; the %d of the snapshots written again bitwise): %s'
      % (len(names), 'bitwise' if a.tolerance == 0 else 'relative %g' % a.tolerance, n_again,
         'all equal' if not bad else 'differ: ' + ', '.join(bad)))
if a.kill_at > 0 and n_again == 0:
    sys.exit('FAIL: no snapshot dataset of the restart\'s files was compared')
sys.exit(1 if bad else 0)
