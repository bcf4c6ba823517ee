#!/usr/bin/env python3
"""Regression check of fig. 2.6's verdict per mesh (docs/research/figures.md):
hardening, perfectly plastic and softening bars at dx = 0.25 and 0.125 m.

  fig2_6_order_check.py EXE INPUTS OUT

Runs inputs/fig2_3_local_dx0.25.nml (perfectly plastic), fig2_6_hardening.nml
and fig2_6_softening.nml on a 350 m bar to 170 ms with stations at 100, 200
and 300 m (the head passes 300 m by 150 ms; the 700 m decks' first 300 m are
the same scene), at both cell sizes. Passes when
  - the plastic head speed orders softening > plastic > hardening on both
    meshes, each within 0.5 % of its closed form C_P (c_plastic_head), and the
    head-minus-tail separation rate orders the same way;
  - at dx = 0.25 m the 300 m peaks of the three agree within 1.5 %: the
    coarse mesh shows no amplitude ordering;
  - at dx = 0.125 m softening's 300 m peak is the largest, at least 5 % above
    both others;
  - every model's 300 m peak grows by at least 1.5x from dx = 0.25 to 0.125 m:
    the amplitude is mesh-divergent whatever the hardening (section 2.4).
Measured: heads 2127 / 2041 / 1986 m/s; 300 m peaks 16.22 / 16.40 / 16.43 MPa
at dx = 0.25 and 35.66 / 31.24 / 33.69 MPa at 0.125 (softening / plastic /
hardening), growth 2.20 / 1.90 / 2.05x.
Exit status 0 on success, 1 with a message otherwise.
"""
import os
import subprocess
import sys

MODELS = (('plastic', 'fig2_3_local_dx0.25'), ('hardening', 'fig2_6_hardening'),
          ('softening', 'fig2_6_softening'))
REDUCE = ['grid.length=350', 'time.t_end=0.17', 'stations.first=100',
          'stations.spacing=100', 'stations.count=3', 'output.snapshot_dt=0.17']


def summary(path):
    out = {}
    with open(path) as f:
        for line in f:
            if '=' in line:
                k, v = line.split('=', 1)
                out[k.strip()] = v.split('#', 1)[0].strip()
    return out


def main(argv):
    if len(argv) != 4:
        sys.stderr.write(__doc__)
        return 2
    exe, inputs, out = argv[1:]
    runs = {}
    for dx in ('0.25', '0.125'):
        for model, stem in MODELS:
            root = os.path.join(out, 'dx' + dx)
            cmd = [exe, os.path.join(inputs, stem + '.nml'), 'grid.dx=' + dx] + REDUCE + \
                  ['--out', root, '--no-plot', '--checkpoint-every', '0']
            r = subprocess.run(cmd, capture_output=True, text=True)
            if r.returncode != 0:
                print('FAIL: %s at dx = %s exited %d:\n%s' % (stem, dx, r.returncode, r.stderr))
                return 1
            runs[model, dx] = summary(os.path.join(root, stem, 'summary.txt'))
    fails = []

    def val(model, dx, key):
        return float(runs[model, dx][key])

    for dx in ('0.25', '0.125'):
        head = {m: val(m, dx, 'c_head') for m, _ in MODELS}
        sep = {m: val(m, dx, 'separation_rate') for m, _ in MODELS}
        print('dx = %s: head %s m/s, separation %s m/s' % (
            dx, ' / '.join('%.0f' % head[m] for m in ('softening', 'plastic', 'hardening')),
            ' / '.join('%.1f' % sep[m] for m in ('softening', 'plastic', 'hardening'))))
        if not head['softening'] > head['plastic'] > head['hardening']:
            fails.append('dx = %s: head speeds not ordered softening > plastic > hardening' % dx)
        if not sep['softening'] > sep['plastic'] > sep['hardening']:
            fails.append('dx = %s: separation rates not ordered' % dx)
        for m, _ in MODELS:
            cp = val(m, dx, 'c_plastic_head')
            if abs(head[m] / cp - 1) > 0.005:
                fails.append('dx = %s, %s: head %.1f m/s not within 0.5 %% of C_P %.1f' %
                             (dx, m, head[m], cp))
    peak = {(m, dx): abs(val(m, dx, 'station_3_peak')) for m, _ in MODELS for dx in ('0.25', '0.125')}
    for dx in ('0.25', '0.125'):
        print('dx = %s: 300 m peaks %s MPa (softening / plastic / hardening)' % (
            dx, ' / '.join('%.2f' % (peak[m, dx] / 1e6) for m in ('softening', 'plastic', 'hardening'))))
    coarse = [peak[m, '0.25'] for m, _ in MODELS]
    if max(coarse) / min(coarse) - 1 > 0.015:
        fails.append('dx = 0.25: the 300 m peaks differ by %.2f %% (> 1.5 %%)' %
                     (100 * (max(coarse) / min(coarse) - 1)))
    for m in ('plastic', 'hardening'):
        if not peak['softening', '0.125'] >= 1.05 * peak[m, '0.125']:
            fails.append('dx = 0.125: softening peak not 5 %% above %s' % m)
    for m, _ in MODELS:
        g = peak[m, '0.125'] / peak[m, '0.25']
        print('%s: 300 m peak grows %.2fx from dx = 0.25 to 0.125 m' % (m, g))
        if g < 1.5:
            fails.append('%s: 300 m peak grows only %.2fx under refinement' % (m, g))
    for f in fails:
        print('FAIL: ' + f)
    return 1 if fails else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
