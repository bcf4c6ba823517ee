#!/usr/bin/env python3
"""pf2f90: pFUnit 4 .pf test files to plain Fortran, for pfunit_lite.

    pf2f90.py --outdir DIR --driver DRIVER.F90 TEST.pf [TEST2.pf ...]

Writes DIR/<module>.F90 for each TEST.pf with every directive replaced as
pFUnit 4 replaces it,

    call assertEqual(<arguments as written>, location=SourceLocation('TEST.pf', N))
    if (anyExceptions()) return

(#line markers keep compiler messages on the .pf), and DRIVER.F90, a program
that runs each @test between its @before and @after and ends with
`error stop 1` when one failed. With --max-pes N (CMake's MAX_PES) the
files hold MPI tests, `@test(npes=[...])`, which the driver runs once per
npes value on that many ranks of an mpirun of N (module `pfunit`).

Strict on purpose: what real pFUnit 4.14 refuses and a test could slip into
(README.md, "What is refused") stops here too, as `file:line: error: ...`.
Standard library only.
"""

import argparse
import os
import re
import sys

# Directive (lower case) -> (spelling, fewest operands counting tolerance=,
# most positional). The suite gives the message by keyword, message=, and
# tolerance= only where a tolerance can be.
ASSERTS = {spelling.lower(): (spelling, fewest, most) for spelling, fewest, most in (
    ('assertEqual', 2, 3), ('assertRelativelyEqual', 3, 3), ('assertTrue', 1, 1),
    ('assertFalse', 1, 1), ('assertLessThan', 2, 2), ('assertLessThanOrEqual', 2, 2),
    ('assertGreaterThan', 2, 2), ('assertGreaterThanOrEqual', 2, 2), ('assertIsFinite', 1, 1),
    ('assertIsNaN', 1, 1), ('assertAll', 1, 1), ('assertAny', 1, 1))}
TOLERANT = {'assertequal', 'assertrelativelyequal'}
# pFUnit 4 directives the suite does not use, so pfunit_lite lacks them.
PFUNIT_ONLY = {'assertnotequal', 'assertnotall', 'assertnone', 'assertsameshape', 'assertfail',
               'assertexceptionraised', 'assertassociated', 'assertnotassociated',
               'assertequivalent', 'assertequaluserdefined', 'testcase', 'testparameter',
               'suite', 'mpiassertequal', 'mpiasserttrue', 'mpiassertfalse'}
# Accepted by pFUnit 4.14's parser, but the code it writes does not compile.
PFUNIT_BROKEN = {'assertisinfinite', 'assertthat', 'assertismemberof', 'assertcontains',
                 'assertispermutationof'}
# Names a test module must not define: `use funit` brings them in under
# pFUnit 4.14 (each tried there), and its generated suite declares t, suite.
RESERVED = set('''t suite abstractmatcher abstracttestparameter all_of allof any_of anyexceptions
    anyof array_with_size assert_that assertall assertany assertequal assertexceptionraised
    assertfail assertfalse assertgreaterthan assertgreaterthanorequal assertisfinite assertisnan
    assertlessthan assertlessthanorequal assertnone assertnotall assertnotequal
    assertrelativelyequal assertsameshape asserttrue basetestrunner catch catchnext
    contains_string debuglistener disable empty_array ends_with equal_to every every_item
    expectation false fhamcrest finalize funit generic_run get_context ignore_all
    ignore_differences initialize is isarraywithsize isequal isnear isnot iso_fortran_env
    isrelativelynear istrueorfalse keep_all listenerpointer loadtests_interface matchable
    matcherdescription namefilter near not output_unit parallelcontext parameterizedtestcase
    predicate relatively_near remoterunner resultprinter robustrunner run serialcontext
    sourcelocation starts_with stringcontains stringdescription stringendswith stringstartswith
    stub subject taplistener test testannotation testcase testlistener testlistenervector
    testmethod testresult testrunner testsuite throw timeoutannotation trim_all true wascalled
    wascalledonce wasnotcalled whitespaceoptions xmlprinter'''.split())
