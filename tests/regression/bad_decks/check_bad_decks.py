#!/usr/bin/env python3
"""Bad decks against the programs that read decks: every one must be
refused at reading or set-up, before the first step.

  check_bad_decks.py decks KIND OUT EXE [EXE ...] [--launcher CMD] [--skip NAME]
                     [--only REGEX]
      runs every bad deck of KIND ('mpm': any_*, mpm_* and the generated
      wrong-type decks of the bar and the plate; 'point': any_*, point_* and
      the point deck's) through each EXE (optionally under the launcher, e.g.
      "mpirun -np 2") with --out OUT/<exe>/<deck>; --skip leaves a deck
      out, --only keeps the decks whose file name matches REGEX;
  check_bad_decks.py batch KIND OUT EXE [--driver DRIVER]
      the same decks as one batch file through `EXE --batch FILE` (or,
      with --driver, through `EXE DRIVER FILE`: wellposed-batch).

Each refusal must: exit non-zero; say on standard error, in a line of the
program's own, the deck's path (and the `! expect:` regex of the deck, or
that of EXPECT below); show no "STOP n", gfortran backtrace or signal; take
no step (no progress line on standard output); and leave nothing under its
--out folder (no run folder, finished or .partial). A batch must exit 1
and list every job as failed, with no finished job folder.

The wrong-type decks are made here from the good decks (GOOD): for every
key that any deck of inputs/ and tests/ gives in a group the good deck's
program reads, one deck with that key's value replaced by a value of
another type ('text' for a number or a logical, 1.5 for an integer or a
word; a key is taken for an integer when every deck gives it a whole
number). Free-text keys (title, name, label, out_dir, reference_label: a
number read into them is the text of that number) have no wrong type.
Exit status 0 when every refusal is as described.

Without a launcher each program starts as an Open MPI singleton, whose
start (a helper daemon, transport probes) costs most of a refusal's time:
the runs here get an isolated singleton on the shared-memory transport
(FAST_START, unless the environment sets them), which refuses the same.
"""
import glob
import os
import re
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, '..', '..', '..'))

# Messages of the decks that cannot carry an `! expect:` comment.
EXPECT = {
    'any_empty.nml': r'holds no namelist group \(empty, or comments only\)',
    'any_binary.nml': r'not a text file \(byte 1 is 127\)',
    'any_comments_only.nml': r'holds no namelist group \(empty, or comments only\)',
}
# The good decks the wrong-type decks are made from, by kind, and the
# groups their program reads.
GOOD = {
    'mpm': [('tests/regression/parallel/decks/short_wave.nml',
             'scene grid time viscosity material initial load stations output nonlocal'),
            ('tests/regression/plate/decks/plate_small_local.nml',
             'scene plate grid time material boundary viscosity stations nonlocal study output'),
            ('inputs/axisymmetric_thick_cylinder.nml',
             'scene cylinder grid time material boundary viscosity nonlocal output')],
    'point': [('inputs/fig2_4_directional_stiffness.nml',
               'run material initial leg probe chapter3')],
}
FAST_START = {'OMPI_MCA_ess_singleton_isolated': '1', 'OMPI_MCA_pml': 'ob1',
              'OMPI_MCA_btl': 'self,vader'}
FREE_TEXT = {'title', 'name', 'label', 'out_dir', 'reference_label'}
FORBIDDEN = re.compile(r'^\s*(ERROR )?STOP\b|Backtrace for this error|^#\d+ +0x|'
                       r'Program received signal|Error termination', re.M)
STEPPED = re.compile(r'^\s*t = .* ms \(|\bstep \d+|particles, .* nodes, dt =', re.M)


def code_of(text):
    """Deck text without comments (outside quotes)."""
    out = []
    for line in text.splitlines():
        q, keep = None, ''
        for ch in line:
            if q:
                q = None if ch == q else q
            elif ch in '\'"':
                q = ch
            elif ch == '!':
                break
            keep += ch
        out.append(keep)
    return '\n'.join(out)


def groups_of(text):
    """[(group, body)] of a deck's namelist groups."""
    return [(m.group(1).lower(), m.group(2)) for m in
            re.finditer(r'&(\w+)(.*?)(?:/|&end)', code_of(text), re.S)]


def keys_of(body):
    """{key: value text} of one group's body (a quoted value reads 'S')."""
    body = re.sub(r"'[^']*'|\"[^\"]*\"", "'S'", body)
    parts = re.split(r'(?:^|[\s,])(\w+)\s*(?:\([^)]*\))?\s*=', body)
    return {parts[i].lower(): parts[i + 1].strip().rstrip(',').strip()
            for i in range(1, len(parts) - 1, 2)}


