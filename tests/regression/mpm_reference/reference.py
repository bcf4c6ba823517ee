#!/usr/bin/python3
"""Run the MPM decks of decks.txt and compare a run folder with a reference.

reference.py run --bin DIR --out ROOT [--old] [--long] [NAME ...]
    runs each deck (default: every deck not marked long; --long adds those)
    with --no-plot --checkpoint-every 0 into ROOT/NAME. With --old the bar
    decks run through DIR/wellposed-mpm and the plate decks through
    DIR/wellposed-mpm2d (the programs before the one engine); without it
    every deck runs through DIR/wellposed-mpm.
reference.py compare REF RUN [--tolerance T]
    compares the run folder RUN with the reference folder REF: every
    summary.txt figure (recursively: a plate study writes one per case) and
    every run.h5 dataset. Bitwise unless a key below says otherwise; with
    --tolerance T every float within T relative (to the dataset's largest
    magnitude), the exemptions below always.
reference.py compare-all REF_ROOT RUN_ROOT [--tolerance T] [NAME ...]
    compare for every deck of decks.txt present in both roots.
reference.py check --exe EXE --out ROOT NAME [--tolerance T]
    the regression test: runs deck NAME of decks.txt through EXE into
    ROOT/NAME and compares its summary.txt with the stored reference
    expected/NAME/summary.txt (docs/guide/mpm.md; their history is in git),
    bitwise but for the keys of TOLERANCES (with --tolerance T, every
    figure within T relative: a build other than Release, see
    CMakeLists.txt).

Exit status 0 when every compared figure agrees.
"""
import argparse, os, re, subprocess, sys, time, warnings
import h5py, numpy as np

warnings.simplefilter("ignore", RuntimeWarning)
HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, '..', '..', '..'))

# Summary keys not compared, with the reason: they describe the run, not
# its result.
NOT_RESULTS = {
    'wall_time_s': 'wall clock', 'wall_seconds': 'wall clock', 'elapsed_s': 'wall clock',
    'seconds': 'wall clock', 'build': 'build stamp', 'build_type': 'build stamp',
    'compiler': 'build stamp', 'git': 'build stamp', 'version': 'build stamp',
    'date': 'wall clock', 'started': 'wall clock', 'finished': 'wall clock',
    'deck': 'the path of the deck', 'out': 'the run folder', 'command': 'the command line',
    'program': 'the program name', 'host': 'machine', 'ranks_hostname': 'machine',
    'bytes_per_particle': 'measured memory (peak resident size)',
}
# Substrings of summary keys and run.h5 names that are timings (wall clock
# and the shares of it) or build stamps.
TIMING = ('wall', 'time_s', 'seconds', 'timing', 'cpu_', 'rate_per_s', 'per_second',
          'ns_per_particle_step', 'share_', 'sweep_cost', 'git_revision', 'version')


# Summary keys compared within a relative tolerance instead of bitwise, with
# the reason. (Empty: every stored figure is reproduced bit for bit.)
TOLERANCES = {}
# Summary keys (suffixes) that hold a message: compared up to its first ': '
# (the step and time it names), since the words are the UMAT host's.
MESSAGES = ('end_reason',)


def decks():
    rows = []
    with open(os.path.join(HERE, 'decks.txt')) as f:
        for line in f:
            line = line.split('#', 1)[0].split()
            if not line:
                continue
            name, kind, deck, *rest = line
            long_ = 'long' in rest
            rows.append((name, kind, deck, [r for r in rest if r != 'long'], long_))
    return rows


def is_timing(key):
    k = key.lower()
    return k in NOT_RESULTS or any(s in k for s in TIMING)


def read_summary(path):
    values = {}
    with open(path) as f:
        for line in f:
            line = line.split('#', 1)[0].strip()
            if '=' in line:
                k, v = line.split('=', 1)
                values[k.strip()] = v.strip()
    return values


def number(v):
    try:
        return float(v)
    except ValueError:
        return None


def tolerance_of(per_key, key, tol):
    """The relative tolerance for summary key `key`: per_key's entry (a
    number, or a tuple whose first item is the number) or `tol`."""
    t = per_key.get(key, tol)
    return float(t[0] if isinstance(t, (tuple, list)) else t)


