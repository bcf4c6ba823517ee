#!/usr/bin/env python3
"""A run whose UMAT's STATEV is shorter than our model's leaves out what it cannot know.

  short_statev.py EXE DECK NAME NSTATV KEY ... [--absent NAME ...]
      runs EXE on DECK (--no-plot, run folder NAME under short_statev_NAME/);
      it must finish and its folder give every summary KEY as
      `not_applicable  # the UMAT's STATEV has no <what> slot (NSTATV = N)`,
      hold no run.h5 dataset whose last name is an --absent NAME (a snapshot
      field that would read past NSTATV), still hold snapshots (some dataset
      under a snap_ group), and its .xdmf files name only datasets run.h5
      holds (tests/regression/xdmf_check.py); a plate's console line says
      "no band: NSTATV = N ...", not a band width.
Exit 0 when every check holds.
"""
import os, re, shutil, subprocess, sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, '..'))
sys.path.insert(0, os.path.join(HERE, '..', 'mpm_reference'))
import reference  # noqa: E402
import xdmf_check  # noqa: E402
import h5py  # noqa: E402


def main(argv):
    exe, deck, name, nstatv = argv[:4]
    keys, absent, rest = [], [], argv[4:]
    root = os.path.join(os.getcwd(), 'short_statev_' + name)
    shutil.rmtree(root, ignore_errors=True)
    os.makedirs(root)
    cmd = [exe, '--out', root, '--name', name, '--no-plot', '--checkpoint-every', '0', deck]
    p = subprocess.run(cmd, capture_output=True, text=True)
    print(' '.join(cmd))
    if p.returncode != 0:
        print(p.stdout[-3000:], p.stderr[-3000:])
        print(f'FAIL: exit status {p.returncode}')
        return 1
    folder = os.path.join(root, name)
    while rest:
        if rest[0] == '--absent':
            absent.append(rest[1])
            rest = rest[2:]
        else:
            keys.append(rest.pop(0))
    bad = []
    with open(os.path.join(folder, 'summary.txt')) as f:
        lines = f.read().splitlines()
    why = re.compile(r"= not_applicable +# the UMAT's STATEV has no .+ slot \(NSTATV = "
                     + re.escape(nstatv) + r"\)$")
    for k in keys:
        hit = [line for line in lines if line.split(' = ')[0].strip() == k]
        if not hit or not why.search(hit[0]):
            bad.append(f'summary {k}: {hit[0] if hit else "missing"}')
    with h5py.File(os.path.join(folder, 'run.h5'), 'r') as f:
        names = reference.datasets(f)
    for n in names:
        if n.split('/')[-1] in absent:
            bad.append(f'run.h5 holds {n}, a field the STATEV has no slot for')
    if not any('snap_' in n for n in names):
        bad.append('run.h5 holds no snapshot')
    bad += xdmf_check.problems(folder)
    # a plate's console line says there is no band, not a width of zero
    if 'band FWHM' in p.stdout or ('&plate' in open(deck).read()
                                   and 'no band: NSTATV = ' + nstatv not in p.stdout):
        bad.append('the console line of a case gives a band width: ' +
                   [line for line in p.stdout.splitlines() if 'done in' in line][0])
    for b in bad:
        print('FAIL ' + b)
    if not bad:
        print(f'ok   {len(keys)} keys not_applicable, {len(absent)} fields left out, '
              f'{len(names)} datasets')
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
