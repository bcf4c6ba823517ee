#!/usr/bin/env python3
"""Every summary the regression tests wrote holds finite figures only.

  summaries_finite.py DIR       walks DIR for summary.txt and
                                batch_summary.txt files (a plate study
                                writes one per case) and fails, naming file,
                                line and key, on any value that is NaN or
                                Inf; a figure that does not apply must read
                                `not_applicable  # why` (docs/guide/decks.md).
                                A batch summary's quoted error lines
                                (`error: ...`, e.g. of the bad decks, which
                                name the Inf they refused) are not figures.
  summaries_finite.py --self-test   the walk on a made-up folder with one
                                NaN and one Inf must fail, and on a clean
                                one pass.
Exit status 0 when every summary is finite (and there is at least one).
"""
import os
import re
import sys
import tempfile

NONFINITE = re.compile(r'(?<![A-Za-z_])[-+]?(nan|inf|infinity)(?![A-Za-z_])', re.I)
NAMES = ('summary.txt', 'batch_summary.txt')


def walk(root):
    """(number of summaries, [problems])."""
    found, bad = 0, []
    for dirpath, _, files in os.walk(root):
        for name in files:
            if name not in NAMES:
                continue
            found += 1
            path = os.path.join(dirpath, name)
            with open(path, errors='replace') as f:
                for n, line in enumerate(f, 1):
                    if line.strip().startswith('error:'):
                        continue
                    value = line.split('#', 1)[0]
                    if '=' in value:
                        value = value.split('=', 1)[1]
                    if NONFINITE.search(value):
                        bad.append(f'{path}:{n}: {line.strip()}')
    return found, bad


def self_test():
    with tempfile.TemporaryDirectory() as d:
        os.makedirs(os.path.join(d, 'a', 'case'))
        with open(os.path.join(d, 'a', 'summary.txt'), 'w') as f:
            f.write('c_head = NaN  # m/s\nwidth = 1.0E+00\n')
        with open(os.path.join(d, 'a', 'case', 'summary.txt'), 'w') as f:
            f.write('peak = -Infinity\nnote = not_applicable  # no pulse: NaN is not written\n'
                    '    error: wellposed-mpm: error: a.nml: &load: peak = NaN is not finite\n')
        n, bad = walk(d)
        if n != 2 or len(bad) != 2:
            print(f'FAIL: the walk found {n} summaries and {len(bad)} non-finite figures '
                  f'(expected 2 and 2): {bad}')
            return 1
        os.remove(os.path.join(d, 'a', 'summary.txt'))
        with open(os.path.join(d, 'a', 'case', 'summary.txt'), 'w') as f:
            f.write('note = not_applicable  # no pulse: NaN is not written\ninfo = 2.5E+00\n')
        n, bad = walk(d)
        if bad:
            print(f'FAIL: a clean summary was reported: {bad}')
            return 1
    print('self-test: NaN and -Infinity found, not_applicable and comments left alone')
    return 0


def main(argv):
    if len(argv) != 2:
        sys.stderr.write(__doc__)
        return 2
    if argv[1] == '--self-test':
        return self_test()
    n, bad = walk(argv[1])
    for b in bad:
        print('FAIL non-finite figure: ' + b)
    if n == 0:
        print(f'FAIL: no summary.txt under {argv[1]} (run the regression tests first)')
        return 1
    print(f'{n} summaries under {argv[1]}: {len(bad)} non-finite figures')
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
