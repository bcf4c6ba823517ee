#!/usr/bin/env python3
"""Serial = parallel for wellposed-mpm.

check_ranks.py --launcher "mpirun -np 4 --oversubscribe" --program wellposed-mpm
               --deck DECK --name NAME --reference DIR --out DIR
               [--bitwise | --tolerance T] [--translate] [--ranks N --parallel-hdf5]
               -- [ARGS]

Runs DECK under the launcher into OUT and compares its run.h5 with the
serial run of the same deck in REFERENCE/NAME (run by the fixture test):
the same layout (datasets, their types and shapes, root attributes and
their values) and every dataset bitwise (--bitwise: one rank must be the serial program), or
within T relative to the dataset's largest value. Always exact, whatever T:
the nonlocal iteration counts (datasets nonlocal/step and
nonlocal/iterations: the sweeps of every step; the summary's nonlocal_*
counts), the particle count and the step count.
Exempt from T, with the reason printed: energy/momentum_minus_impulse and
the summary's energy_balance_error, momentum_error (conservation residuals:
differences of totals 1e8 times larger, so the summation order of the
totals shows at 1e-8 of the residual, 1e-16 of the totals).
--translate (the free-flying bar): the stresses are round-off noise
(micro-pascals) and are not compared, nor the works made of them; instead every particle must be there
exactly once with its own data (x0 of the last snapshot bitwise), and the
momentum minus impulse must stay at its initial value within 1e-13 in both
runs. The summary's h5_writer must say how run.h5 was written: on
--ranks N > 1 with --parallel-hdf5 (the build's HDF5 is parallel)
mpio-collective, every rank writing its rows through MPI-IO; else
rank0-gather. Exit status 0 when all holds.

compare_runs(), relative() and compare_summaries() are the comparison
alone, for every_deck.py.
"""
import argparse, os, shlex, subprocess, sys
import warnings
import h5py, numpy as np
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..'))
from rank_launch import layout_problems, writer_problem  # noqa: E402
warnings.simplefilter("ignore", RuntimeWarning)   # all-NaN measures of stations the wave never reached

RESIDUALS = {'energy/momentum_minus_impulse'}
EXACT = ('nonlocal/iterations', 'nonlocal/step')
RESIDUALS_NOTE = ('not compared: energy/momentum_minus_impulse, energy_balance_error, '
                  'momentum_error (conservation residuals: the summation order of totals 1e8 '
                  'times larger)')


def dataset_names(f):
    names = []
    f.visit(lambda n: names.append(n) if isinstance(f[n], h5py.Dataset) else None)
    return names


def relative(x, y):
    """The largest |x - y| over the largest |x| (NaNs left out; 0 for x = 0)."""
    s = np.nanmax(np.abs(x)) if x.size else 0.0
    return float(np.nanmax(np.abs(x - y)) / s) if s > 0 else 0.0


def compare_runs(ref, run, tolerance=1e-12, bitwise=False, translate=False):
    """Every dataset of the open run.h5 `ref` against `run`: (names, bad,
    worst, worst_name), bad listing what differs beyond `tolerance` relative
    to the dataset's largest value (EXACT ones: not bitwise; RESIDUALS exempt
    unless `bitwise`)."""
    names = dataset_names(ref)
    bad, worst, worst_name = [], 0.0, ''
    for n in names:
        if n not in run:
            bad.append(n + ' (missing)'); continue
        x, y = ref[n][()], run[n][()]
        if x.shape != y.shape:
            bad.append(n + ' (shape %s, serial %s)' % (y.shape, x.shape)); continue
        if bitwise or n in EXACT:
            if x.tobytes() != y.tobytes():
                bad.append(n + ' (not bitwise)')
            continue
        if n in RESIDUALS or (translate and ('sigma' in n or n in ('energy/internal_work',
                                                                    'energy/plastic_work',
                                                                    'measures/peak'))):
            continue
        d = relative(x, y)
        if not np.array_equal(np.isnan(x), np.isnan(y)):
            d = np.inf
        if d > worst:
            worst, worst_name = d, n
        if d > tolerance:
            bad.append('%s (%.2e)' % (n, d))
    return names, bad, worst, worst_name


