"""No UMAT or VUMAT call saves and restores the floating-point environment.

gfortran saves the floating-point environment on entry to every procedure
in whose scope an IEEE intrinsic module is visible, even through another
module (a call of _gfortran_ieee_procedure_entry, then ..._exit), and
restores it on return: on some CPUs that costs several UMAT calls' worth of
time. This walks the direct calls of the disassembled library from umat_
and vumat_ (objdump -dr, so the relocations of an archive's members count)
and fails if any procedure they reach calls the save.

Usage: umat_no_fp_env.py OBJDUMP LIBRARY [LIBRARY ...]
       umat_no_fp_env.py --self-test   (made-up disassemblies: caught, passed)
"""
import re
import subprocess
import sys

ENTRIES = ('umat_', 'vumat_')
SAVE = '_gfortran_ieee_procedure_entry'
FUNCTION = re.compile(r'^[0-9a-f]+ <([^>]+)>:$')
# A direct call or jump to a symbol, or a relocation that names one (an
# archive member's call of a procedure in another member).
TARGET = re.compile(r'\b(?:call|jmp)\s+[0-9a-f]+ <([^>+]+)(?:\+0x[0-9a-f]+)?>'
                    r'|R_X86_64_(?:PLT32|PC32|GOTPCRELX|REX_GOTPCRELX)\s+([^\s+-]+)')


def call_graph(text):
    """{procedure: set of symbols it calls or jumps to} from objdump -dr."""
    graph, current = {}, None
    for line in text.splitlines():
        m = FUNCTION.match(line)
        if m:
            current = m.group(1)
            graph.setdefault(current, set())
            continue
        m = TARGET.search(line)
        if m and current is not None:
            name = (m.group(1) or m.group(2)).split('@')[0]
            if name != current:
                graph[current].add(name)
    return graph


def offenders(graph):
    """(entry, path) for every entry that reaches SAVE, the path as names,
    and how many procedures the entries reach."""
    found, reached = [], set()
    for entry in ENTRIES:
        if entry not in graph:
            raise ValueError(f'{entry} is not in the disassembly')
        parent, todo = {entry: None}, [entry]
        while todo:
            name = todo.pop()
            for callee in sorted(graph.get(name, ())):
                if callee == SAVE:
                    path = [name]
                    while parent[path[-1]] is not None:
                        path.append(parent[path[-1]])
                    found.append((entry, list(reversed(path))))
                elif callee not in parent and callee in graph:
                    parent[callee] = name
                    todo.append(callee)
        reached.update(parent)
    return found, len(reached)


def check(text, label):
    graph = call_graph(text)
    bad, reached = offenders(graph)
    for entry, path in bad:
        print(f'{label}: {entry} saves the floating-point environment: '
              + ' -> '.join(path) + f' calls {SAVE}')
    if not bad:
        print(f'{label}: the {reached} procedures umat_ and vumat_ reach '
              f'never call {SAVE}')
    return 1 if bad else 0


def self_test():
    clean = ('0000 <umat_>:\n  10:\tcall   20 <helper>\n'
             '0020 <helper>:\n  30:\tret\n'
             '0040 <vumat_>:\n  50:\tjmp    20 <helper>\n'
             '0060 <other_>:\n  70:\tcall   0 <_gfortran_ieee_procedure_entry@plt>\n')
    # vumat_ reaches the save through a member's relocation, two calls deep
    dirty = clean + ('0080 <deep>:\n  90:\tcall   95 <deep+0x5>\n'
                     '\t\t\t91: R_X86_64_PLT32\t_gfortran_ieee_procedure_entry-0x4\n')
    dirty = dirty.replace('0020 <helper>:\n  30:\tret\n',
                          '0020 <helper>:\n  30:\tcall   0 <other>\n'
                          '\t\t\t31: R_X86_64_PLT32\tdeep-0x4\n')
    ok = check(clean, 'clean') == 0 and check(dirty, 'dirty') == 1
    print('self-test', 'passed' if ok else 'FAILED')
    return 0 if ok else 1


def main(args):
    if args == ['--self-test']:
        return self_test()
    if len(args) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    objdump, bad = args[0], 0
    for path in args[1:]:
        text = subprocess.run([objdump, '-dr', '--no-show-raw-insn', path], check=True,
                              capture_output=True, text=True).stdout
        bad += check(text, path)
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
