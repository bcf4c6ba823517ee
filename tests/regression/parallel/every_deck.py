#!/usr/bin/env python3
"""Every MPM deck of inputs/ on 1, 2 and 4 ranks against the serial program.

every_deck.py [DECK ...] [--ranks 1,2,4] [--out DIR] [--quick | --full]
              [--set STEM:group.key=value ...] [--reuse] [--list]
              [--bin DIR] [--launcher "mpirun --oversubscribe"] [--np-flag -np]
              [--tolerance 1e-12]

DECK: deck files or stems of inputs/ (default: every deck of inputs/ that
wellposed-mpm (&scene) or wellposed-mpm2d (&plate) reads; --list prints
which decks are which, the wellposed-point ones included, and the
overrides each would run with). For each deck: the serial program (no
launcher) into OUT/<stem>/serial, then the launcher with -np N into
OUT/<stem>/np<N>, always with --no-plot --checkpoint-every 0 and the same
overrides, and every run.h5 dataset and the summary against the serial
run through check_ranks.py (wellposed-mpm) or check_ranks_2d.py
(wellposed-mpm2d): within --tolerance relative to the dataset's largest
value, the conservation residuals exempt (check_ranks.py says why); the
counts exactly (steps, particles, every integer dataset such as the
nonlocal sweeps of every step, the summary's iteration counts).

A run on N > 1 ranks counts only if the plastic activity crossed a rank
boundary: the ranks own strips of whole cells along the last axis
(x in 1D, y in 2D; rank r from cell floor(r ncells / N)), and the
particles with plastic strain (1D z, 2D plastic_strain, above 1e-6 of the
largest) in the last snapshot, or stations with plastic strain, must lie on
both sides of at least one strip edge (in 2D: in every case of the deck).
A deck that stays elastic is judged by its wave instead (particles moved,
stations shaken, above 1e-6 of the largest). A run that never left rank 0's
strip is equal to the serial one trivially: reported as such, not counted.

Printed per run: the worst dataset, the counts, the strip edges crossed,
the conservation residuals' differences (not compared) and, beyond one
rank, the worst difference of every snapshot in time (how it grows);
--ranks '' runs the serial program alone and says which strip edges its
activity would cross on 2 and 4 ranks (for choosing a shortening).

Overrides: the shortenings of PLAN below (why each still crosses the rank
boundaries is written beside it), or with --quick those of QUICK (seconds per
deck, for ctest), or none with --full; --set STEM:group.key=value adds one
(repeatable). --reuse keeps a finished run of OUT made by the same command.
Prints progress while it runs, then a table (also written to
OUT/every_deck.md). Exit status 0 when every run agrees and counts.
"""
import argparse
import json
import math
import os
import re
import shlex
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, '..', '..', '..'))
sys.path.insert(0, os.path.join(HERE, '..', 'parallel_2d'))
import check_ranks  # noqa: E402
import check_ranks_2d  # noqa: E402
import h5py  # noqa: E402
import numpy as np  # noqa: E402

# The 1D scenes of 700 m at dx = 0.125 m cost 1.5-4 minutes serially at
# full length (24 500 steps): cut to 250 m and 100 ms. Nothing reaches the
# far end by then (the head is at 204 m), so the first 204 m are the 700 m
# scene's. The ranks' strips meet at 125 m (2 ranks) and 62.25, 125,
# 187.6 m (4 ranks); the plastic zone reaches 176-213 m, past two or
# all three. Stations every 50 m.
SHORT_700 = ['grid.length=250', 'time.t_end=0.1', 'stations.first=50',
             'stations.spacing=50', 'stations.count=4']
# Algorithm 1 (fig. 2.10 right) at dx = 0.125 m: some 10 sweeps a step, and
# on N ranks they go rank after rank: 120 m and 50 ms, the head at 102 m,
# strip edges at 60 m (2 ranks) and 29.75, 60, 90.1 m (4 ranks).
SHORT_OVERLOCAL = ['grid.length=120', 'time.t_end=0.05', 'stations.first=20',
                   'stations.spacing=20', 'stations.count=5']