def read_summary(path):
    out = {}
    with open(path) as f:
        for line in f:
            if '=' in line:
                k, v = line.split('#')[0].split('=', 1)
                out[k.strip()] = v.strip()
    return out


def compare_summaries(sa, sb):
    """The summary's counts that must be exact (steps, particles, the
    nonlocal_* iteration counts): what differs, as text."""
    exact = ['steps', 'particles'] + [k for k in sa if k.startswith('nonlocal_') and
                                      k not in ('nonlocal_support_radius',)]
    return ['summary %s: %s, serial %s' % (k, sb.get(k), sa.get(k))
            for k in exact if sa.get(k) != sb.get(k)]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--launcher', default='')
    ap.add_argument('--program', required=True)
    ap.add_argument('--deck', required=True)
    ap.add_argument('--name', required=True)
    ap.add_argument('--reference', required=True)
    ap.add_argument('--out', required=True)
    ap.add_argument('--bitwise', action='store_true')
    ap.add_argument('--tolerance', type=float, default=1e-12)
    ap.add_argument('--translate', action='store_true')
    ap.add_argument('--ranks', type=int, default=1)
    ap.add_argument('--parallel-hdf5', action='store_true')
    ap.add_argument('args', nargs='*')
    a = ap.parse_args()

    subprocess.run(['rm', '-rf', a.out])
    cmd = shlex.split(a.launcher) + [a.program, '--out', a.out, '--no-plot',
                                     '--checkpoint-every', '0', a.deck] + a.args
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if r.returncode != 0:
        sys.exit('FAIL: %s exited %d\n%s' % (' '.join(cmd), r.returncode, r.stdout[-3000:]))

    ref = h5py.File(os.path.join(a.reference, a.name, 'run.h5'), 'r')
    run = h5py.File(os.path.join(a.out, a.name, 'run.h5'), 'r')
    names, bad, worst, worst_name = compare_runs(ref, run, a.tolerance, a.bitwise, a.translate)
    bad = layout_problems(ref, run) + bad
    sa = read_summary(os.path.join(a.reference, a.name, 'summary.txt'))
    sb = read_summary(os.path.join(a.out, a.name, 'summary.txt'))
    bad += compare_summaries(sa, sb)
    for label, s, ranks in (('serial', sa, 1), ('this run', sb, a.ranks)):
        problem = writer_problem(s.get('h5_writer'), ranks, a.parallel_hdf5)
        if problem:
            bad.append('%s: %s' % (label, problem))
    print('run.h5 written %s on %d rank(s)' % (sb.get('h5_writer'), a.ranks))
    if a.translate:
        last = sorted(k for k in ref['snapshots'] if k != 'count')[-1]
        x0a, x0b = ref['snapshots/%s/x0' % last][()], run['snapshots/%s/x0' % last][()]
        if x0a.tobytes() != x0b.tobytes() or len(np.unique(x0b)) != len(x0b):
            bad.append('a particle was lost, doubled or altered on the way across the ranks')
        for label, f in (('serial', ref), ('parallel', run)):
            m = f['energy/momentum_minus_impulse'][()]
            drift = float(np.max(np.abs(m - m[0])) / abs(m[0]))
            print('%s: momentum - impulse drifts by %.1e of its initial value' % (label, drift))
            if not drift <= 1e-13:
                bad.append('%s momentum not conserved (%.1e)' % (label, drift))
        x = run['snapshots/%s/x' % last][()]
        print('the bar moved %.1f m' % (float(np.min(x)) - float(np.min(x0b))))
    nl = ref['nonlocal/iterations'][()] if 'nonlocal/iterations' in ref else None
    if nl is not None:
        print('nonlocal sweeps: %d steps iterated, %d sweeps in all (serial and parallel equal: %s)'
              % (len(nl), int(nl.sum()), 'nonlocal/iterations (not bitwise)' not in bad))
    print('%d datasets against the serial run (%s): %s; worst %.2e (%s)' % (
        len(names), 'bitwise' if a.bitwise else 'relative %g' % a.tolerance,
        'all equal' if not bad else 'differ: ' + ', '.join(bad), worst, worst_name))
    if not a.bitwise:
        print(RESIDUALS_NOTE)
    sys.exit(1 if bad else 0)


if __name__ == '__main__':
    main()