def wrong_value(values):
    """A literal of another type than that of `values` (every value a deck
    gives the key)."""
    v = [x.strip().lower() for x in values]
    if v[0].startswith(("'", '"')):
        return '1.5'
    if v[0] in ('.true.', '.false.', 't', 'f'):
        return "'text'"
    if all(re.fullmatch(r'[-+]?\d+', x) for x in v):
        return '1.5'
    return "'text'"


def known_keys(kind, groups):
    """{group: {key: [values]}} over every deck of `kind` in inputs/ and tests/."""
    keys = {}
    for path in glob.glob(os.path.join(ROOT, 'inputs', '*.nml')) + \
            glob.glob(os.path.join(ROOT, 'tests', '**', '*.nml'), recursive=True):
        if '/bad' in path or 'bad_' in os.path.basename(path):
            continue
        try:
            text = open(path, encoding='utf-8').read()
        except (UnicodeDecodeError, OSError):
            continue
        found = groups_of(text)
        if ('scene' in dict(found)) != (kind == 'mpm'):
            continue
        for g, body in found:
            if g in groups:
                for k, v in keys_of(body).items():
                    keys.setdefault(g, {}).setdefault(k, []).append(v)
    return keys


def wrong_type_decks(kind, out):
    """Write the wrong-type decks of `kind` into `out`; [(path, regex)]."""
    os.makedirs(out, exist_ok=True)
    made = []
    for good, groups in GOOD[kind]:
        text = open(os.path.join(ROOT, good)).read()
        stem = os.path.splitext(os.path.basename(good))[0]
        present = [g for g, _ in groups_of(text)]
        for g, keys in sorted(known_keys(kind, groups.split()).items()):
            for k, v in sorted(keys.items()):
                if k in FREE_TEXT:
                    continue
                bad = f'{k} = {wrong_value(v)}'
                if g in present:
                    new = re.sub(r'(&' + g + r')\b', r'\1 ' + bad + ',', text, count=1,
                                 flags=re.I)
                    # the key given twice: the later (good) one would win, so drop it
                    new = drop_key(new, g, k)
                else:
                    new = text + f'\n&{g} {bad} /\n'
                name = f'{kind}_wrong_type_{stem}_{g}_{k}.nml'
                with open(os.path.join(out, name), 'w') as f:
                    f.write(f'! wrong type: &{g} {bad}\n' + new)
                made.append((os.path.join(out, name),
                             rf'&{g}\b.*(wrong type|{k}\b|not one of|must be)'))
    return made


def drop_key(text, group, key):
    """`text` without the first `key = value` inside &group after the
    inserted bad one (the good deck's own)."""
    m = re.search(r'&' + group + r'\b', text, re.I)
    end = text.find('/', m.end())
    body = text[m.end():end]
    first = re.search(r'\b' + key + r'\s*=', body, re.I)
    second = re.search(r'\b' + key + r'\s*=\s*[^,\n/]*(,\s*[-+0-9.eE]+)*', body[first.end():],
                       re.I)
    if not second:
        return text
    s, e = first.end() + second.start(), first.end() + second.end()
    return text[:m.end()] + body[:s] + body[e:] + text[end:]


def corpus(kind, out):
    """[(path, regex)] of every bad deck of `kind`."""
    decks = []
    for path in sorted(glob.glob(os.path.join(HERE, '*.nml'))):
        base = os.path.basename(path)
        if not (base.startswith(kind + '_') or base.startswith('any_')):
            continue
        expect = EXPECT.get(base)
        if expect is None:
            m = re.search(r'^! expect: (.*)$', open(path, errors='replace').read(), re.M)
            expect = m.group(1).strip() if m else None
        decks.append((path, expect))
    return decks + wrong_type_decks(kind, os.path.join(out, 'generated'))


def problems(deck, expect, rc, out, err, folder):
    bad = []
    if rc == 0:
        bad.append('exit status 0')
    own = [line for line in err.splitlines() if line.startswith('wellposed-')]
    if not any(deck in line for line in own):
        bad.append('no error line of the program names the deck')
    if expect and not re.search(expect, err):
        bad.append(f'message does not match /{expect}/')
    if FORBIDDEN.search(out + err):
        bad.append('a STOP code, backtrace or signal: ' + FORBIDDEN.search(out + err).group(0))
    if STEPPED.search(out):
        bad.append('it took steps: ' + STEPPED.search(out).group(0))
    if os.path.isdir(folder) and os.listdir(folder):
        bad.append('left ' + ', '.join(sorted(os.listdir(folder))) + ' in its --out folder')
    return bad


