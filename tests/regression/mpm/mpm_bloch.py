#!/usr/bin/env python3
"""The bar's step linearised (docs/research/timestep.md): stability
limits and group velocities from the eigenvalues of the whole discrete step.

usage: mpm_bloch.py [--check EXE DECK]

The step of eq. 4.9-4.13 on an elastic bar (c = 1, dx = 1) whose ppc
particles per cell sit evenly and stay at rest, periodic over N cells: the
state is every particle's velocity and stress, the map one step of MUSL or
USL with the lumped, consistent (M_P a = f) or blended (M_P a = M_L H^-1 f,
H = (M_L + M_P)/2) grid acceleration, as wellposed-mpm takes it (linear
weights; GIMP's are the same at rest). Printed:

- the largest cfl with every eigenvalue of the map within the unit circle
  (bisection), beside the closed form of wellposed_mpm_bar_cfl_limit;
- the group velocity of MUSL with the blended mass, per wavelength in
  cells, from the eigenvalues' phases (the acoustic branch).

--check exits 1 unless: every limit equals its closed form to 1e-3; the
program refuses cfl = 1 on DECK naming the same limit (to the 4 digits it
prints) for the five cases below 1; and the blended group velocity of waves
of 3 cells and longer is within 6 % of c at cfl 0.5 while at cfl 0.2 the
3-cell wave lags by more than 10 % (the wake behind a short pulse: those
waves fall behind it; measured 0.84 and 0.95 of c).
"""
import re
import subprocess
import sys

import numpy as np

# Closed forms at ppc = 2 (a = 5/8, b = 3/16: mu(pi) = 1/4) and ppc = 4
# (mu(pi) = 5/16); tests/unit/mpm/test_mpm_cfl_limit.pf has the derivation.
CLOSED = {('musl', 'lumped', 2): np.sqrt(3.0), ('musl', 'consistent', 2): 1.0,
          ('musl', 'blended', 2): np.sqrt(5.0 / 8.0), ('usl', 'lumped', 2): 2.0 / np.sqrt(7.0),
          ('usl', 'consistent', 2): 1.0 / np.sqrt(7.0), ('usl', 'blended', 2): 2.0 / np.sqrt(44.8),
          ('musl', 'blended', 4): 2.0 / np.sqrt(8.0 / (21.0 / 16.0))}


def weights(n, ppc):
    """Node-by-particle linear weights and gradients, periodic, dx = 1."""
    xp = (np.arange(n * ppc) + 0.5) / ppc
    s = np.zeros((n, xp.size))
    d = np.zeros((n, xp.size))
    cell = np.floor(xp).astype(int)
    frac = xp - cell
    cols = np.arange(xp.size)
    s[cell % n, cols] = 1.0 - frac
    s[(cell + 1) % n, cols] = frac
    d[cell % n, cols] = -1.0
    d[(cell + 1) % n, cols] = 1.0
    return xp, s, d


def step(n, ppc, scheme, mass, cfl):
    """The map of (v_p, sigma_p) over one step, rho = E = 1."""
    xp, s, d = weights(n, ppc)
    mp = vol = 1.0 / ppc
    m_l = np.diag(s.sum(1) * mp)
    m_p = mp * s @ s.T
    force = -vol * d                                    # f = force @ sigma
    if mass == 'lumped':
        acc = np.linalg.solve(m_l, force)
    elif mass == 'consistent':
        acc = np.linalg.solve(m_p, force)
    else:
        acc = np.linalg.solve(m_p, m_l @ np.linalg.solve(0.5 * (m_l + m_p), force))
    rebuild = np.linalg.solve(m_l, mp * s)              # grid velocity from the particles
    dt = cfl
    p = xp.size
    vv, vs = np.eye(p), dt * s.T @ acc                  # FLIP: v_p += dt sum phi a
    if scheme == 'musl':
        gv, gs = rebuild @ vv, rebuild @ vs             # rebuilt from the new v_p
    else:
        gv, gs = rebuild, dt * acc                      # USL: the updated grid velocity
    sv, ss = dt * d.T @ gv, np.eye(p) + dt * d.T @ gs
    return np.block([[vv, vs], [sv, ss]]), xp


