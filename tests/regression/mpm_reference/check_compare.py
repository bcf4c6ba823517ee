#!/usr/bin/python3
"""reference.py compare on folders that differ, without --tolerance: a
number against another number, a number against not_applicable, a float
dataset against a string one, floats against floats, NaN against a number.
Each is named in a clear line, the exit status is 1, no Python traceback;
with --tolerance the close numbers pass and the others still fail; equal
folders pass."""
import os, subprocess, sys, tempfile
import h5py, numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REFERENCE = os.path.join(HERE, 'reference.py')


def folder(root, name, summary, data):
    path = os.path.join(root, name)
    os.makedirs(path)
    with open(os.path.join(path, 'summary.txt'), 'w') as f:
        for k, v in summary.items():
            f.write(f'{k} = {v}  # a comment\n')
    with h5py.File(os.path.join(path, 'run.h5'), 'w') as f:
        for k, v in data.items():
            f[k] = v
    return path


def compare(ref, run, *extra):
    p = subprocess.run([sys.executable, REFERENCE, 'compare', ref, run, *extra],
                       capture_output=True, text=True)
    return p.returncode, p.stdout + p.stderr


def main():
    failures = []
    with tempfile.TemporaryDirectory() as root:
        ref = folder(root, 'ref', {'c_head': '1.986080370488785E+003', 'peak': '5.0E+006',
                                   'ratio': '1.5E+000', 'scene': 'bar'},
                     {'a': np.array([1.0, 2.0, 3.0]), 'b': np.array([1.0, 2.0]),
                      'c': np.array([4.0, 5.0]), 'label': 'x'})
        run = folder(root, 'run', {'c_head': '1.986080370488786E+003', 'peak': '7.0E+006',
                                   'ratio': 'not_applicable', 'scene': 'bar'},
                     {'a': np.array([1.0, 2.0, 3.0 + 1e-15]), 'b': np.array(['1', '2'],
                                                                          dtype='S1'),
                      'c': np.array([4.0, np.nan]), 'label': 'x'})
        status, out = compare(ref, run)
        expect = ['c_head = 1.986080370488785E+003 (reference) vs 1.986080370488786E+003',
                  'peak = 5.0E+006 (reference) vs 7.0E+006',
                  'ratio = 1.5E+000 (reference) vs not_applicable: one is a number',
                  'run.h5: a differs, largest |diff|/max|ref| =',
                  'run.h5: b is float64 in the reference, |S1 in the run',
                  'run.h5: c differs, NaN or infinity']
        if status != 1:
            failures.append(f'exit status {status}, expected 1')
        if 'Traceback' in out:
            failures.append('a Python traceback')
        failures += [f'no line "{e}"' for e in expect if e not in out]
        status, out_tol = compare(ref, run, '--tolerance', '1e-12')
        if status != 1 or 'c_head' in out_tol or ' a differs' in out_tol or \
                'peak = ' not in out_tol or 'c differs' not in out_tol:
            failures.append('--tolerance 1e-12: the close numbers should pass, the others '
                            'fail')
        status, out2 = compare(ref, ref)
        if status != 0:
            failures.append(f'a folder against itself: exit {status}\n{out2}')
    print(out)
    for f in failures:
        print('FAIL:', f)
    print('reference.py compare:', 'OK' if not failures else f'{len(failures)} failures')
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
