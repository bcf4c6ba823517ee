"""No program or library of the build asks for an executable stack.

GCC gives a program an executable stack (ELF PT_GNU_STACK with PF_X) when
an internal procedure that uses its host's variables is passed as an
argument (a trampoline on the stack); hardened systems refuse such
programs, and a library that needs it makes its host's stack executable.
Reads the ELF program headers of each file given (64-bit little-endian).

Usage: no_exec_stack.py FILE [FILE ...]
       no_exec_stack.py --self-test   (two made-up ELF headers: caught, passed)
"""
import os
import struct
import sys
import tempfile

PT_GNU_STACK = 0x6474E551
PF_X = 0x1


def stack_flags(path):
    """The PT_GNU_STACK flags of ELF file `path`, or None without one."""
    with open(path, 'rb') as f:
        data = f.read()
    if data[:4] != b'\x7fELF' or data[4] != 2 or data[5] != 1:
        raise ValueError(f'{path}: not a 64-bit little-endian ELF file')
    phoff, = struct.unpack_from('<Q', data, 0x20)
    phentsize, phnum = struct.unpack_from('<HH', data, 0x36)
    for i in range(phnum):
        p_type, p_flags = struct.unpack_from('<II', data, phoff + i * phentsize)
        if p_type == PT_GNU_STACK:
            return p_flags
    return None


def fake_elf(flags):
    """A minimal 64-bit ELF header with one PT_GNU_STACK program header."""
    head = bytearray(64)
    head[:6] = b'\x7fELF\x02\x01'
    struct.pack_into('<Q', head, 0x20, 64)        # e_phoff
    struct.pack_into('<HH', head, 0x36, 56, 1)    # e_phentsize, e_phnum
    ph = bytearray(56)
    struct.pack_into('<II', ph, 0, PT_GNU_STACK, flags)
    return bytes(head + ph)


def self_test():
    with tempfile.TemporaryDirectory() as tmp:
        rw, rwe = os.path.join(tmp, 'rw'), os.path.join(tmp, 'rwe')
        with open(rw, 'wb') as f:
            f.write(fake_elf(0x6))
        with open(rwe, 'wb') as f:
            f.write(fake_elf(0x7))
        ok = main([rw]) == 0 and main([rwe]) == 1
    print('self-test', 'passed' if ok else 'FAILED')
    return 0 if ok else 1


def main(paths):
    if paths == ['--self-test']:
        return self_test()
    if not paths:
        print(__doc__, file=sys.stderr)
        return 2
    bad = 0
    for path in paths:
        flags = stack_flags(path)
        if flags is None:
            print(f'{path}: no PT_GNU_STACK header (the loader assumes an executable stack)')
            bad += 1
        elif flags & PF_X:
            print(f'{path}: executable stack (PT_GNU_STACK flags {flags:#x})')
            bad += 1
        else:
            print(f'{path}: stack not executable')
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
