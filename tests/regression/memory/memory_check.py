#!/usr/bin/env python3
"""wellposed-mpm and wellposed-point refuse a deck whose estimated memory exceeds --max-memory or
the machine's MemAvailable, naming the deck and the estimate, before it
allocates anything: exit status 1, no run folder, a small peak resident size.

usage: memory_check.py MPM POINT SRC_DIR WORK_DIR
"""
import os
import resource
import subprocess
import sys

BAR = 'tests/regression/mpm/decks/sr_short.nml'
PLATE = 'tests/regression/plate/decks/plate_small_local.nml'
# far below what any refused run would take once its particles were allocated
MAX_PEAK_KB = 200_000


def refused(label, cmd, deck, needles, work, name):
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    p = subprocess.run(cmd + ['--out', work], capture_output=True, text=True, timeout=60)
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    problems = []
    if p.returncode != 1:
        problems.append(f'exit status {p.returncode}, not 1')
    for n in [deck, 'the deck needs about', 'nothing was allocated'] + needles:
        if n not in p.stderr:
            problems.append(f'standard error does not say "{n}": {p.stderr.strip()!r}')
    for d in (name, name + '.partial'):
        if os.path.exists(os.path.join(work, d)):
            problems.append(f'{d}/ was created')
    if peak > max(before, MAX_PEAK_KB):
        problems.append(f'peak resident size {peak} kB: memory was taken')
    print(f'{label}: ' + ('ok' if not problems else 'FAIL: ' + '; '.join(problems)))
    return not problems


def main():
    mpm, point = sys.argv[1], sys.argv[2]
    src, work = os.path.abspath(sys.argv[3]), os.path.abspath(sys.argv[4])
    os.makedirs(work, exist_ok=True)
    bar, plate = os.path.join(src, BAR), os.path.join(src, PLATE)
    ok = True
    ok &= refused('bar over --max-memory 8M', [mpm, bar, '--max-memory', '8M'], bar,
                  ['--max-memory 8 MiB', '1600 particles'], work, 'sr_short')
    ok &= refused('plate over --max-memory 4G', [mpm, plate, '--max-memory', '4G',
                                                 'grid.dx=0.004'], plate,
                  ['--max-memory 4.0 GiB'], work, 'plate_small_local')
    ok &= refused('bar over MemAvailable', [mpm, bar, 'grid.dx=2e-5'], bar,
                  ['MemAvailable'], work, 'sr_short')
    # a point deck of 400000 increments (its history about 150 MiB)
    deck = os.path.join(work, 'long_path.nml')
    with open(os.path.join(src, 'inputs/fig2_7_left_uniaxial.nml')) as f:
        text = f.read().replace('n_inc = 300', 'n_inc = 400000')
    with open(deck, 'w') as f:
        f.write(text)
    ok &= refused('point over --max-memory 100M', [point, deck, '--max-memory', '100M',
                                                    '--no-plot'], deck,
                  ['--max-memory 100 MiB', '400001 increments'], work, 'fig2_7_left_uniaxial')
    p = subprocess.run([mpm, bar, '--max-memory', '4X', '--out', work], capture_output=True,
                       text=True, timeout=60)
    good = p.returncode == 1 and '--max-memory needs a size' in p.stderr
    print('--max-memory 4X refused: ' + ('ok' if good else 'FAIL: ' + p.stderr.strip()))
    ok &= good
    return 0 if ok else 1


if __name__ == '__main__':
    sys.exit(main())