def within(x, y, t):
    """True when the numbers x and y (None: not a number) agree within t
    relative to the larger; never for t = 0 (bitwise: the caller compared
    the text already) or a non-number."""
    if x is None or y is None or not t > 0 or not (np.isfinite(x) and np.isfinite(y)):
        return False
    return abs(x - y) <= t * max(abs(x), abs(y))


def compare_summary(a, b, tol, where, bad, per_key=None):
    sa, sb = read_summary(a), read_summary(b)
    per_key = per_key or {}
    n = 0
    for k in sorted(set(sa) | set(sb)):
        if is_timing(k):
            continue
        if k not in sa:
            continue      # a figure the reference did not have yet: nothing to compare
        if k not in sb:
            bad.append(f'{where}: summary key {k} missing from the run')
            continue
        n += 1
        x, y = number(sa[k]), number(sb[k])
        if sa[k] == sb[k]:
            continue
        if k.endswith(MESSAGES) and sa[k].split(': ')[0] == sb[k].split(': ')[0]:
            continue
        if within(x, y, tolerance_of(per_key, k, tol)):
            continue
        if (x is None) != (y is None):
            bad.append(f'{where}: {k} = {sa[k]} (reference) vs {sb[k]}: one is a number, '
                       f'the other not')
            continue
        bad.append(f'{where}: {k} = {sa[k]} (reference) vs {sb[k]}')
    return n


def datasets(f):
    names = []
    f.visit(lambda n: names.append(n) if isinstance(f[n], h5py.Dataset) else None)
    return names


def compare_h5(a, b, tol, where, bad):
    n = 0
    with h5py.File(a, 'r') as fa, h5py.File(b, 'r') as fb:
        na, nb = set(datasets(fa)), set(datasets(fb))
        for k in sorted(na ^ nb):
            bad.append(f'{where}: dataset {k} only in {"reference" if k in na else "run"}')
        for k in sorted(na & nb):
            if is_timing(k):
                continue
            x, y = fa[k][()], fb[k][()]
            n += 1
            if np.shape(x) != np.shape(y):
                bad.append(f'{where}: {k} shape {np.shape(x)} vs {np.shape(y)}')
                continue
            x, y = np.asarray(x), np.asarray(y)
            numeric = 'biufc'
            if (x.dtype.kind in numeric) != (y.dtype.kind in numeric):
                bad.append(f'{where}: {k} is {x.dtype} in the reference, {y.dtype} in the run')
                continue
            if 'f' in (x.dtype.kind, y.dtype.kind):
                x, y = x.astype(float), y.astype(float)
                same = np.array_equal(x, y, equal_nan=True)
                if same:
                    continue
                if not np.array_equal(np.isfinite(x), np.isfinite(y)):
                    bad.append(f'{where}: {k} differs, NaN or infinity where the other has '
                               f'a number')
                    continue
                s = np.nanmax(np.abs(x)) if x.size else 0.0
                d = np.nanmax(np.abs(x - y)) if x.size else 0.0
                r = d / s if s > 0 else d
                if tol > 0 and r <= tol:
                    continue
                bad.append(f'{where}: {k} differs, largest |diff|/max|ref| = {r:.3e}')
            elif not np.array_equal(x, y):
                bad.append(f'{where}: {k} differs (non-float data)')
    return n


def compare(ref, run, tol):
    bad, counted = [], 0
    found = False
    for dirpath, _, files in os.walk(ref):
        rel = os.path.relpath(dirpath, ref)
        other = os.path.join(run, rel)
        for fname in files:
            if fname not in ('summary.txt', 'run.h5'):
                continue
            found = True
            where = os.path.join(rel, fname)
            if not os.path.exists(os.path.join(other, fname)):
                bad.append(f'{where}: missing in the run')
                continue
            fn = compare_summary if fname == 'summary.txt' else compare_h5
            counted += fn(os.path.join(dirpath, fname), os.path.join(other, fname), tol, where, bad)
    if not found:
        bad.append(f'{ref}: no summary.txt or run.h5 (no reference)')
    return counted, bad