PLAN = {
    'fig2_3_local_dx0.125': SHORT_700,
    'fig2_7_exponential': SHORT_700,
    'fig2_9_dl_de0.01': SHORT_700,
    'fig2_9_dl_de1': SHORT_700,
    'fig2_9_dl_de5': SHORT_700,
    'fig2_9_dl_de10': SHORT_700,
    'fig2_9_gdl_de0.01': SHORT_700,
    'fig2_9_gdl_de1': SHORT_700,
    'fig2_9_gdl_de5': SHORT_700,
    'fig2_9_gdl_de10': SHORT_700,
    'fig2_10_right_local_softening': SHORT_700,
    'fig2_10_right_overlocal': SHORT_OVERLOCAL,
    # decks without snapshots: one at the end, so fields are compared too
    'fig2_10_left_overlocal': ['output.snapshot_dt=0.0103'],
    'mesh_study_sandler_rubin': ['output.snapshot_dt=0.185'],
    'mesh_study_gdl_de10': ['output.snapshot_dt=0.185'],
    'work_precision_efr': ['output.snapshot_dt=0.065'],
    'work_precision_elastic': ['output.snapshot_dt=0.016'],
}

# --quick: 40 m and 12.5 ms of the 700 m scenes (head at 26 m; strip edges
# at 20 m on 2 ranks, 9.5-9.75, 20 and 30.1-30.25 m on 4); 8 m and 3 ms of
# fig. 2.10 left (edges at 4 m on 2 ranks, 1.94, 4 and 6.03 m on 4); the plate
# decks to 7.5 ms, when the plastic zone first spans the plate's height.
QUICK_700 = ['grid.length=40', 'time.t_end=0.0125', 'stations.first=5', 'stations.spacing=5',
             'stations.count=5', 'output.snapshot_dt=0.0125']
QUICK = {stem: QUICK_700 for stem in (
    'sandler_rubin_default', 'fig2_3_local_dx0.25', 'fig2_3_local_dx0.125', 'fig2_6_hardening',
    'fig2_6_softening', 'fig2_7_exponential', 'fig2_8_right_efr', 'fig2_8_right_efr_lumped',
    'fig2_9_dl_de0.01',
    'fig2_9_dl_de1', 'fig2_9_dl_de5', 'fig2_9_dl_de10', 'fig2_9_gdl_de0.01', 'fig2_9_gdl_de1',
    'fig2_9_gdl_de5', 'fig2_9_gdl_de10', 'fig2_10_right_local_softening',
    'fig2_10_right_overlocal')}
QUICK.update({
    'fig2_10_left_overlocal': ['grid.length=8', 'time.t_end=0.003', 'stations.first=1',
                               'stations.spacing=1', 'stations.count=5',
                               'output.snapshot_dt=0.003'],
    'mesh_study_sandler_rubin': ['grid.length=100', 'time.t_end=0.04', 'stations.first=20',
                                 'stations.spacing=20', 'stations.count=3',
                                 'output.snapshot_dt=0.04'],
    'mesh_study_gdl_de10': ['grid.length=100', 'time.t_end=0.04', 'stations.first=20',
                            'stations.spacing=20', 'stations.count=3', 'output.snapshot_dt=0.04'],
    'work_precision_efr': PLAN['work_precision_efr'],
    'work_precision_elastic': PLAN['work_precision_elastic'],
    'fig4_2_local_plate': ['time.t_end=0.0075'],
    'fig4_4_overlocal_plate': ['time.t_end=0.0075'],
    'fig4_6_size_effect': ['time.t_end=0.0075'],
})

ACTIVE = 1e-6      # plastic strain, displacement, velocity: active above this of the largest


def deck_kind(path):
    """'mpm' (&scene, 1D), 'mpm2d' (&plate), 'point' (wellposed-point) or
    'implicit' (scheme = 'implicit' or 'newmark': not here, whose exact counts
    do not hold for Newton, its solves following the residual's rounding at
    the tolerance; tests/regression/parallel_2d compares them on ranks)."""
    text = re.sub(r'!.*', '', open(path).read()).lower()
    if re.search(r"scheme\s*=\s*'(implicit|newmark)'", text):
        return 'implicit'
    if re.search(r'&plate\b', text):
        return 'mpm2d'
    if re.search(r'&scene\b', text):
        return 'mpm'
    return 'point'


def scene_name(path):
    return re.search(r"name\s*=\s*'([^']+)'", re.sub(r'!.*', '', open(path).read())).group(1)


