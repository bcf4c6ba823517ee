#!/usr/bin/env python3
"""Full-disk tests of every program and output kind.

injected: WELLPOSED_FAIL_WRITE=<file name part> makes the checked write
layer fail that one output as a full disk would (a build with
WELLPOSED_WRITE_FAULTS); tmpfs: a real full file system, a small tmpfs
mounted here when the test runs as root (skipped otherwise). Every case
must end with exit status 1, an error line on standard error (a file here,
not a terminal) naming the file and the reason, and no finished run folder.

usage: full_disk.py --bin DIR --src DIR --work DIR [--only PROGRAM] injected|tmpfs|demo
"""
import argparse
import os
import shutil
import subprocess
import sys
import tempfile

POINT_DECK = 'inputs/fig2_5_hardening_softening.nml'   # results.h5, CSV, PNG
BAR_DECK = 'tests/regression/mpm/decks/sr_short.nml'
PLATE_DECK = 'tests/regression/plate/decks/plate_small_local.nml'
BAR_ARGS = ['time.t_end=4e-3', 'output.snapshot_dt=2e-3', '--checkpoint-every', '20']
PLATE_ARGS = ['time.t_end=1e-3', 'output.snapshot_dt=5e-4', '--checkpoint-every', '60']


def run(cmd, env=None, stdout=subprocess.DEVNULL):
    with tempfile.TemporaryFile('w+') as err:
        p = subprocess.run(cmd, env=env, stdout=stdout, stderr=err, timeout=120)
        err.seek(0)
        return p.returncode, err.read()


def finished(root, name):
    """The finished folder of run `name` under root, if any."""
    d = os.path.join(root, name)
    return os.path.isdir(d)


def expect_failure(label, rc, err, root, name, needle, reason):
    problems = []
    if rc != 1:
        problems.append(f'exit status {rc}, not 1')
    lines = [ln for ln in err.splitlines() if 'error:' in ln]
    if not any(needle in ln and reason in ln for ln in lines):
        problems.append(f'no error line naming "{needle}" and "{reason}" in: {err.strip()!r}')
    if name is not None and finished(root, name):
        problems.append(f'a finished folder {name}/ exists')
    status = 'ok' if not problems else 'FAIL: ' + '; '.join(problems)
    print(f'{label}: {status}')
    return not problems


def injected(a):
    ok = True
    src = a.src
    point = [os.path.join(a.bin, 'wellposed-point'), os.path.join(src, POINT_DECK)]
    mpm = os.path.join(a.bin, 'wellposed-mpm')
    reason = 'injected by WELLPOSED_FAIL_WRITE'
    stem = 'fig2_5_hardening_softening'
    cases = [('point ' + kind, point + ([] if kind == 'PNG' else ['--no-plot']), target, stem)
             for kind, target in [('summary', 'summary.txt'), ('HDF5', 'results.h5'),
                                  ('CSV', '_path.csv'), ('deck copy', '.nml'),
                                  ('PNG', '.png')]]
    scenes = [('bar', BAR_DECK, BAR_ARGS, 'sr_short', []),
              ('plate', PLATE_DECK, PLATE_ARGS, 'plate_small_local', [('CSV', '_curve.csv')])]
    for scene, deck, args, name, extra in scenes:
        for kind, target in [('summary', 'summary.txt'), ('HDF5', 'run.h5'), ('XDMF', '.xdmf'),
                             ('checkpoint', 'checkpoint_')] + extra:
            cases.append((scene + ' ' + kind, [mpm, os.path.join(src, deck)] + args, target,
                          name))
    for label, cmd, target, name in cases:
        if a.only and not label.startswith(a.only):
            continue
        root = os.path.join(a.work, 'injected', label.replace(' ', '_'))
        shutil.rmtree(root, ignore_errors=True)
        os.makedirs(root)
        if cmd[0].endswith('wellposed-mpm') and '--no-plot' not in cmd:
            cmd = cmd + ['--no-plot']
        env = dict(os.environ, WELLPOSED_FAIL_WRITE=target)
        rc, err = run(cmd + ['--out', root], env)
        ok &= expect_failure(label, rc, err, root, name, target, reason)
    if a.only and a.only != 'batch':
        return ok
    # the batch summary of wellposed-batch (its one job succeeds)
    root = os.path.join(a.work, 'injected', 'batch')
    shutil.rmtree(root, ignore_errors=True)
    os.makedirs(root)
    batch = os.path.join(root, 'one.batch')
    with open(batch, 'w') as f:
        f.write(os.path.join(src, POINT_DECK) + '\n')
    for target in ['batch_summary.txt', 'batch_summary.csv']:
        env = dict(os.environ, WELLPOSED_FAIL_WRITE=target)
        rc, err = run([os.path.join(a.bin, 'wellposed-batch'), '--out', root,
                       os.path.join(a.bin, 'wellposed-point'), batch, '--no-plot'], env)
        ok &= expect_failure('batch ' + target, rc, err, root, 'one', target, reason)
    return ok


def demo(a):
    with open('/dev/full', 'w') as full:
        rc, err = run([os.path.join(a.bin, 'wellposed-demo')], stdout=full)
    return expect_failure('demo table on a full disk', rc, err, a.work, None,
                          'standard output', 'full disk')


def tmpfs(a):
    """Real full file systems: a tmpfs of a few hundred kB (root only)."""
    mnt = os.path.join(a.work, 'tmpfs')
    os.makedirs(mnt, exist_ok=True)
    point = [os.path.join(a.bin, 'wellposed-point'), os.path.join(a.src, POINT_DECK),
             '--no-plot']
    mpm = os.path.join(a.bin, 'wellposed-mpm')
    cases = [
        ('point, 150k', '150k', point, 'fig2_5_hardening_softening'),
        ('point, 300k', '300k', point, 'fig2_5_hardening_softening'),
        ('bar, 400k', '400k', [mpm, os.path.join(a.src, BAR_DECK), '--no-plot'] + BAR_ARGS,
         'sr_short'),
        ('plate, 150k', '150k', [mpm, os.path.join(a.src, PLATE_DECK), '--no-plot'] +
         PLATE_ARGS, 'plate_small_local'),
    ]
    ok = True
    for label, size, cmd, name in cases:
        if subprocess.run(['mount', '-t', 'tmpfs', '-o', 'size=' + size, 'tmpfs', mnt],
                          stderr=subprocess.DEVNULL).returncode != 0:
            print('tmpfs: cannot mount a tmpfs here (not root?): skipped')
            return 77
        try:
            rc, err = run(cmd + ['--out', mnt])
            ok &= expect_failure('full tmpfs: ' + label, rc, err, mnt, name, mnt,
                                 'No space left on device' if 'point' in label else 'cannot')
        finally:
            subprocess.run(['umount', mnt])
    return ok


def main():
    p = argparse.ArgumentParser()
    p.add_argument('--bin', required=True)
    p.add_argument('--src', required=True)
    p.add_argument('--work', required=True)
    p.add_argument('--only', default='', help='injected: the cases of one program '
                   '(point, bar, plate, batch)')
    p.add_argument('what', choices=['injected', 'tmpfs', 'demo'])
    a = p.parse_args()
    a.bin, a.src, a.work = (os.path.abspath(x) for x in (a.bin, a.src, a.work))
    os.makedirs(a.work, exist_ok=True)
    result = {'injected': injected, 'tmpfs': tmpfs, 'demo': demo}[a.what](a)
    if result == 77:
        return 77
    return 0 if result else 1


if __name__ == '__main__':
    sys.exit(main())