def run_decks(args):
    names = set(args.names)
    for name, kind, deck, overrides, long_ in decks():
        if names and name not in names:
            continue
        if long_ and not args.long and name not in names:
            continue
        prog = 'wellposed-mpm2d' if (args.old and kind == '2d') else 'wellposed-mpm'
        path = os.path.join(ROOT, deck)
        if args.old:
            # the programs before the one engine know no &scene kind
            os.makedirs(os.path.join(args.out, '_decks'), exist_ok=True)
            with open(path) as f:
                text = re.sub(r"kind\s*=\s*'[a-z]+',\s*", '', f.read())
            path = os.path.join(args.out, '_decks', os.path.basename(deck))
            with open(path, 'w') as f:
                f.write(text)
        cmd = ['nice', '-n', '10', os.path.join(args.bin, prog), '--out', args.out, '--name', name,
               '--no-plot', '--checkpoint-every', '0', path] + overrides
        t0 = time.time()
        p = subprocess.run(cmd, capture_output=True, text=True)
        os.makedirs(args.out, exist_ok=True)
        with open(os.path.join(args.out, name + '.log'), 'w') as f:
            f.write(' '.join(cmd) + '\n' + p.stdout + p.stderr)
        print(f'{name}: exit {p.returncode} in {time.time() - t0:.1f} s', flush=True)


def check(args):
    row = [r for r in decks() if r[0] == args.name]
    if not row:
        print(f'{args.name}: not a deck of decks.txt')
        return 1
    name, kind, deck, overrides, _ = row[0]
    cmd = [args.exe, '--out', args.out, '--name', name, '--no-plot', '--checkpoint-every', '0',
           os.path.join(ROOT, deck)] + overrides
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        print(' '.join(cmd) + '\n' + p.stdout + p.stderr)
        print(f'FAIL: exit status {p.returncode}')
        return 1
    bad = []
    ref = os.path.join(HERE, 'expected', name, 'summary.txt')
    n = compare_summary(ref, os.path.join(args.out, name, 'summary.txt'), args.tolerance,
                        name, bad, TOLERANCES)
    for b in bad:
        print('FAIL:', b)
    how = 'all equal' if args.tolerance == 0.0 else f'all within {args.tolerance:g} relative'
    print(f'{name}: {n} summary figures compared with {ref}: '
          f'{how if not bad else f"{len(bad)} differ"}')
    return 1 if bad else 0


def main():
    ap = argparse.ArgumentParser()
    sub = ap.add_subparsers(dest='cmd', required=True)
    r = sub.add_parser('run')
    r.add_argument('--bin', required=True)
    r.add_argument('--out', required=True)
    r.add_argument('--old', action='store_true')
    r.add_argument('--long', action='store_true')
    r.add_argument('names', nargs='*')
    c = sub.add_parser('compare')
    c.add_argument('ref')
    c.add_argument('run')
    c.add_argument('--tolerance', type=float, default=0.0)
    k = sub.add_parser('check')
    k.add_argument('--exe', required=True)
    k.add_argument('--out', required=True)
    k.add_argument('name')
    k.add_argument('--tolerance', type=float, default=0.0)
    a = sub.add_parser('compare-all')
    a.add_argument('ref')
    a.add_argument('run')
    a.add_argument('--tolerance', type=float, default=0.0)
    a.add_argument('names', nargs='*')
    args = ap.parse_args()
    if args.cmd == 'run':
        run_decks(args)
        return 0
    if args.cmd == 'check':
        return check(args)
    pairs = [(args.ref, args.run, 'run')] if args.cmd == 'compare' else [
        (os.path.join(args.ref, n), os.path.join(args.run, n), n)
        for n, *_ in decks() if (not args.names or n in args.names)
        and os.path.isdir(os.path.join(args.run, n))]
    failed = 0
    for ref, run, name in pairs:
        counted, bad = compare(ref, run, args.tolerance)
        print(f'{name}: {"OK" if not bad else "DIFFERS"} ({counted} figures and datasets)')
        for b in bad[:20]:
            print('   ', b)
        failed += bool(bad)
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main())