def spectral_radius(n, ppc, scheme, mass, cfl):
    return np.max(np.abs(np.linalg.eigvals(step(n, ppc, scheme, mass, cfl)[0])))


def limit(scheme, mass, ppc, n=48):
    """Bisection for the largest stable cfl (N = 48 holds theta = pi and
    comes within 4e-4 of MUSL lumped's inner maximum)."""
    lo, hi = 0.01, 2.5
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        if spectral_radius(n, ppc, scheme, mass, mid) <= 1.0 + 1e-9:
            lo = mid
        else:
            hi = mid
    return lo


def group_velocity(cfl, n=60, ppc=2):
    """Wavelength (cells) and group velocity of MUSL blended's acoustic
    branch: the eigenvalue phases of the Bloch-reduced map per theta."""
    a, xp = step(n, ppc, 'musl', 'blended', cfl)
    p = xp.size
    th, om = [], []
    for m in range(1, n // 2 + 1):
        k = 2.0 * np.pi * m / n
        basis = np.zeros((2 * p, 2 * ppc), complex)
        for f in range(2):
            for j in range(ppc):
                idx = np.arange(j, p, ppc)
                basis[f * p + idx, f * ppc + j] = np.exp(1j * k * xp[idx])
        t = np.linalg.lstsq(basis, a @ basis, rcond=None)[0]
        th.append(k)
        om.append(np.max(np.abs(np.angle(np.linalg.eigvals(t)))) / cfl)
    th, om = np.array(th), np.array(om)
    return 2.0 * np.pi / th, np.gradient(om, th)


def program_limit(exe, deck, scheme, mass, ppc):
    """The limit wellposed-mpm names when it refuses cfl = 1."""
    cmd = [exe, '--out', '/dev/null/none', '--no-plot', deck, 'time.cfl=1',
           f"time.scheme='{scheme}'", f"time.mass='{mass}'", f'grid.ppc={ppc}']
    p = subprocess.run(cmd, capture_output=True, text=True)
    m = re.search(r'is above ([0-9.]+), where', p.stderr)
    return float(m.group(1)) if m else None


def main(argv):
    check = '--check' in argv
    bad = 0
    for (scheme, mass, ppc), closed in CLOSED.items():
        lim = limit(scheme, mass, ppc)
        ok = abs(lim - closed) <= 1e-3 * closed
        line = f'{scheme:4s} {mass:10s} ppc {ppc}: eigenvalues {lim:.4f}, closed form {closed:.4f}'
        if check and closed < 1.0:
            exe, deck = argv[argv.index('--check') + 1:argv.index('--check') + 3]
            named = program_limit(exe, deck, scheme, mass, ppc)
            line += f', wellposed-mpm {named}'
            ok = ok and named is not None and abs(named - closed) <= 6e-5
        print(('ok   ' if ok else 'FAIL ') + line)
        bad += not ok
    print('MUSL blended, group velocity / c by wavelength (cells):')
    cg = {}
    for cfl in (0.05, 0.2, 0.5, 0.6):
        lam, g = group_velocity(cfl)
        cg[cfl] = (lam, g)
        print(f'  cfl {cfl:4.2f}: ' + '  '.join(f'{l:.1f}:{v:.3f}' for l, v in zip(lam, g)
                                             if l in (10.0, 6.0, 5.0, 4.0, 3.0, 2.5)))
    lam, g = cg[0.5]
    long_enough = lam >= 3.0 - 1e-9
    ok = np.max(np.abs(g[long_enough] - 1.0)) <= 0.06
    lam2, g2 = cg[0.2]
    lag = 1.0 - g2[np.argmin(np.abs(lam2 - 3.0))]
    ok = ok and lag > 0.10
    print(('ok   ' if ok else 'FAIL ') + 'cfl 0.5: |c_g/c - 1| <= '
          f'{np.max(np.abs(g[long_enough] - 1.0)):.3f} from 3 cells; cfl 0.2: the 3-cell wave '
          f'lags by {lag:.3f}')
    bad += not ok
    return 1 if (check and bad) else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
