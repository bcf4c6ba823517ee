"""A benchmark refuses a bad argument: exit status 1, nothing on standard
output (no measurement started), and standard error matching MESSAGE.

Usage: refused.py MESSAGE BIN_DIR PROGRAM [ARG ...]
"""
import os
import re
import subprocess
import sys


def main(argv):
    if len(argv) < 4:
        print(__doc__, file=sys.stderr)
        return 2
    message, bin_dir, program, args = argv[1], argv[2], argv[3], argv[4:]
    run = subprocess.run([os.path.join(bin_dir, program)] + args, capture_output=True,
                         text=True, timeout=50)
    problems = []
    if run.returncode != 1:
        problems.append(f'exit status {run.returncode}, expected 1')
    if run.stdout.strip():
        problems.append(f'standard output not empty: {run.stdout[:200]!r}')
    if not re.search(message, run.stderr):
        problems.append(f'standard error {run.stderr!r} does not match {message!r}')
    if 'Backtrace' in run.stderr or 'ERROR STOP' in run.stderr:
        problems.append('a crash report instead of a message')
    for p in problems:
        print(f'{program} {" ".join(args)}: {p}')
    if not problems:
        print(f'{program} {" ".join(args)}: refused: {run.stderr.strip()}')
    return 1 if problems else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
