#!/usr/bin/env python3
"""An allocation that fails past the memory estimate ends with a message
naming the deck, exit status 1, no runtime backtrace and no finished folder.

usage: alloc_failure.py MPM SRC_DIR WORK_DIR

The bar of tests/regression/mpm/decks/sr_short.nml stretched to 200 km (about
800 000 particles, an estimate near 1.3 GB, under MemAvailable) runs with its
address space limited to 500 MB (RLIMIT_AS), so the particle storage cannot
be allocated although the estimate let the deck through. Skipped (exit 77)
when the machine has less than the estimate available: the estimate then
refuses the deck first, which memory_estimate_refused tests.
"""
import os
import resource
import shutil
import subprocess
import sys

LIMIT = 500 * 2**20


def limit_memory():
    resource.setrlimit(resource.RLIMIT_AS, (LIMIT, LIMIT))


def main():
    mpm, src, work = sys.argv[1], os.path.abspath(sys.argv[2]), os.path.abspath(sys.argv[3])
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    deck = os.path.join(src, 'tests', 'regression', 'mpm', 'decks', 'sr_short.nml')
    cmd = [mpm, deck, 'grid.length=200000', 'time.t_end=3e-3', '--out', work, '--no-plot',
           '--checkpoint-every', '0']
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=120, preexec_fn=limit_memory)
    if 'more than the machine has available' in p.stderr:
        print('skipped: the estimate refuses the deck on this machine first')
        return 77
    problems = []
    if p.returncode != 1:
        problems.append(f'exit status {p.returncode}, not 1')
    for needle in (deck, 'out of memory'):
        if needle not in p.stderr:
            problems.append(f'standard error does not say "{needle}"')
    if 'Backtrace' in p.stderr or 'Error allocating' in p.stderr:
        problems.append('a runtime backtrace instead of the message')
    if os.path.exists(os.path.join(work, 'sr_short')):
        problems.append('a finished-looking folder sr_short/ was left')
    print(p.stderr.strip()[-600:])
    print('ok' if not problems else 'FAIL: ' + '; '.join(problems))
    return 1 if problems else 0


if __name__ == '__main__':
    sys.exit(main())
