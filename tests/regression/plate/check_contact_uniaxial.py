#!/usr/bin/env python3
"""The quasi-static implicit step with the frictionless contact platen
against the closed form (docs/research/implicit.md, "The contact platen").

check_contact_uniaxial.py PROGRAM DECK OUT [--velocity V ...] [ARG ...]

Runs DECK (the homogeneous elastic plate of plate_elastic_static.nml:
roller bottom, free sides) with platen = 'contact', top_lateral = 'free',
scheme = 'implicit', once per platen velocity V. The exact state is
uniaxial stress, sigma_yy = E / (1 - nu^2) eps_yy in plane strain, so per
case of the deck's study: the apparent modulus final_stress/final_strain
against E / (1 - nu^2) (K = 76 GPa, G = 26 GPa) within 2 eps (the finite
strain's first-order terms: measured 0.99 eps on every mesh, so the
linear limit holds exactly); Newton at most 3 solves a step (the tangent
is exact on the contact set); the run ended normally. Exit status 0 when
all hold.
"""
import os
import re
import subprocess
import sys

K, G = 76e9, 26e9
E = 9 * K * G / (3 * K + G)
NU = (3 * K - 2 * G) / (2 * (3 * K + G))
MODULUS = E / (1 - NU ** 2)


def summary(path):
    out = {}
    for line in open(path):
        key, _, value = line.partition(' = ')
        out[key.strip()] = value.split('#')[0].strip()
    return out


def main(argv):
    program, deck, out = argv[:3]
    rest = argv[3:]
    velocities = []
    while '--velocity' in rest:
        k = rest.index('--velocity')
        velocities.append(rest[k + 1])
        del rest[k:k + 2]
    failed = False
    for v in velocities or ['-0.25']:
        name = 'contact_v%s' % v.lstrip('-')
        cmd = [program, deck, '--out', out, '--name', name, '--no-plot', '--checkpoint-every',
               '0', '--force', 'time.scheme=implicit', 'time.dt=0.004', 'viscosity.a1=0',
               'viscosity.a2=0', "boundary.platen='contact'", "boundary.top_lateral='free'",
               'boundary.top_velocity=' + v] + rest
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        if p.returncode != 0:
            print('FAIL: %s exited %d\n%s' % (' '.join(cmd), p.returncode, p.stderr[-2000:]))
            return 1
        s = summary(os.path.join(out, name, 'summary.txt'))
        cases = sorted(k[:-len('.final_stress')] for k in s if k.endswith('.final_stress'))
        for c in cases:
            stress = float(s[c + '.final_stress']) * 1e6
            strain = float(s[c + '.final_strain'])
            err = stress / strain / MODULUS - 1
            solves = int(s[c + '.newton_solves_max'])
            ok = abs(err) <= 2 * strain and solves <= 3 and s[c + '.ended_early'] == 'false'
            failed = failed or not ok
            print('%s v = %s m/s, %s: strain %.4e, apparent modulus / E/(1-nu^2) - 1 = %.3e '
                  '(%.2f strain; bound 2), Newton solves a step at most %d (bound 3): %s'
                  % ('ok  ' if ok else 'FAIL', v, c, strain, err, err / strain, solves,
                     'ok' if ok else 'beyond'))
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
