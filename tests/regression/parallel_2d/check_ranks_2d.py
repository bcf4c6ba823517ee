#!/usr/bin/env python3
"""Serial = parallel for wellposed-mpm2d.

check_ranks_2d.py --program wellposed-mpm2d --deck DECK --out DIR
                  [--launcher "mpirun --oversubscribe"] [--np-flag -np]
                  [--ranks 2 4] [--tolerance 1e-12] [--min-handed 1]
                  [--parallel-hdf5] [--stress-scale] -- [ARGS]

Runs DECK serially (no launcher) into DIR/np1, then under the launcher on
each rank count into DIR/np<N>, and compares every run.h5 dataset with the
serial one: the largest difference relative to the dataset's largest
magnitude must stay within the tolerance (summation order of the nodal sums
is the only difference; --stress-scale: the stresses relative to their
snapshot's largest stress, for a state in which some components vanish). Also: the same layout (datasets, their types and
shapes, root attributes and their values), the same summary.txt lines
but for wall times and the figures computed from the stress curve (compared
with the same tolerance), and at least --min-handed particles handed between
ranks, as the program reports, so the run did cross rank boundaries, and
the summary's h5_writer: rank0-gather serially, and on more ranks
mpio-collective when the build has parallel HDF5 (--parallel-hdf5: run.h5
written by every rank through MPI-IO), else rank0-gather.
Exit status 0 when all hold.

compare_runs(), read_summary(), compare_summaries() and handed() are the
comparison alone, for every_deck.py.
"""
import argparse, os, re, shlex, subprocess, sys
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..'))
from rank_launch import layout_problems, run, writer_problem  # noqa: E402
import h5py, numpy as np


def dataset_names(f):
    names = []
    f.visit(lambda n: names.append(n) if isinstance(f[n], h5py.Dataset) else None)
    return names


def stress_scales(f, names):
    """Each group's largest stress magnitude over its sigma_* datasets."""
    scales = {}
    for n in names:
        if os.path.basename(n).startswith('sigma_') and f[n].size:
            g = os.path.dirname(n)
            scales[g] = max(scales.get(g, 0.0), float(np.max(np.abs(f[n][()]))))
    return scales


def compare_runs(fa, fb, tolerance=1e-12, stress_scale=False):
    """Every dataset of the open run.h5 `fa` (serial) against `fb`: (names,
    bad, (worst, its name)), bad listing what differs beyond `tolerance`
    relative to the dataset's largest magnitude (with `stress_scale`, a
    sigma_* dataset relative to its snapshot's largest stress: a component
    that is zero in the exact state holds only rounding)."""
    names = dataset_names(fa)
    scales = stress_scales(fa, names) if stress_scale else {}
    bad, worst = [], (0.0, '')
    for n in names:
        if n not in fb:
            bad.append(n + ' (missing)')
            continue
        x, y = fa[n][()], fb[n][()]
        if x.shape != y.shape:
            bad.append(n + ' (shape)')
            continue
        if x.size == 0:
            continue
        s = float(np.max(np.abs(x)))
        s = max(s, scales.get(os.path.dirname(n), 0.0)) if os.path.basename(n).startswith(
            'sigma_') else s
        r = float(np.max(np.abs(x - y))) / s if s > 0 else float(np.max(np.abs(y)))
        if r > worst[0]:
            worst = (r, n)
        if not r <= tolerance:
            bad.append('%s (%.2e)' % (n, r))
    return names, bad, worst


def read_summary(path):
    out = {}
    with open(path) as f:
        for line in f:
            key, _, value = line.partition(' = ')
            out[key] = value.split('  #')[0].strip()
    return out


def compare_summaries(sa, sb, tolerance=1e-12):
    """Every summary.txt line of `sa` (serial) against `sb` but for wall
    times and the implicit scheme's converged residual (rounding, below its
    Newton tolerance in each run): numbers within `tolerance` relative,
    text equal. What differs."""
    bad = []
    for key, value in sa.items():
        if key.endswith(('wall_time', 'ns_per_particle_step', 'sweep_cost_over_local_update',
                         'h5_writer', 'newton_residual_max')):
            continue
        other = sb.get(key)
        try:
            u, v = float(value), float(other)
            same = abs(u - v) <= tolerance * max(abs(u), abs(v), 1e-300)
        except (TypeError, ValueError):
            same = value == other
        if not same:
            bad.append('summary %s: %s against %s' % (key, value, other))
    return bad


def handed(text):
    """Particles handed between ranks, as the program's output reports them."""
    return sum(int(m) for m in re.findall(r'particles handed between ranks: (\d+)', text))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--program', required=True)
    ap.add_argument('--deck', required=True)
    ap.add_argument('--out', required=True)
    ap.add_argument('--launcher', default='')
    ap.add_argument('--np-flag', default='-np')
    ap.add_argument('--ranks', type=int, nargs='+', default=[2, 4])
    ap.add_argument('--tolerance', type=float, default=1e-12)
    ap.add_argument('--min-handed', type=int, default=1)
    ap.add_argument('--parallel-hdf5', action='store_true')
    ap.add_argument('--stress-scale', action='store_true',
                    help='stresses relative to the snapshot\'s largest (see compare_runs)')
    ap.add_argument('args', nargs='*')
    a = ap.parse_args()
    common = ['--no-plot', '--checkpoint-every', '0', a.deck] + a.args
    name = re.search(r"name\s*=\s*'([^']+)'", open(a.deck).read()).group(1)

    subprocess.run(['rm', '-rf', a.out])
    ref = os.path.join(a.out, 'np1')
    run([a.program, '--out', ref] + common)
    fa = h5py.File(os.path.join(ref, name, 'run.h5'))
    sa = read_summary(os.path.join(ref, name, 'summary.txt'))
    problem = writer_problem(sa.get('h5_writer'), 1, a.parallel_hdf5)
    failed = problem is not None
    if problem:
        print('serial: ' + problem)
    for np_ in a.ranks:
        d = os.path.join(a.out, 'np%d' % np_)
        text = run(shlex.split(a.launcher) + [a.np_flag, str(np_), a.program, '--out', d] + common)
        n_handed = handed(text)
        fb = h5py.File(os.path.join(d, name, 'run.h5'))
        names, bad, worst = compare_runs(fa, fb, a.tolerance, a.stress_scale)
        bad = layout_problems(fa, fb) + bad
        sb = read_summary(os.path.join(d, name, 'summary.txt'))
        bad += compare_summaries(sa, sb, a.tolerance)
        if n_handed < a.min_handed:
            bad.append('only %d particles handed between ranks' % n_handed)
        problem = writer_problem(sb.get('h5_writer'), np_, a.parallel_hdf5)
        if problem:
            bad.append(problem)
        print('%d ranks (run.h5: %s): %d datasets, worst relative difference %.2e (%s), '
              '%d particles handed; %s'
              % (np_, sb.get('h5_writer'), len(names), worst[0], worst[1], n_handed,
                 'equal' if not bad else 'differ: ' + ', '.join(bad)))
        failed = failed or bool(bad)
    sys.exit(1 if failed else 0)


if __name__ == '__main__':
    main()