# What `use pfunit` adds in an MPI test module (besides every name of `use mpi`).
RESERVED_MPI = {'mpitestmethod', 'mpitestcase', 'mpicontext', 'mpitestparameter', 'mpi'}
NPES = re.compile(r'^\(\s*npes\s*=\s*\[\s*(\d+(?:\s*,\s*\d+)*)\s*\]\s*\)$', re.I)
COLUMNS = 132  # gfortran's free-form line limit, which pFUnit's output must keep

DIRECTIVE = re.compile(r'^\s*@(\w+)\s*(.*?)\s*$')
MODULE = re.compile(r'^\s*module\s+(?!procedure\b|subroutine\b|function\b)(\w+)', re.I)
SUBROUTINE = re.compile(r'^\s*subroutine\s+(\w+)\s*(?:\((.*)\))?\s*$', re.I)
PROCEDURE = re.compile(r'^(?!\s*end\b)\s*(?:[\w(),=*:\s]*\s)?(?:subroutine|function)\s+(\w+)', re.I)
END_PROCEDURE = re.compile(r'^\s*end\s*(?:(?:subroutine|function)\b.*)?$', re.I)
# Module-level names: an interface, a type, the entities of a declaration.
INTERFACE = re.compile(r'^\s*(?:abstract\s+)?interface\s+(\w+)|^\s*type\s+(\w+)\s*$', re.I)
DECLARATION = re.compile(r'^(?!\s*(?:use|public|private)\b)[^!]*?::(.*)$', re.I)
KEYWORD = re.compile(r'^(\w+)\s*=(?!=)')


class PfError(Exception):
    def __init__(self, path, line, message):
        super().__init__('%s:%d: error: %s' % (path, line, message))


def split_code(text):
    """(code, comment) of a line: the comment starts at a `!` outside strings."""
    quote = None
    for i, c in enumerate(text):
        if c in '\'"' and quote in (None, c):
            quote = None if quote else c
        elif c == '!' and not quote:
            return text[:i], text[i:]
    return text, ''


def split_args(text):
    """Arguments split at commas outside brackets and strings (None if unbalanced)."""
    args, depth, quote, start = [], 0, None, 0
    for i, c in enumerate(text):
        if c in '\'"' and quote in (None, c):
            quote = None if quote else c
        elif quote:
            continue
        elif c in '([':
            depth += 1
        elif c in ')]':
            depth -= 1
        elif c == ',' and depth == 0:
            args.append(text[start:i].strip())
            start = i + 1
        if depth < 0:
            return None
    args.append(text[start:].strip())
    return None if depth or quote or '' in args else args


