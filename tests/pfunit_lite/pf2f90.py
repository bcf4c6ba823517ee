#!/usr/bin/env python3
"""pf2f90: turn pFUnit 4 .pf test files into plain Fortran (pfunit_lite).

Usage:
    pf2f90.py --outdir DIR --driver DRIVER.F90 TEST.pf [TEST2.pf ...]

For each TEST.pf it writes DIR/TEST.F90: the test module with every directive
replaced by a call on the `funit` module of pfunit_lite, as pFUnit 4 does:

    call assertEqual(<args as written>, location=SourceLocation('TEST.pf', N))
    if (anyExceptions()) return

with `#line` markers so that compiler messages point at the .pf file. It also
writes DRIVER.F90, a program that runs every @test (with @before/@after around
it), prints `N passed, N failed[, N skipped]` and ends with `error stop 1` if
any test failed.

Only the directives listed in SUPPORTED are accepted; anything else stops with
a message naming the file, the line and what to do. Standard library only.
"""

import argparse
import os
import re
import sys

# Directive (lower case) -> (Fortran name, minimum operands counting a
# tolerance= keyword, maximum positional arguments, allowed keywords).
# The message must always be given as message=: most pFUnit 4 assertions put a
# KeywordEnforcer dummy before it, so a positional message does not compile.
SUPPORTED = {
    # name: (Fortran name, minimum operands, maximum positional, keywords)
    'assertequal': ('assertEqual', 2, 3, {'message', 'tolerance'}),
    'assertrelativelyequal': ('assertRelativelyEqual', 3, 3, {'message', 'tolerance'}),
    'asserttrue': ('assertTrue', 1, 1, {'message'}),
    'assertfalse': ('assertFalse', 1, 1, {'message'}),
    'assertlessthan': ('assertLessThan', 2, 2, {'message'}),
    'assertlessthanorequal': ('assertLessThanOrEqual', 2, 2, {'message'}),
    'assertgreaterthan': ('assertGreaterThan', 2, 2, {'message'}),
    'assertgreaterthanorequal': ('assertGreaterThanOrEqual', 2, 2, {'message'}),
    'assertisfinite': ('assertIsFinite', 1, 1, {'message'}),
    'assertisnan': ('assertIsNaN', 1, 1, {'message'}),
    'assertall': ('assertAll', 1, 1, {'message'}),
    'assertany': ('assertAny', 1, 1, {'message'}),
}

# Valid in pFUnit 4 but not (yet) implemented here.
PFUNIT_ONLY = {
    'assertnotequal', 'assertnotall', 'assertnone', 'assertsameshape',
    'assertfail', 'assertexceptionraised', 'assertassociated',
    'assertnotassociated', 'assertunassociated', 'assertequivalent',
    'assertequaluserdefined', 'testcase', 'testparameter', 'suite',
    'mpitest', 'mpiassertequal', 'mpiasserttrue', 'mpiassertfalse',
}

# Accepted by pFUnit's parser but the generated code does not compile.
PFUNIT_BROKEN = {
    'assertisinfinite', 'assertthat', 'assertismemberof', 'assertcontains',
    'assertispermutationof',
}

# @test(...) options that change which tests run or how; refused rather than
# silently ignored.
TEST_OPTIONS_REFUSED = {
    'npes': 'MPI tests (npes=) need real pFUnit',
    'ifdef': 'conditional tests (ifdef=) are not supported',
    'ifndef': 'conditional tests (ifndef=) are not supported',
    'type': 'test case types (type=) are not supported',
    'testparameters': 'parameterized tests (testParameters=) are not supported',
    'cases': 'parameterized tests (cases=) are not supported',
}

MAX_LINE = 100  # target length of generated lines (gfortran limit is 132)

EXTEND_HINT = 'extend tests/pfunit_lite (pf2f90.py + funit.f90) or build with real pFUnit'


class PfError(Exception):
    """Error in a .pf file, reported as `file:line: error: message`."""

    def __init__(self, path, line, message):
        super().__init__('%s:%d: error: %s' % (path, line, message))


# ----------------------------------------------------------------------------
# Lexical helpers (quote aware)
# ----------------------------------------------------------------------------

def strip_comment(text):
    """Remove a trailing `!` comment that is outside string literals."""
    quote = None
    for i, c in enumerate(text):
        if quote:
            if c == quote:
                quote = None  # a doubled quote re-enters on the next char
        elif c in ('"', "'"):
            quote = c
        elif c == '!':
            return text[:i]
    return text


