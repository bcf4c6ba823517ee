#!/usr/bin/env python3
"""Two MPM runs that must agree, or one that must fail cleanly.

  regions_same.py EXE DECK_A DECK_B NAME [--exe-b EXE_B] [--tolerance T]
                  [--absolute NAME=TOL ...] [--skip NAME ...] [--stderr-b REGEX]
                  [driver args]
      runs EXE on DECK_A and EXE_B (default EXE) on DECK_B (--no-plot
      --checkpoint-every 0, the same run folder name NAME under a/ and b/)
      and compares every summary.txt figure and run.h5 dataset of the two
      folders (tests/regression/mpm_reference/reference.py compare; wall
      times and build stamps excepted): bitwise, or with --tolerance T
      within T relative to each dataset's largest magnitude. Each
      --absolute NAME=TOL (a summary key or run.h5 dataset, e.g. a balance
      residual whose own size is round-off, where a relative comparison
      means nothing) is compared as max |A - B| <= TOL instead. Each
      --skip NAME (a summary key or run.h5 dataset) is not compared (a
      figure one of the two runs cannot know; the caller says why). With
      --stderr-b, run B's standard error must match REGEX (Python re).
  regions_same.py --fail REGEX EXE DECK NAME [driver args]
      the run must exit non-zero, print REGEX (searched in its standard
      output and error together) and leave no finished folder NAME.
Exit 0 when every check holds.
"""
import os, re, shutil, subprocess, sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, '..', 'mpm_reference'))
import reference  # noqa: E402


def fail(argv):
    regex, exe, deck, name = argv[:4]
    root = os.path.join(os.getcwd(), 'regions_fail_' + name)
    shutil.rmtree(root, ignore_errors=True)
    os.makedirs(root)
    cmd = [exe, '--out', root, '--name', name, '--no-plot', deck] + argv[4:]
    p = subprocess.run(cmd, capture_output=True, text=True)
    text = p.stdout + p.stderr
    print(' '.join(cmd))
    print('exit status', p.returncode)
    print(text[-3000:])
    if p.returncode == 0:
        print('FAIL: the run succeeded')
        return 1
    if not re.search(regex, text, re.S):
        print(f'FAIL: the output does not match {regex!r}')
        return 1
    if os.path.exists(os.path.join(root, name)):
        print(f'FAIL: {name} exists: a failed run left output that looks finished')
        return 1
    print('ok   non-zero exit, clear message, no finished output')
    return 0


def absolute_difference(a, b, key):
    """max |A - B| of summary key or run.h5 dataset `key`, None if absent."""
    import h5py
    import numpy as np
    sa = reference.read_summary(os.path.join(a, 'summary.txt'))
    sb = reference.read_summary(os.path.join(b, 'summary.txt'))
    if key in sa and key in sb:
        return abs(float(sa[key]) - float(sb[key]))
    with h5py.File(os.path.join(a, 'run.h5'), 'r') as fa, \
            h5py.File(os.path.join(b, 'run.h5'), 'r') as fb:
        if key in fa and key in fb:
            return float(np.max(np.abs(fa[key][()] - fb[key][()])))
    return None


def main(argv):
    if argv[:1] == ['--fail']:
        return fail(argv[1:])
    exe, deck_a, deck_b, name = argv[:4]
    rest = argv[4:]
    regex, exe_b, tol, absolute, skip = None, exe, None, {}, []
    while rest[:1] and rest[0] in ('--stderr-b', '--exe-b', '--tolerance', '--absolute',
                                   '--skip'):
        if rest[0] == '--skip':
            skip.append(rest[1])
        elif rest[0] == '--stderr-b':
            regex = rest[1]
        elif rest[0] == '--absolute':
            key, value = rest[1].split('=')
            absolute[key] = float(value)
        elif rest[0] == '--exe-b':
            exe_b = rest[1]
        else:
            tol = float(rest[1])
        rest = rest[2:]
    root = os.path.join(os.getcwd(), 'regions_same_' + name)
    shutil.rmtree(root, ignore_errors=True)
    folders = []
    for tag, deck, program in (('a', deck_a, exe), ('b', deck_b, exe_b)):
        out = os.path.join(root, tag)
        os.makedirs(out)
        cmd = [program, '--out', out, '--name', name, '--no-plot', '--checkpoint-every', '0',
               deck] + rest
        p = subprocess.run(cmd, capture_output=True, text=True)
        if p.returncode != 0:
            print(' '.join(cmd))
            print(p.stdout[-3000:], p.stderr[-3000:])
            print(f'FAIL: run {tag} exit status {p.returncode}')
            return 1
        if tag == 'b' and regex and not re.search(regex, p.stderr):
            print(f'FAIL: run b\'s stderr does not match {regex!r}:\n{p.stderr}')
            return 1
        folders.append(os.path.join(out, name))
    counted, bad = reference.compare(folders[0], folders[1], tol)
    for key in skip:
        bad = [b for b in bad if not re.search(r'[ /]' + re.escape(key) + r'( |:|$)', b)]
        print(f'skip {key}: not compared')
    for key, limit in absolute.items():
        bad = [b for b in bad if not re.search(r'[ /]' + re.escape(key) + r'( |$)', b)]
        diff = absolute_difference(folders[0], folders[1], key)
        ok = diff is not None and diff <= limit
        print(('ok   ' if ok else 'FAIL ') + f'{key}: max |A - B| = {diff}, limit {limit}')
        if not ok:
            bad.append(f'{key}: absolute difference {diff} > {limit}')
    for b in bad:
        print('FAIL ' + b)
    if counted == 0:
        print('FAIL: nothing compared')
        return 1
    if not bad:
        print(f'ok   {counted} figures and datasets ' +
              ('identical' if tol is None else f'agree within {tol} relative'))
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