class PfFile:
    def __init__(self, path, max_pes=None):
        self.max_pes = max_pes     # MAX_PES of the test: MPI tests allowed
        self.path = os.path.abspath(path)
        self.base = os.path.basename(path)
        self.stem = os.path.splitext(self.base)[0]
        self.module = None
        self.tests = []            # (name, disabled, npes list or None), in file order
        self.self_arg = None       # (dummy, line) of an MPI test awaiting its declaration
        self.fixture = {}          # 'before'/'after' -> name
        self.out = ['#line 1 "%s"\n' % self.path]
        self.depth = 0             # nesting of subroutines and functions
        self.in_contains = False   # past the module's own `contains`

    def error(self, line, message):
        return PfError(self.path, line, message)

    def translate(self):
        with open(self.path, encoding='utf-8') as f:
            lines = f.read().splitlines()
        waiting = None    # [directive, its line, disabled, npes] until its subroutine
        uses = None       # 'funit' or 'pfunit', from the module's use line
        for n, text in enumerate(lines, 1):
            code, comment = split_code(text)
            m = DIRECTIVE.match(code)
            if not m:
                if self.self_arg and code.strip():
                    self.check_self(code, n)
                if waiting and code.strip():
                    self.take_subroutine(waiting, code, n)
                    waiting = None
                uses = self.check_statement(code, comment, n) or uses
                self.out.append(text + '\n')
                continue
            name, rest = m.group(1), m.group(2)
            key = name.lower()
            if waiting and key != 'disable':
                raise self.error(n, '@%s while @%s (line %d) still waits for its subroutine'
                                 % (name, waiting[0], waiting[1]))
            if code.rstrip().endswith('&'):
                raise self.error(n, '@%s is continued with "&": pFUnit reads a directive from one line '
                                    'only; put it on one line (compute a long expression into a '
                                    'variable first)' % name)
            if comment:
                raise self.error(n, 'comment after @%s: pFUnit then leaves the line untranslated; put '
                                    'the comment on the line above' % name)
            if key in ('test', 'before', 'after'):
                npes = self.npes(key, name, rest, n)
                if key in self.fixture:
                    raise self.error(n, 'second @%s in one file' % key)
                waiting = [key, n, False, npes]
            elif key == 'disable':
                if rest or not waiting or waiting[0] != 'test':
                    raise self.error(n, '@disable goes alone on the line between @test and its '
                                        'subroutine (elsewhere pFUnit loses it or fails)')
                waiting[2] = True
            elif key in ASSERTS:
                self.out.append('#line %d\n' % n)
                self.out.append(self.expand(key, name, rest, n))
                self.out.append('#line %d\n' % (n + 1))
                continue
            elif key == 'mpitest':
                raise self.error(n, '@mpitest is deprecated in pFUnit 4 (its parser: "should now just '
                                    'use @test"): write @test(npes=[...])')
            elif key in PFUNIT_ONLY:
                raise self.error(n, '@%s is pFUnit 4 but pfunit_lite does not support it (no test used '
                                    'it yet): add it to gen_funit.py and pf2f90.py with a self-test'
                                 % name)
            elif key in PFUNIT_BROKEN:
                raise self.error(n, '@%s is accepted by pFUnit 4.14\'s parser but what it generates '
                                    'does not compile; do not use it' % name)
            else:
                raise self.error(n, 'unknown directive @%s (pFUnit 4 has none of that name)' % name)
            self.out.append('!' + text.lstrip() + '\n')
        if waiting:
            raise self.error(waiting[1], '@%s is not followed by a subroutine' % waiting[0])
        if self.module is None:
            raise self.error(1, 'no "module %s": pFUnit 4 wants one module named after the file'
                             % self.stem)
        if not self.tests:
            raise self.error(1, 'no @test in %s' % self.base)
        self.check_kind(uses)

    def npes(self, key, name, rest, n):
        """The npes list of `@test(npes=[...])` (None for a plain @test)."""
        if not rest:
            return None
        m = NPES.match(rest)
        if key != 'test' or not m:
            raise self.error(n, '@%s%s: pfunit_lite supports @%s without options%s (cases=, ifdef=, '
                                '... need real pFUnit)' % (name, rest, key,
                                                        ' or with npes=[...] alone' * (key == 'test')))
        npes = [int(v) for v in m.group(1).split(',')]
        if self.max_pes is None:
            raise self.error(n, '@%s%s is an MPI test: register it with wellposed_add_pf_test(... '
                                'MAX_PES <n>)' % (name, rest))
        if min(npes) < 1 or max(npes) > self.max_pes:
            raise self.error(n, '@%s%s: every npes must be 1 to MAX_PES = %d (pFUnit fails a test '
                                'with more: "Insufficient processes")' % (name, rest, self.max_pes))
        return npes

    def check_kind(self, uses):
        """Serial files use funit; MPI files use pfunit, hold MPI tests only, no fixtures."""
        mpi = [t for t in self.tests if t[2]]
        want = 'pfunit' if mpi else 'funit'
        if uses != want:
            raise self.error(self.module_line, 'module %s does not "use %s" on a line of its own '
                             '(pFUnit 4 test modules use funit, MPI ones (@test(npes=...)) pfunit; '
                             'pfunit_mod is gone)' % (self.module, want))
        if mpi and len(mpi) < len(self.tests):
            raise self.error(self.module_line, 'module %s mixes serial @test and MPI '
                             '@test(npes=...): pfunit_lite runs a file of either kind' % self.module)
        if mpi and self.fixture:
            raise self.error(self.module_line, '@%s in a file of MPI tests: pfunit_lite lacks MPI '
                             'fixtures (class(MpiTestMethod) arguments)' % sorted(self.fixture)[0])
        if self.max_pes is not None and not mpi:
            raise self.error(self.module_line, 'MAX_PES given for %s, which holds no MPI test '
                             '(@test(npes=[...]))' % self.base)

    def check_self(self, code, n):
        """An MPI test's first statement declares its dummy as pFUnit's interface wants."""
        arg, line = self.self_arg
        self.self_arg = None
        if not re.match(r'^\s*class\s*\(\s*MpiTestMethod\s*\)\s*,\s*intent\s*\(\s*inout\s*\)'
                        r'\s*::\s*%s\s*$' % re.escape(arg), code, re.I):
            raise self.error(n, 'the first statement of an MPI test (line %d) must be '
                                '"class(MpiTestMethod), intent(inout) :: %s"' % (line, arg))

    def check_statement(self, code, comment, n):
        """File-shape rules of a plain line; True when it is `use funit`."""
        m = MODULE.match(code)
        if m and self.module is not None:
            raise self.error(n, 'a second module in one file: pFUnit wants one, named after the file')
        if m:
            if m.group(1).lower() != self.stem.lower():
                raise self.error(n, 'module name "%s" and file name "%s" do not match (pFUnit '
                                    'requires module %s in %s)' % (m.group(1), self.stem, self.stem,
                                                                   self.base))
            if not re.match(r'^\s*module\s+\w+\s*$', code) or comment:
                raise self.error(n, 'write "module %s" alone on its line: pFUnit finds the module '
                                    'name only there' % m.group(1))
            self.module, self.module_line = m.group(1), n
        names = []
        m = PROCEDURE.match(code)
        if m:
            names = [m.group(1)] if self.depth == 0 else []
            self.depth += 1
        elif END_PROCEDURE.match(code):
            self.depth = max(self.depth - 1, 0)
        elif self.depth == 0 and re.match(r'^\s*contains\s*$', code, re.I):
            self.in_contains = True
        elif self.depth == 0:
            m = INTERFACE.match(code)
            names = [g for g in m.groups() if g] if m else []
            m = DECLARATION.match(code)
            if m and not self.in_contains:
                names += [re.match(r'\s*(\w*)', e).group(1) for e in split_args(m.group(1)) or []]
        for name in names:
            if name.lower() in RESERVED | {self.stem.lower() + '_suite', 'wrap' + self.stem.lower()}:
                raise self.error(n, '"%s" is a name pFUnit defines in a test module (through use '
                                    'funit) or in the suite it generates; rename it' % name)
        for name in names if self.max_pes is not None else []:
            if name.lower() in RESERVED_MPI or name.lower().startswith('mpi_'):
                raise self.error(n, '"%s" is a name "use pfunit" brings into an MPI test module '
                                    '(with all of "use mpi", whose names begin mpi_); rename it'
                                 % name)
        m = re.match(r'^\s*use\s+(p?funit)\s*$', code, re.I)
        return m.group(1).lower() if m else None

    def take_subroutine(self, waiting, code, n):
        key, line, disabled, npes = waiting
        m = SUBROUTINE.match(code)
        if not m:
            raise self.error(n, 'expected "subroutine <name>()" after @%s (line %d)' % (key, line))
        if npes:
            if not re.match(r'^\s*\w+\s*$', m.group(2) or ''):
                raise self.error(n, 'an MPI test takes one argument: subroutine %s(this)' % m.group(1))
            self.tests.append((m.group(1), disabled, npes))
            self.self_arg = (m.group(2).strip(), n)
            return
        if (m.group(2) or '').strip():
            raise self.error(n, 'subroutine %s(%s): pfunit_lite runs tests without arguments '
                                '(fixtures and test cases need real pFUnit)' % (m.group(1), m.group(2)))
        if key == 'test':
            self.tests.append((m.group(1), disabled, None))
        else:
            self.fixture[key] = m.group(1)

    def expand(self, key, name, rest, n):
        spelling, fewest, most = ASSERTS[key]
        args = split_args(rest[1:-1]) if rest.startswith('(') and rest.endswith(')') else None
        if args is None:
            raise self.error(n, '@%s needs its arguments in balanced parentheses: @%s(...)'
                             % (name, spelling))
        keywords = [KEYWORD.match(a).group(1).lower() for a in args if KEYWORD.match(a)]
        positional = [a for a in args if not KEYWORD.match(a)]
        if args[:len(positional)] != positional:
            raise self.error(n, '@%s: a positional argument after a keyword argument' % name)
        allowed = {'message', 'tolerance'} if key in TOLERANT else {'message'}
        for k in keywords:
            if k not in allowed or keywords.count(k) > 1:
                raise self.error(n, '@%s: keyword "%s=" is not one of %s, once each'
                                 % (name, k, ', '.join(sorted(allowed))))
        if len(positional) > most or (most == 3 and len(positional) == 3
                                      and positional[2][:1] in '\'"'):
            raise self.error(n, '@%s: too many positional arguments; the suite gives the message as '
                                'message=...' % name)
        if len(positional) + ('tolerance' in keywords) < fewest:
            raise self.error(n, '@%s needs %d operands' % (name, fewest))
        wide = '  call %s(%s, &' % (name, rest[1:-1])
        if len(wide) > COLUMNS:
            raise self.error(n, '@%s: pFUnit writes this as a line of %d columns, over the %d that '
                                'gfortran reads; shorten it' % (name, len(wide), COLUMNS))
        call = '  call %s(%s, &\n#line %d\n    & location=SourceLocation(\'%s\', %d))\n' % (
            spelling, rest[1:-1], n, self.base, n)
        return call + '  if (anyExceptions()) return\n'