def split_top_level(text, path, line):
    """Split on commas outside (), [], and string literals."""
    args, depth, quote, cur = [], 0, None, []
    for c in text:
        if quote:
            cur.append(c)
            if c == quote:
                quote = None
            continue
        if c in ('"', "'"):
            quote = c
        elif c in '([':
            depth += 1
        elif c in ')]':
            depth -= 1
            if depth < 0:
                raise PfError(path, line, 'unbalanced brackets in directive arguments')
        elif c == ',' and depth == 0:
            args.append(''.join(cur).strip())
            cur = []
            continue
        cur.append(c)
    if quote:
        raise PfError(path, line, 'unterminated string in directive arguments')
    if depth != 0:
        raise PfError(path, line, 'unbalanced brackets in directive arguments')
    last = ''.join(cur).strip()
    if last or args:
        args.append(last)
    if any(a == '' for a in args):
        raise PfError(path, line, 'empty argument in directive')
    return args


def matching_paren(text, start):
    """Index of the `)` closing the `(` at text[start], or -1."""
    depth, quote = 0, None
    for i in range(start, len(text)):
        c = text[i]
        if quote:
            if c == quote:
                quote = None
            continue
        if c in ('"', "'"):
            quote = c
        elif c in '([':
            depth += 1
        elif c in ')]':
            depth -= 1
            if depth == 0:
                return i if c == ')' else -1
    return -1


KEYWORD_RE = re.compile(r'^([A-Za-z]\w*)\s*=(?!=)')


def wrap_statement(pieces, indent):
    """Join pieces into free-form lines shorter than MAX_LINE.

    Breaks preferably between pieces; a piece too long for one line is cut
    anywhere with `&` at the end and `&` at the start of the next line, which
    free form allows even inside names and character literals.
    """
    lines, cur = [], indent
    for piece in pieces:
        if len(cur) + len(piece) + 2 <= MAX_LINE:
            cur += piece
            continue
        if cur.strip():
            lines.append(cur + '&')
            cur = indent + '  & '
        while len(cur) + len(piece) + 2 > MAX_LINE:
            room = MAX_LINE - len(cur) - 2
            lines.append(cur + piece[:room] + '&')
            piece = piece[room:]
            cur = indent + '  &'
        cur += piece
    lines.append(cur)
    return '\n'.join(lines) + '\n'


# ----------------------------------------------------------------------------
# .pf translation
# ----------------------------------------------------------------------------

DIRECTIVE_RE = re.compile(r'^\s*@(\w+)\s*(.*)$', re.DOTALL)
MODULE_RE = re.compile(r'^\s*module\s+(\w+)\s*(!.*)?$', re.IGNORECASE)
SUBROUTINE_RE = re.compile(
    r'^\s*subroutine\s+(\w+)\s*(\(\s*([\w\s,]*)\))?\s*(!.*)?$', re.IGNORECASE)
COMMENT_RE = re.compile(r'^\s*(!.*)?$')


def line_marker(line, path):
    return '#line %d "%s"\n' % (line, path.replace('\\', '\\\\').replace('"', '\\"'))