def strip_edges(origin, dx, ncells, nranks):
    """Where the ranks' strips meet (wellposed_mpm_decomposition)."""
    return [origin + (r*ncells//nranks)*dx for r in range(1, nranks)]


def geometry_1d(log, summary):
    """[('', origin, dx, ncells)]: the 1D grid along x, from the serial run
    (ncells = nodes - 1 cells, as many pad cells at either end of the bar)."""
    m = re.search(r'(\d+) particles, (\d+) nodes', log)
    dx, ppc = float(summary['dx']), int(summary['ppc'])
    ncells = int(m.group(2)) - 1
    pad = (ncells - int(m.group(1))//ppc)//2
    return [('', -pad*dx, dx, ncells)]


def geometry_2d(log, summary, f):
    """(case, origin, dx, ncells) of each case's rows along y, from the
    serial run: the plate's size from the first snapshot (particles sit
    symmetrically in their cells), the pad from the node count."""
    out = []
    for case, nodes in re.findall(r'case (\S+): \d+ particles, (\d+) nodes', log):
        dx = float(summary[case + '.dx'])
        snaps = sorted((k for k in f['cases/' + case] if k.startswith('snap_')),
                       key=lambda k: int(k[5:]))
        if not snaps:
            continue
        xy = f['cases/%s/%s/xy' % (case, snaps[0])][()]
        ncx, ncy = (int(round((xy[:, i].min() + xy[:, i].max())/dx)) for i in (0, 1))
        pad = next((p for p in range(64) if (ncx + 2*p + 1)*(ncy + 2*p + 1) == int(nodes)), None)
        if pad is not None:
            out.append((case, -pad*dx, dx, ncy + 2*pad))
    return out


def active(values):
    """Where |values| exceeds ACTIVE of its largest (nowhere if all 0)."""
    v = np.abs(values)
    top = np.max(v) if v.size else 0.0
    return v > ACTIVE*top if top > 0 else np.zeros(v.shape, bool)


def extent_1d(f):
    """{'': (what, lo, hi)}: the x range of the plastic particles at the
    last snapshot and of the stations with plastic strain (or, for an
    elastic run, of the moved particles and shaken stations)."""
    sx = f['stations/x'][()]
    snaps = sorted(k for k in f['snapshots'] if k != 'count')
    last = f['snapshots/' + snaps[-1]] if snaps else None
    for what, field, station in (('plastic', 'z', 'stations/z'),
                                 ('wave', None, 'stations/velocity')):
        xs = [sx[np.any(active(f[station][()]), axis=1)]]
        if last is not None:
            x = last['x'][()]
            xs.append(x[active(last['z'][()] if field else x - last['x0'][()])])
        xs = np.concatenate(xs)
        if xs.size:
            return {'': (what, float(xs.min()), float(xs.max()))}
    return {'': ('nothing', math.nan, math.nan)}


def extent_2d(f):
    """{case: ('plastic', lo, hi)}: the y range of the particles with
    plastic strain at each case's last snapshot."""
    out = {}
    for case in f['cases']:
        snaps = sorted((k for k in f['cases/' + case] if k.startswith('snap_')),
                       key=lambda k: int(k[5:]))
        y = np.empty(0)
        if snaps:
            g = f['cases/%s/%s' % (case, snaps[-1])]
            y = g['xy'][()][:, 1][active(g['plastic_strain'][()])]
        out[case] = ('plastic', float(y.min()), float(y.max())) if y.size else \
            ('nothing', math.nan, math.nan)
    return out


def crossings(geometry, extent, nranks):
    """Per case: (strip edges inside the active range, strip edges)."""
    out = {}
    for case, origin, dx, ncells in geometry:
        edges = strip_edges(origin, dx, ncells, nranks)
        what, lo, hi = extent.get(case, ('nothing', math.nan, math.nan))
        out[case] = (sum(lo < e < hi for e in edges), len(edges))
    return out


def exact_counts(fa, fb, sa, sb, kind):
    """Steps, particles and iteration counts: what differs (every integer
    dataset bitwise, the summary's counts as text)."""
    bad = [n for n in check_ranks.dataset_names(fa) if fa[n].dtype.kind in 'iu' and
           (n not in fb or fa[n][()].tobytes() != fb[n][()].tobytes())]
    if kind == 'mpm':
        bad += check_ranks.compare_summaries(sa, sb)
    else:
        bad += ['summary ' + k for k in sa if re.search(
            r'(^|\.)(cases|steps|particles|nonlocal_\w+|ended_early|max_substeps)$', k)
            and sa[k] != sb.get(k)]
    return bad


def sweeps(f):
    """Nonlocal sweeps of the whole run (None when Algorithm 1 never iterated)."""
    n = [f[k][()].sum() for k in check_ranks.dataset_names(f)
         if k == 'nonlocal/iterations' or re.match(r'cases/[^/]+/iterations$', k)]
    total = int(sum(n)) if n else 0
    return total or None


def growth(fa, fb):
    """[(t, worst relative difference, dataset)] of every snapshot: how the
    difference to the serial run grows with time."""
    rows = []
    groups = []
    if 'snapshots' in fa:
        groups = ['snapshots/' + k for k in fa['snapshots'] if k != 'count']
    if 'cases' in fa:
        groups = ['cases/%s/%s' % (c, k) for c in fa['cases'] for k in fa['cases/' + c]
                  if k.startswith('snap_')]
    for g in groups:
        worst = (0.0, '')
        for n in fa[g]:
            if n == 'time' or g + '/' + n not in fb:
                continue
            worst = max(worst, (check_ranks.relative(fa[g][n][()], fb[g][n][()]), n))
        rows.append((g.rsplit('/', 1)[0] if 'cases' in g else '', float(fa[g]['time'][0]),
                     worst[0], worst[1]))
    return sorted(rows)


def station_growth(fa, fb):
    """How the stations' difference to the serial run grows with time (1D):
    [(label, t, d)] where d, the worst over the station datasets relative to
    each one's largest value, is first nonzero, first passes 1e-14 and
    1e-12, and at the end."""
    if 'stations/time' not in fa:
        return []
    t = fa['stations/time'][()]
    d = np.zeros(t.size)
    for n in fa['stations']:
        x = fa['stations/' + n][()]
        if x.ndim == 2 and x.shape[1] == t.size and 'stations/' + n in fb:
            s = np.nanmax(np.abs(x))
            if s > 0:
                d = np.fmax(d, np.nanmax(np.abs(x - fb['stations/' + n][()]), axis=0)/s)
    out = []
    for label, bound in (('first', 0.0), ('past 1e-14', 1e-14), ('past 1e-12', 1e-12)):
        i = np.flatnonzero(d > bound)
        if i.size:
            out.append((label, float(t[i[0]]), float(d[i[0]])))
    return out + [('end', float(t[-1]), float(d[-1]))] if out else []


def run_program(cmd, out, reuse):
    """Run cmd (its folder `out`), or with `reuse` keep what the same command
    left there; (wall seconds, output text, exit status, kept)."""
    record = out + '.json'
    if reuse and os.path.exists(record):
        with open(record) as fh:
            r = json.load(fh)
        if r['cmd'] == cmd and r['status'] == 0:
            return r['wall'], r['log'], 0, True
    subprocess.run(['rm', '-rf', out, record])
    t0 = time.monotonic()
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    wall = time.monotonic() - t0
    with open(record, 'w') as fh:
        json.dump({'cmd': cmd, 'status': r.returncode, 'wall': wall, 'log': r.stdout}, fh)
    return wall, r.stdout, r.returncode, False


def fmt_cross(cross):
    return ', '.join(('%s %d/%d' % (c, k, n)).strip() for c, (k, n) in cross.items())


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('decks', nargs='*')
    ap.add_argument('--ranks', default=[1, 2, 4], metavar='1,2,4',
                    type=lambda s: [int(n) for n in s.split(',') if n.strip()])
    ap.add_argument('--out', default=os.path.join(ROOT, 'build', 'every_deck'))
    ap.add_argument('--bin', default=os.path.join(ROOT, 'build', 'bin'))
    ap.add_argument('--launcher', default='mpirun --oversubscribe')
    ap.add_argument('--np-flag', default='-np')
    ap.add_argument('--tolerance', type=float, default=1e-12)
    mode = ap.add_mutually_exclusive_group()
    mode.add_argument('--quick', action='store_true')
    mode.add_argument('--full', action='store_true')
    ap.add_argument('--set', action='append', default=[], metavar='STEM:group.key=value')
    ap.add_argument('--reuse', action='store_true')
    ap.add_argument('--list', action='store_true')
    a = ap.parse_args()
    os.environ.setdefault('OMPI_ALLOW_RUN_AS_ROOT', '1')
    os.environ.setdefault('OMPI_ALLOW_RUN_AS_ROOT_CONFIRM', '1')

    inputs = os.path.join(ROOT, 'inputs')
    if a.decks:
        paths = [d if os.path.exists(d) else os.path.join(inputs, d + '.nml') for d in a.decks]
    else:
        paths = sorted(os.path.join(inputs, d) for d in os.listdir(inputs) if d.endswith('.nml'))
    plan = {} if a.full else QUICK if a.quick else PLAN
    extra = {}
    for s in a.set:
        stem, _, ov = s.partition(':')
        extra.setdefault(stem, []).append(ov)
    decks = []
    for p in paths:
        stem = os.path.basename(p)[:-4] if p.endswith('.nml') else os.path.basename(p)
        kind = deck_kind(p)
        ov = plan.get(stem, []) + extra.get(stem, [])
        if a.list:
            print('%-36s %-8s %s' % (stem, kind if kind not in ('point', 'implicit')
                                     else kind + ' (not here)', ' '.join(ov)))
        elif kind not in ('point', 'implicit'):
            decks.append((stem, p, kind, ov))
        elif a.decks:
            sys.exit('%s is a %s deck' % (p, 'wellposed-point' if kind == 'point' else
                                          'implicit (tests/regression/parallel_2d)'))
    if a.list:
        return 0

    launcher = shlex.split(a.launcher)
    rows, failed, t_all = [], False, time.monotonic()
    total_runs = len(decks)*(1 + len(a.ranks))
    k = 0
    for stem, path, kind, ov in decks:
        program = os.path.join(a.bin, 'wellposed-' + kind)
        name = scene_name(path)
        args = ['--no-plot', '--checkpoint-every', '0', path] + ov
        base = os.path.join(a.out, stem)
        os.makedirs(base, exist_ok=True)
        k += 1
        print('[%d/%d %6.0f s] %s: serial%s' % (k, total_runs, time.monotonic() - t_all, stem,
                                                ' ' + ' '.join(ov) if ov else ''), flush=True)
        ref = os.path.join(base, 'serial')
        wall, log, status, kept = run_program([program, '--out', ref] + args, ref, a.reuse)
        if status != 0:
            print('  FAIL: the serial run exited %d\n%s' % (status, log[-2000:]), flush=True)
            rows.append((stem, ov, 'serial', 'exit %d' % status, '-', '-', wall, 'FAIL'))
            failed = True
            k += len(a.ranks)
            continue
        fa = h5py.File(os.path.join(ref, name, 'run.h5'), 'r')
        sa = (check_ranks if kind == 'mpm' else check_ranks_2d).read_summary(
            os.path.join(ref, name, 'summary.txt'))
        geometry = geometry_1d(log, sa) if kind == 'mpm' else geometry_2d(log, sa, fa)
        extent = extent_1d(fa) if kind == 'mpm' else extent_2d(fa)
        nsweeps = sweeps(fa)
        print('  %.1f s%s; %s; strip edges crossed by the activity: %s%s' % (
            wall, ' (kept)' if kept else '',
            ', '.join(('%s %s %.3g..%.3g m' % (c, w, lo, hi)).strip()
                      for c, (w, lo, hi) in extent.items()),
            '; '.join('%d ranks %s' % (n, fmt_cross(crossings(geometry, extent, n)))
                      for n in (2, 4)),
            '; %d nonlocal sweeps' % nsweeps if nsweeps else ''), flush=True)
        rows.append((stem, ov, 'serial', '-', '-' if nsweeps is None else str(nsweeps),
                     '-', wall, ''))
        for n in a.ranks:
            k += 1
            print('[%d/%d %6.0f s] %s: %d rank%s' % (k, total_runs, time.monotonic() - t_all,
                                                     stem, n, 's' if n > 1 else ''), flush=True)
            d = os.path.join(base, 'np%d' % n)
            wall, log, status, kept = run_program(
                launcher + [a.np_flag, str(n), program, '--out', d] + args, d, a.reuse)
            if status != 0:
                print('  FAIL: exited %d\n%s' % (status, log[-2000:]), flush=True)
                rows.append((stem, ov, str(n), 'exit %d' % status, '-', '-', wall, 'FAIL'))
                failed = True
                continue
            fb = h5py.File(os.path.join(d, name, 'run.h5'), 'r')
            if kind == 'mpm':
                names, bad, worst, worst_name = check_ranks.compare_runs(fa, fb, a.tolerance)
                sb = check_ranks.read_summary(os.path.join(d, name, 'summary.txt'))
                bad += check_ranks.compare_summaries(sa, sb)
                bitwise = not check_ranks.compare_runs(fa, fb, bitwise=True)[1]
            else:
                names, bad, (worst, worst_name) = check_ranks_2d.compare_runs(fa, fb, a.tolerance)
                sb = check_ranks_2d.read_summary(os.path.join(d, name, 'summary.txt'))
                bad += check_ranks_2d.compare_summaries(sa, sb, a.tolerance)
                bitwise = worst == 0.0 and not bad
            counts = exact_counts(fa, fb, sa, sb, kind)
            cross = crossings(geometry, extent_1d(fb) if kind == 'mpm' else extent_2d(fb), n)
            trivial = n > 1 and (not cross or min(c for c, _ in cross.values()) == 0)
            if counts or any(re.search(r'\((missing|shape|not bitwise)', b) for b in bad):
                verdict = 'FAIL'
            elif bad:
                verdict = 'beyond %g' % a.tolerance
            else:
                verdict = 'bitwise' if bitwise else 'within %g' % a.tolerance
            if trivial:
                verdict += ', trivial: not counted'
            failed = failed or bool(bad) or bool(counts) or trivial
            worst_text = '0 (bitwise)' if bitwise else '%.1e (%s)' % (worst, worst_name) \
                if worst > 0 else '0 (the residuals aside)'
            rows.append((stem, ov, str(n), worst_text, 'yes' if not counts else 'NO',
                         fmt_cross(cross) if n > 1 else '-', wall, verdict))
            print('  %.1f s%s: %d datasets, worst %s; counts %s; strip edges crossed %s%s: %s'
                  % (wall, ' (kept)' if kept else '', len(names), worst_text,
                     'equal' if not counts else 'differ: ' + ', '.join(counts),
                     fmt_cross(cross) if n > 1 else '-',
                     '' if kind == 'mpm' else ', %d particles handed between ranks'
                     % check_ranks_2d.handed(log), verdict), flush=True)
            if bad:
                print('  beyond: ' + ', '.join(bad), flush=True)
            if kind == 'mpm':
                print('  conservation residuals (not compared): ' + ', '.join(
                    '%s %.1e' % (r, check_ranks.relative(fa[r][()], fb[r][()]))
                    for r in sorted(check_ranks.RESIDUALS) if r in fa and r in fb), flush=True)
            if n > 1 and not bitwise:
                print('  by snapshot: ' + ', '.join(
                    ('%s t=%.4g s %.1e' % (c, t, w)).strip() for c, t, w, _ in growth(fa, fb)),
                    flush=True)
                g = station_growth(fa, fb)
                if g:
                    print('  stations in time: ' + ', '.join('%s t=%.4g s %.1e' % r for r in g),
                          flush=True)

    header = ('| deck | overrides | ranks | worst relative difference (dataset) | counts equal '
              '(sweeps) | strip edges crossed | wall (s) | result |\n|---|---|---|---|---|---|---|---|')
    lines = [header] + ['| %s | %s | %s | %s | %s | %s | %.1f | %s |' % (
        stem, ' '.join('`%s`' % o for o in ov) if r == 'serial' else '', r, worst, counts, cross,
        wall, verdict) for stem, ov, r, worst, counts, cross, wall, verdict in rows]
    table = '\n'.join(lines)
    print('\n' + table)
    print('\n%d runs, %.0f s of their wall time (%.0f s this time); %s' % (
        len(rows), sum(r[6] for r in rows), time.monotonic() - t_all,
        'FAILED' if failed else 'all equal and counted'))
    with open(os.path.join(a.out, 'every_deck.md'), 'w') as fh:
        fh.write(table + '\n')
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main())
