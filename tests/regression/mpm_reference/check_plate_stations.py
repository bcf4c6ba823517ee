#!/usr/bin/python3
"""Stations of a plate (decks/plate_stations.nml): run the deck and check
 - every case has cases/<case>/stations/ in run.h5, station by sample, on
   the time axis k sample_dt;
 - each station reads a particle whose reference position is nearest its
   point (scaled with the case): no particle of the case's lattice lies
   nearer;
 - the plate is mirror symmetric about x = width/2, so the mirrored pair of
   stations has the same sigma_yy and sigma_xx histories, and opposite v_x
   and sigma_xy, to round-off (1e-9 of the largest magnitude);
 - summary.txt's station figures are those of the histories.

check_plate_stations.py EXE OUT
"""
import os, subprocess, sys
import h5py, numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, '..', '..', '..', 'common'))
from summary_text import read_summary  # noqa: E402
DECK = os.path.join(HERE, 'decks', 'plate_stations.nml')
WIDTH, HEIGHT, PPC, SAMPLE_DT = 2.0, 3.0, 2, 1e-4
POINTS = [(0.4, 1.4), (1.6, 1.4), (1.0, 3.0)]
CASES = {'h0.5': 0.5, 'h0.25': 0.25}


def main(exe, out):
    fails = []
    p = subprocess.run([exe, '--out', out, '--no-plot', '--checkpoint-every', '0', DECK],
                       capture_output=True, text=True)
    if p.returncode != 0:
        print(p.stdout, p.stderr)
        return 1
    folder = os.path.join(out, 'plate_stations')
    sm = read_summary(folder)
    with h5py.File(os.path.join(folder, 'run.h5'), 'r') as f:
        for tag, dx in CASES.items():
            g = f[f'cases/{tag}/stations']
            t, x, y = g['time'][()], g['x'][()], g['y'][()]
            h = {k: g[k][()] for k in ('sigma_xx', 'sigma_yy', 'sigma_xy', 'velocity_x',
                                       'velocity_y')}
            if any(v.shape != (len(POINTS), len(t)) for v in h.values()):
                fails.append(f'{tag}: histories not station by sample')
                continue
            if np.max(np.abs(t - SAMPLE_DT * np.arange(len(t)))) > 1e-12:
                fails.append(f'{tag}: the time axis is not k sample_dt')
            lp = dx / PPC
            xs = np.arange(0.5 * lp, WIDTH, lp)
            ys = np.arange(0.5 * lp, HEIGHT, lp)
            px, py = np.meshgrid(xs, ys)
            for s, (qx, qy) in enumerate(POINTS):
                best = np.min((px - qx) ** 2 + (py - qy) ** 2)
                got = (x[s] - qx) ** 2 + (y[s] - qy) ** 2
                if got > best + 1e-12:
                    fails.append(f'{tag}: station {s + 1} reads ({x[s]}, {y[s]}), not a '
                                 f'nearest particle of ({qx}, {qy})')
            if abs(x[0] + x[1] - WIDTH) > 1e-12 or y[0] != y[1]:
                fails.append(f'{tag}: stations 1 and 2 do not read mirrored particles')
            for k, sign in (('sigma_yy', 1), ('sigma_xx', 1), ('velocity_x', -1),
                            ('sigma_xy', -1), ('velocity_y', 1)):
                a, b = h[k][0], sign * h[k][1]
                scale = max(np.max(np.abs(a)), 1e-300)
                d = np.max(np.abs(a - b)) / scale
                print(f'{tag}: {k} mirrored pair differs by {d:.2e} of its largest value')
                if d > 1e-9:
                    fails.append(f'{tag}: {k} of the mirrored stations differ by {d:.2e}')
            for s in range(len(POINTS)):
                k = f'{tag}.station_{s + 1}'
                dyy = h['sigma_yy'][s] - h['sigma_yy'][s][0]
                j = int(np.argmax(np.abs(dyy)))
                checks = {k + '_x': x[s], k + '_y': y[s], k + '_sigma_yy_extreme': dyy[j],
                          k + '_t_sigma_yy_extreme': t[j],
                          k + '_v_y_final': h['velocity_y'][s][-1]}
                for key, want in checks.items():
                    got = float(sm.get(key, 'nan'))
                    if not abs(got - want) <= 1e-14 * max(abs(want), 1e-300):
                        fails.append(f'{key} = {got}, the histories give {want}')
    for f_ in fails:
        print('FAIL:', f_)
    print('plate stations:', 'OK' if not fails else f'{len(fails)} failures')
    return 1 if fails else 0


if __name__ == '__main__':
    sys.exit(main(*sys.argv[1:3]))