class PfFile:
    """One translated .pf file: its module name and its tests."""

    def __init__(self, path):
        self.path = os.path.abspath(path)
        self.base = os.path.basename(path)
        self.stem = os.path.splitext(self.base)[0]
        self.module = None
        self.tests = []        # list of (name, disabled)
        self.before = None
        self.after = None
        self.output = []

    def mark(self, line):
        marker = line_marker(line, self.path)
        if not (self.output and self.output[-1] == marker):
            self.output.append(marker)

    def error(self, line, message):
        return PfError(self.path, line, message)

    def translate(self):
        with open(self.path, encoding='utf-8') as f:
            raw = f.read().splitlines()
        out = self.output
        self.mark(1)
        pending = None   # 'test' | 'before' | 'after' waiting for its subroutine
        pending_line = 0
        pending_test = None  # dict for the test being declared
        i = 0
        n = len(raw)
        while i < n:
            lineno = i + 1
            text = raw[i]
            m = DIRECTIVE_RE.match(text)
            if not m:
                if pending and not COMMENT_RE.match(text) and not text.lstrip().startswith('#'):
                    sm = SUBROUTINE_RE.match(text)
                    if not sm:
                        raise self.error(lineno, 'expected "subroutine <name>()" after @%s (line %d)'
                                         % (pending, pending_line))
                    name, argl = sm.group(1), (sm.group(3) or '').strip()
                    if argl:
                        raise self.error(lineno, 'subroutine %s takes arguments (%s): fixtures and '
                                         'test cases are not supported; %s' % (name, argl, EXTEND_HINT))
                    if pending == 'test':
                        pending_test['name'] = name
                        self.tests.append((name, pending_test['disabled']))
                        pending_test = None
                    elif pending == 'before':
                        self.before = name
                    else:
                        self.after = name
                    pending = None
                if self.module is None:
                    mm = MODULE_RE.match(text)
                    if mm and mm.group(1).lower() != 'procedure':
                        self.module = mm.group(1)
                        if self.module.lower() != self.stem.lower():
                            raise self.error(lineno, 'module name "%s" and file name "%s" do not match '
                                             '(pFUnit requires the module in %s to be named %s)'
                                             % (self.module, self.stem, self.base, self.stem))
                out.append(text + '\n')
                i += 1
                continue

            # A directive: join continuation lines (trailing `&`).
            first = lineno
            logical = strip_comment(text).rstrip()
            while logical.endswith('&'):
                i += 1
                if i >= n:
                    raise self.error(first, 'directive continued with "&" past the end of the file')
                nxt = strip_comment(raw[i]).strip()
                if nxt.startswith('&'):
                    logical = logical[:-1] + nxt[1:]
                else:
                    logical = logical[:-1].rstrip() + ' ' + nxt
            last = i + 1
            i += 1
            m = DIRECTIVE_RE.match(logical)
            name, rest = m.group(1), m.group(2).strip()
            key = name.lower()

            if key == 'test':
                if pending:
                    raise self.error(first, '@test while @%s (line %d) still waits for its subroutine'
                                     % (pending, pending_line))
                self.check_test_options(rest, first)
                pending, pending_line = 'test', first
                pending_test = {'disabled': False}
                out.append('!' + logical.lstrip() + '\n')
            elif key == 'disable':
                if rest:
                    raise self.error(first, '@disable takes no arguments')
                if pending != 'test':
                    raise self.error(first, '@disable must come after @test and before the test '
                                     'subroutine (pFUnit ignores it anywhere else)')
                pending_test['disabled'] = True
                out.append('!' + logical.lstrip() + '\n')
            elif key in ('before', 'after'):
                if rest:
                    raise self.error(first, '@%s takes no arguments' % key)
                if pending:
                    raise self.error(first, '@%s while @%s (line %d) still waits for its subroutine'
                                     % (key, pending, pending_line))
                if getattr(self, key) is not None:
                    raise self.error(first, 'second @%s in one file' % key)
                pending, pending_line = key, first
                out.append('!' + logical.lstrip() + '\n')
            elif key in SUPPORTED:
                self.mark(first)
                out.append(self.expand_assert(key, rest, first))
                self.mark(last + 1)
                continue
            elif key in PFUNIT_ONLY:
                raise self.error(first, '@%s is valid pFUnit 4 but not supported by pfunit_lite; %s'
                                 % (name, EXTEND_HINT))
            elif key in PFUNIT_BROKEN:
                raise self.error(first, '@%s is accepted by pFUnit 4\'s parser but its generated code '
                                 'does not compile; do not use it' % name)
            else:
                raise self.error(first, 'unknown directive @%s' % name)
            if last > first:
                self.mark(last + 1)

        if pending:
            raise self.error(pending_line, '@%s is not followed by a subroutine' % pending)
        if self.module is None:
            raise self.error(1, 'no "module %s" found: pFUnit 4 test files hold one module named '
                             'after the file' % self.stem)
        if not self.tests:
            sys.stderr.write('%s: warning: no @test found\n' % self.path)

    def check_test_options(self, rest, line):
        if not rest:
            return
        if not (rest.startswith('(') and matching_paren(rest, 0) == len(rest) - 1):
            raise self.error(line, 'malformed @test options "%s"' % rest)
        for opt in split_top_level(rest[1:-1], self.path, line) if rest[1:-1].strip() else []:
            km = KEYWORD_RE.match(opt)
            if not km:
                raise self.error(line, '@test option "%s" is not of the form key=value' % opt)
            k = km.group(1).lower()
            if k in TEST_OPTIONS_REFUSED:
                raise self.error(line, '@test(%s=...): %s; %s' % (km.group(1), TEST_OPTIONS_REFUSED[k],
                                                                   EXTEND_HINT))
            # Other options (e.g. timeout=) are accepted and ignored.

    def expand_assert(self, key, rest, line):
        fname, min_pos, max_pos, keywords = SUPPORTED[key]
        if not (rest.startswith('(') and matching_paren(rest, 0) == len(rest) - 1):
            raise self.error(line, '@%s needs its arguments in parentheses: @%s(...)' % (fname, fname))
        inner = rest[1:-1].strip()
        args = split_top_level(inner, self.path, line) if inner else []
        n_pos, seen_kw = 0, set()
        for a in args:
            km = KEYWORD_RE.match(a)
            if km:
                k = km.group(1).lower()
                if k not in keywords:
                    raise self.error(line, '@%s: keyword argument "%s=" is not supported (allowed: %s)'
                                     % (fname, km.group(1), ', '.join(sorted(keywords))))
                if k in seen_kw:
                    raise self.error(line, '@%s: keyword "%s=" given twice' % (fname, km.group(1)))
                seen_kw.add(k)
            else:
                if seen_kw:
                    raise self.error(line, '@%s: positional argument "%s" after a keyword argument'
                                     % (fname, a))
                n_pos += 1
        positional = [a for a in args if not KEYWORD_RE.match(a)]
        if n_pos > max_pos or (n_pos == 3 and positional[2][:1] in ('"', "'")):
            raise self.error(line, '@%s: too many positional arguments; give the message as '
                             'message=... (pFUnit 4 requires the keyword)' % fname)
        if n_pos + len(seen_kw & {'tolerance'}) < min_pos:
            raise self.error(line, '@%s needs at least %d operands, got %d' % (fname, min_pos, n_pos))
        pieces = ['call %s(' % fname] + [a + ', ' for a in args]
        pieces.append("location=SourceLocation('%s', %d))" % (self.base.replace("'", "''"), line))
        return wrap_statement(pieces, '  ') + '  if (anyExceptions()) return\n'

    def write(self, outdir):
        path = os.path.join(outdir, self.module + '.F90')
        write_file(path, ''.join(self.output))
        return path