def start_env():
    """The environment of a run without a launcher (FAST_START added)."""
    env = dict(os.environ)
    for key, value in FAST_START.items():
        env.setdefault(key, value)
    return env


def mode_decks(kind, out, exes, launcher, skip, only):
    failed = 0
    decks = [d for d in corpus(kind, out) if re.search(only, os.path.basename(d[0]))]
    for exe in exes:
        for deck, expect in decks:
            base = os.path.basename(deck)
            if base in skip:
                continue
            folder = os.path.join(out, os.path.basename(exe), base[:-4])
            shutil.rmtree(folder, ignore_errors=True)
            os.makedirs(folder)
            cmd = launcher + [exe, '--out', folder, '--no-plot', deck]
            p = subprocess.run(cmd, capture_output=True, text=True, errors='replace', timeout=120,
                               env=None if launcher else start_env())
            bad = problems(deck, expect, p.returncode, p.stdout, p.stderr, folder)
            if bad:
                failed += 1
                print(f'FAIL {os.path.basename(exe)} {base}: ' + '; '.join(bad))
                print('    ' + (p.stdout + p.stderr).strip().replace('\n', '\n    ')[:2000])
    print(f'{len(decks)} bad decks x {len(exes)} program(s): {failed} not refused as they must be')
    return 1 if failed else 0


def mode_batch(kind, out, exe, driver, skip):
    decks = [d for d, _ in corpus(kind, out) if os.path.basename(d) not in skip]
    shutil.rmtree(os.path.join(out, 'runs'), ignore_errors=True)
    batch = os.path.join(out, f'bad_{kind}.txt')
    with open(batch, 'w') as f:
        f.write(''.join(f'{d}\n' for d in decks))
    runs = os.path.join(out, 'runs')
    if driver:
        cmd = [exe, '--out', runs, driver, batch, '--no-plot']
    else:
        cmd = [exe, '--batch', batch, '--out', runs, '--no-plot']
    p = subprocess.run(cmd, capture_output=True, text=True, errors='replace', timeout=1200,
                       env=start_env())
    bad = []
    if p.returncode != 1:
        bad.append(f'exit status {p.returncode}, not 1 (some job failed)')
    if FORBIDDEN.search(p.stdout + p.stderr):
        bad.append('a STOP code, backtrace or signal')
    summary = os.path.join(out, 'runs', f'bad_{kind}', 'batch_summary.txt')
    if not os.path.exists(summary):
        bad.append('no batch_summary.txt')
    else:
        text = open(summary).read()
        nfail = len(re.findall(r'\bfailed\b', text))
        if nfail < len(decks):
            bad.append(f'{nfail} jobs listed as failed of {len(decks)}')
    finished = [os.path.join(r, 'summary.txt') for r, _, fs in os.walk(os.path.join(out, 'runs'))
                if 'summary.txt' in fs and not r.endswith('.partial')]
    if finished:
        bad.append('finished run folders: ' + ', '.join(finished[:5]))
    for b in bad:
        print('FAIL ' + b)
    if bad:
        print((p.stdout + p.stderr)[-3000:])
    print(f'batch of {len(decks)} bad decks through {" ".join(cmd)}: '
          f'{"as required" if not bad else "NOT as required"}')
    return 1 if bad else 0


def main(argv):
    args = list(argv[1:])
    launcher, skip, driver, only = [], set(), None, ''
    while '--launcher' in args:
        i = args.index('--launcher')
        launcher = args[i + 1].split()
        del args[i:i + 2]
    while '--skip' in args:
        i = args.index('--skip')
        skip.add(args[i + 1])
        del args[i:i + 2]
    if '--only' in args:
        i = args.index('--only')
        only = args[i + 1]
        del args[i:i + 2]
    if '--driver' in args:
        i = args.index('--driver')
        driver = args[i + 1]
        del args[i:i + 2]
    if len(args) < 4 or args[0] not in ('decks', 'batch') or args[1] not in GOOD:
        sys.stderr.write(__doc__)
        return 2
    mode, kind, out, exes = args[0], args[1], os.path.abspath(args[2]), args[3:]
    os.makedirs(out, exist_ok=True)
    if mode == 'decks':
        return mode_decks(kind, out, exes, launcher, skip, only)
    return mode_batch(kind, out, exes[0], driver, skip)


if __name__ == '__main__':
    sys.exit(main(sys.argv))