def driver_source(files, mpi):
    """The program: serial tests in order; MPI ones once per npes (pfunit_run_test)."""
    uses, calls, k = [], [], 0
    for f in files:
        alias = {}
        for proc in [t[0] for t in f.tests] + list(f.fixture.values()):
            k += 1
            alias[proc] = 'p%d' % k
            uses.append('  use %s, only: p%d => %s' % (f.module, k, proc))
        for name, disabled, npes in f.tests:
            label = "'%s::%s'" % (f.module, name)
            for n in npes or []:
                mpi_label = "'%s::%s[npes=%d]'" % (f.module, name, n)
                calls.append('  call funit_skip_test(%s)' % mpi_label if disabled else
                             '  call pfunit_run_test(%s, %s, %d)' % (mpi_label, alias[name], n))
            if npes:
                continue
            if disabled:
                calls.append('  call funit_skip_test(%s)' % label)
                continue
            calls.append('  call funit_begin_test(%s)' % label)
            body = ['call %s()' % alias[name]] + (['call %s()' % alias[f.fixture['after']]]
                                                   if 'after' in f.fixture else [])
            if 'before' in f.fixture:
                calls.append('  call %s()' % alias[f.fixture['before']])
                calls += ['  if (.not. anyExceptions()) then'] + ['    ' + b for b in body] + ['  end if']
            else:
                calls += ['  ' + b for b in body]
            calls.append('  call funit_end_test()')
    start, stop = [], []
    if mpi:
        uses.insert(0, '  use pfunit, only: pfunit_start, pfunit_run_test, pfunit_stop')
        start, stop = ['  call pfunit_start()'], ['  call pfunit_stop()']
    return '\n'.join(['! Written by pf2f90.py (pfunit_lite).', 'program funit_lite_driver',
                      '  use funit, only: funit_begin_test, funit_end_test, funit_skip_test, &',
                      '    funit_summary, anyExceptions'] + uses +
                     ['  implicit none', '  integer :: n_failed'] + start + calls +
                     ['  call funit_summary(n_failed)'] + stop + ['  if (n_failed > 0) error stop 1',
                      'end program funit_lite_driver', ''])


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--outdir', required=True)
    ap.add_argument('--driver', required=True)
    ap.add_argument('--max-pes', type=int, help='MAX_PES: the files hold MPI tests')
    ap.add_argument('sources', nargs='+')
    opts = ap.parse_args(argv)
    try:
        files = [PfFile(src, opts.max_pes) for src in opts.sources]
        for f in files:
            f.translate()
        os.makedirs(opts.outdir, exist_ok=True)
        for f in files:
            with open(os.path.join(opts.outdir, f.stem + '.F90'), 'w', encoding='utf-8') as out:
                out.write(''.join(f.out))
        with open(opts.driver, 'w', encoding='utf-8') as out:
            out.write(driver_source(files, opts.max_pes is not None))
    except (PfError, OSError) as e:
        sys.stderr.write('pf2f90: %s\n' % e)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