def write_file(path, text):
    with open(path, 'w', encoding='utf-8') as f:
        f.write(text)


def driver_source(files):
    lines = [
        '! Generated by pf2f90.py (pfunit_lite): runs every @test of',
        '! ' + ', '.join(f.base for f in files) + '. Do not edit.',
        'program funit_lite_driver',
        '  use funit, only: funit_begin_test, funit_end_test, funit_skip_test, funit_summary, &',
        '    anyExceptions',
    ]
    calls = []
    k = 0
    for f in files:
        local = {}

        def alias(proc):
            nonlocal k
            if proc not in local:
                k += 1
                local[proc] = 'funit_proc_%04d' % k
                lines.append('  use %s, only: %s => %s' % (f.module, local[proc], proc))
            return local[proc]

        calls.append("  write (*, '(a)') '%s: %d test(s)'" % (f.base, len(f.tests)))
        for name, disabled in f.tests:
            label = '%s::%s' % (f.module, name)
            if disabled:
                calls.append("  call funit_skip_test('%s')" % label)
                continue
            calls.append("  call funit_begin_test('%s')" % label)
            if f.before:
                calls.append('  call %s()' % alias(f.before))
                calls.append('  if (.not. anyExceptions()) then')
                calls.append('    call %s()' % alias(name))
                if f.after:
                    calls.append('    call %s()' % alias(f.after))
                calls.append('  end if')
            else:
                calls.append('  call %s()' % alias(name))
                if f.after:
                    calls.append('  call %s()' % alias(f.after))
            calls.append('  call funit_end_test()')
    lines += ['  implicit none', '  integer :: n_failed', '']
    lines += calls
    lines += ['', '  call funit_summary(n_failed)', '  if (n_failed > 0) error stop 1',
              'end program funit_lite_driver', '']
    return '\n'.join(lines)


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--outdir', required=True, help='directory for the generated modules')
    ap.add_argument('--driver', required=True, help='path of the generated driver program')
    ap.add_argument('sources', nargs='+', help='.pf files')
    opts = ap.parse_args(argv)
    try:
        files = []
        for src in opts.sources:
            pf = PfFile(src)
            pf.translate()
            files.append(pf)
        names = {}
        for pf in files:
            if pf.module.lower() in names:
                raise PfError(pf.path, 1, 'module %s also defined in %s'
                              % (pf.module, names[pf.module.lower()]))
            names[pf.module.lower()] = pf.path
        os.makedirs(opts.outdir, exist_ok=True)
        for pf in files:
            pf.write(opts.outdir)
        write_file(opts.driver, driver_source(files))
    except PfError as e:
        sys.stderr.write('pf2f90: %s\n' % e)
        return 1
    except OSError as e:
        sys.stderr.write('pf2f90: %s\n' % e)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
