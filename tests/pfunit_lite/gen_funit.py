#!/usr/bin/env python3
"""gen_funit: write pfunit_lite's `funit` module from funit.f90.in.

    gen_funit.py funit.f90.in funit.f90

Adds one specific procedure per row of the table below (directive, types,
ranks) and the generic interfaces over them. The rows are what the suite
uses, each a subset of what pFUnit 4.14 overloads (so a .pf that compiles
here compiles there); selftest/pflite_selftest_pass.pf calls every row.
"""

import sys

R, S, I, L = 'real(real64)', 'real(sp)', 'integer', 'logical'
DIMS = ('', '(:)', '(:,:)')
MSG = ('character(len=*), intent(in), optional :: message',
       'type(SourceLocation), intent(in), optional :: location')


def rows():
    """Yield (generic, [(dummy, type, rank)], Fortran statement)."""
    for er, ar in ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2)):
        for tol in (None, R, S):
            dummies = [('expected', R, er), ('actual', R, ar)] + ([('tolerance', tol, 0)] if tol else [])
            t = 'real(tolerance, real64)' if tol else '0.0_real64'
            yield 'assertEqual', dummies, ('call cmp_real(\'assertEqual\', [expected], [actual], shape(expected), '
                                           'shape(actual), %s, .false., message, location)' % t)
    for rank in (0, 1, 2):
        for tol in (R, S):
            yield 'assertRelativelyEqual', [('expected', R, rank), ('actual', R, rank), ('tolerance', tol, 0)], (
                'call cmp_real(\'assertRelativelyEqual\', [expected], [actual], shape(expected), '
                'shape(actual), real(tolerance, real64), .true., message, location)')
    for er, ar in ((0, 0), (1, 1), (0, 1)):
        yield 'assertEqual', [('expected', I, er), ('actual', I, ar)], (
            'call cmp_int(\'assertEqual\', [expected], [actual], shape(expected), shape(actual), message, location)')
    yield 'assertEqual', [('expected', L, 0), ('actual', L, 0)], (
        'call cmp_text(\'assertEqual\', expected .eqv. actual, lstr(expected), lstr(actual), message, location)')
    for name, op in (('LessThan', '<'), ('LessThanOrEqual', '<='), ('GreaterThan', '>'),
                     ('GreaterThanOrEqual', '>=')):
        for typ, show in ((I, 'istr'), (R, 'rstr')):
            yield 'assert' + name, [('lhs', typ, 0), ('rhs', typ, 0)], (
                'call cmp_text(\'assert%s\', lhs %s rhs, \'lhs %s rhs\', \'lhs = \'//%s(lhs)//\', rhs = \'//%s(rhs), '
                'message, location)' % (name, op, op, show, show))
    none = '[real(real64) ::]'
    yield 'assertIsFinite', [('x', R, 0)], (
        'call cmp_flags(\'assertIsFinite\', [ieee_is_finite(x)], shape(x), [x], message, location)')
    yield 'assertIsNaN', [('x', R, 0)], (
        'call cmp_flags(\'assertIsNaN\', [ieee_is_nan(x)], shape(x), [x], message, location)')
    yield 'assertTrue', [('condition', L, 0)], (
        'call cmp_flags(\'assertTrue\', [condition], shape(condition), %s, message, location)' % none)
    yield 'assertFalse', [('condition', L, 0)], (
        'call cmp_flags(\'assertFalse\', [.not. condition], shape(condition), %s, message, location)' % none)
    yield 'assertAll', [('conditions', L, 1)], (
        'call cmp_flags(\'assertAll\', conditions, shape(conditions), %s, message, location)' % none)
    yield 'assertAny', [('conditions', L, 1)], (
        'call cmp_flags(\'assertAny\', [any(conditions)], [integer ::], %s, message, location)' % none)


def wrap(text, indent):
    """Break a statement after ', ' outside strings: no line past 100 columns."""
    pieces, quote, start = [], None, 0
    for i, c in enumerate(text):
        if c in '\'"' and quote in (None, c):
            quote = None if quote else c
        elif c == ',' and not quote and text[i + 1:i + 2] == ' ':
            pieces.append(text[start:i + 2])
            start = i + 2
    lines, cur = [], indent
    for piece in pieces + [text[start:]]:
        if len(cur) + len(piece) > 98 and cur.strip():
            lines.append(cur.rstrip() + ' &')
            cur = indent + '    '
        cur += piece
    return '\n'.join(lines + [cur])


def generate(template):
    generics, specifics = {}, []
    for k, (generic, dummies, statement) in enumerate(rows(), 1):
        name = '%s_%d' % (generic, k)
        generics.setdefault(generic, []).append(name)
        names = ', '.join(d[0] for d in dummies)
        body = ['subroutine %s(%s, message, location)' % (name, names)]
        body += ['  %s, intent(in) :: %s%s' % (typ, d, DIMS[rank]) for d, typ, rank in dummies]
        body += ['  ' + m for m in MSG] + [wrap(statement, '  '), 'end subroutine ' + name, '']
        specifics += ['  ' + line if line else '' for line in '\n'.join(body).split('\n')]
    generics['assertEqual'].append('assertEqual_char')
    interfaces = []
    for generic, names in generics.items():
        interfaces.append('  interface %s' % generic)
        interfaces += ['    module procedure %s' % n for n in names]
        interfaces.append('  end interface %s' % generic)
    public = ['  public :: ' + g for g in generics]
    out = template.replace('  !@public\n', '\n'.join(public) + '\n')
    out = out.replace('  !@interfaces\n', '\n'.join(interfaces) + '\n')
    return out.replace('  !@specifics\n', '\n'.join(specifics) + '\n')


def main(argv):
    if len(argv) != 2:
        sys.stderr.write('usage: gen_funit.py funit.f90.in funit.f90\n')
        return 2
    with open(argv[0], encoding='utf-8') as f:
        text = generate(f.read())
    with open(argv[1], 'w', encoding='utf-8') as f:
        f.write(text)
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
