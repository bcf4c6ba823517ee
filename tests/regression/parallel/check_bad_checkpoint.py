#!/usr/bin/env python3
"""A damaged checkpoint is refused by wellposed-mpm or wellposed-mpm2d, never
half-read.

check_bad_checkpoint.py --program wellposed-mpm --deck DECK --out DIR [--launcher L]
                        [--name NAME] [--every STEPS] [--downgrade HELPER] -- [ARGS]

Runs DECK with a checkpoint every STEPS steps (20) in its own session and
kills all of it (launcher and ranks) with SIGKILL once the first
checkpoint exists. Then, from
copies of that checkpoint:
  - truncated to half its length, given with --restart-from;
  - one byte of its data flipped (the checkpoint's checksum must catch it),
    given with --restart-from;
  - the flipped file as the newest of the run's checkpoint folder, found
    by --restart;
  - with --downgrade HELPER (parallel_snapshots_main): the checkpoint
    without its particle snapshot entries, as the programs before the
    snapshot store wrote their checkpoints, given with --restart-from;
  - the checkpoint itself, with its particle snapshot file of the
    checkpoint folder (rank 0's) cut to half its length, then removed;
each restart must exit non-zero with one message naming the file and
saying it is refused (the third also naming --restart-from, the fourth that
an earlier version wrote it, the last two naming the snapshot file), and
leave no finished run folder. Exit status
0 when all holds.
"""
import argparse, glob, os, re, shlex, shutil, signal, subprocess, sys, time


sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..'))
from rank_launch import kill_session  # noqa: E402

ap = argparse.ArgumentParser()
ap.add_argument('--launcher', default='')
ap.add_argument('--program', required=True)
ap.add_argument('--deck', required=True)
ap.add_argument('--out', required=True)
ap.add_argument('--name', default='short_wave')
ap.add_argument('--every', default='20')
ap.add_argument('--downgrade', default=None)
ap.add_argument('args', nargs='*')
a = ap.parse_args()
launch = shlex.split(a.launcher)
common = ['--no-plot', '--checkpoint-every', a.every, a.deck] + a.args
said = os.path.basename(a.program) + ': error:'

shutil.rmtree(a.out, ignore_errors=True)
os.makedirs(a.out)
proc = subprocess.Popen(launch + [a.program, '--out', a.out] + common, stdout=subprocess.DEVNULL,
                        stderr=subprocess.DEVNULL, start_new_session=True)
ckdir = os.path.join(a.out, a.name + '.checkpoints')
deadline = time.time() + 120
while not glob.glob(os.path.join(ckdir, 'checkpoint_*.h5')):
    if proc.poll() is not None:
        sys.exit('FAIL: the run ended before its first checkpoint')
    if time.time() > deadline:
        sys.exit('FAIL: no checkpoint within 120 s')
    time.sleep(0.01)
kill_session(proc.pid)
proc.wait()
good = sorted(glob.glob(os.path.join(ckdir, 'checkpoint_*.h5')))[-1]
data = open(good, 'rb').read()
truncated = os.path.join(a.out, 'truncated.h5')
with open(truncated, 'wb') as f:
    f.write(data[:len(data) // 2])
flipped = os.path.join(a.out, 'flipped.h5')
# flip one bit in the middle of the largest dataset's stored bytes, so the
# file still opens as HDF5 and only the checkpoint's checksum can tell (a
# fixed place in the file may fall in HDF5's free space as the layout grows)
import h5py  # noqa: E402
sets = []
with h5py.File(good, 'r') as f:
    f.visititems(lambda name, o: sets.append((o.id.get_storage_size(), o.id.get_offset(), name))
                 if isinstance(o, h5py.Dataset) and o.id.get_offset() is not None else None)
size, offset, _ = max(sets)
raw = bytearray(data)
k = offset + size // 2
raw[k] ^= 0x10
with open(flipped, 'wb') as f:
    f.write(raw)

failures = []


def refused(label, extra, pattern):
    r = subprocess.run(launch + [a.program, '--out', a.out] + extra + common,
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    msg = [l for l in r.stderr.splitlines() if said in l]
    ok = r.returncode != 0 and msg and re.search(pattern, msg[0])
    if os.path.exists(os.path.join(a.out, a.name)):
        ok = False
        msg.append('(and it left a finished-looking folder)')
    print('%s: %s: %s' % ('ok  ' if ok else 'FAIL', label, msg[0] if msg else
                         'exit %d, no error message' % r.returncode))
    if not ok:
        failures.append(label)


refused('truncated checkpoint', ['--restart-from', truncated],
        r'checkpoint ".*truncated\.h5" is refused')
refused('checkpoint with a flipped byte', ['--restart-from', flipped],
        r'checkpoint ".*flipped\.h5" is refused.*checksum')
shutil.copy(flipped, os.path.join(ckdir, 'checkpoint_9999999999.h5'))
refused('damaged newest checkpoint found by --restart', ['--restart'],
        r'checkpoint_9999999999\.h5" is refused.*--restart-from')
if a.downgrade:
    old = subprocess.run([a.downgrade, 'downgrade', good, os.path.join(a.out, 'old')],
                         stdout=subprocess.PIPE, text=True, check=True).stdout.split()[0]
    refused('checkpoint of the programs before the snapshot store', ['--restart-from', old],
            re.escape(old) + r': it was written by an earlier version of the program')
spool = sorted(glob.glob(os.path.join(ckdir, 'snapshots_*_rank000000.bin')))
if len(spool) != 1:
    sys.exit('FAIL: the killed run left %d snapshot files of rank 0, not one' % len(spool))
spool = spool[0]
with open(spool, 'r+b') as f:
    f.truncate(os.path.getsize(spool) // 2)
refused('truncated snapshot file', ['--restart-from', good],
        r'particle snapshot file "' + re.escape(spool) + r'" is truncated: it has \d+ bytes, '
        r'the checkpoint records \d+')
os.remove(spool)
refused('missing snapshot file', ['--restart-from', good],
        r'particle snapshot file "' + re.escape(spool) + r'" is missing')
sys.exit(1 if failures else 0)
