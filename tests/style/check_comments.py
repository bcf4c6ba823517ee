#!/usr/bin/env python3
"""The comment rules of the sources (docs/STYLE rules of the project):

  header   the comment block that opens a file, or that stands just before a
           module, submodule or program statement, has at most 8 lines;
  measure  no comment carries a measurement: profiler names and output
           (callgrind, perf stat, ...), instruction or cycle counts, times a
           call, "N x faster", "cost N %"; nor a date or a commit hash
           (measurements go to docs/ and commit messages);
  length   no source file (Fortran, Python, CMake, shell) exceeds 600 lines.

usage: check_comments.py [--root REPO] [FILE ...] [--expect-failure-naming TEXT]

Without FILE, every source under REPO's src, umat, driver, bench, tests,
cmake and scripts folders (and REPO/CMakeLists.txt) is read; test fixtures
are skipped. --expect-failure-naming: the check itself must fail and its
report name TEXT (the fixtures' self-test); exit 0 then.
Prints one line per problem (path:line: rule: what); exit status 1 if any.
"""
import argparse
import os
import re
import sys

MAX_HEADER = 8
MAX_LINES = 600
FORTRAN = (".f90", ".F90", ".f", ".pf")
OTHER = (".py", ".cmake", ".sh")
FOLDERS = ("src", "umat", "host", "common", "point", "mpm", "apps", "bench", "tests", "cmake", "scripts")
SKIP = os.path.join("tests", "style", "fixtures")

# A comment that says one of these reports a measurement.
MEASURE = [
    (r"\b(callgrind|cachegrind|valgrind|hyperfine|gprof|perf)"
     r"(\s+and\s+\w+)?\s*:", "a profiler's output"),
    (r"\b(measured|counted|profiled|timed)\s+(with|by|under|in)\s+"
     r"(callgrind|cachegrind|valgrind|hyperfine|gprof|perf)\b", "a profiler's output"),
    (r"\bperf\s+(stat|record|report|annotate)\b", "a profiler's output"),
    (r"\d[\d,.]*\s*[kKM]?\s+(instructions|cycles|instr\.)(?!\s+applied)\b",
     "an instruction or cycle count"),
    (r"\b(hundreds|thousands|millions) of (cycles|instructions)\b",
     "an instruction or cycle count"),
    (r"\d[\d.,]*\s*(ns|nanoseconds|us|µs|microseconds|ms)\s+(a|per|each)\s+"
     r"(call|point|step|particle|update|row)\b", "a time per call"),
    (r"\d+(\.\d+)?\s*(x|times)\s+(faster|slower)\b", "a speed-up"),
    (r"~\s*\d+(\.\d+)?\s*x\b", "a speed-up"),
    (r"\bcost(s|ing)?\s+(about\s+|some\s+|~\s*)?\d+(\.\d+)?\s*%", "a cost in per cent"),
    (r"\b(19|20)\d\d-[01]\d-[0-3]\d\b", "a date"),
    (r"\bcommit\s+[0-9a-f]{7,40}\b", "a commit hash"),
    (r"\b(?=[0-9a-f]*[a-f])(?=[0-9a-f]*\d)[0-9a-f]{12,40}\b", "a commit hash"),
]
MEASURE = [(re.compile(pattern, re.IGNORECASE), what) for pattern, what in MEASURE]

UNIT = re.compile(r"^\s*(module|submodule|program)\b(?!\s+(procedure|function|subroutine|"
                  r"pure|impure|elemental|recursive|integer|real|logical|character|"
                  r"complex|type)\b)\s*[\w(]", re.IGNORECASE)


def fixed_form(path):
    return path.endswith(".f") or path.endswith(".f.in")


def split_comment(line, fixed):
    """(code, comment text or None, whole-line comment?) of a Fortran line."""
    if fixed and line[:1] in ("c", "C", "*", "d", "D"):
        return "", line[1:], True
    if line.strip().startswith("!"):
        return "", line.strip()[1:], True
    quote = None
    for i, char in enumerate(line):
        if quote:
            if char == quote:
                quote = None
        elif char in ("'", '"'):
            quote = char
        elif char == "!":
            return line[:i], line[i + 1:], False
    return line, None, False


def comment_blocks(lines, path):
    """[(first line number, [comment texts], whole-line block?)]: contiguous
    whole-line comments, and a trailing comment with those that follow it,
    joined into one block."""
    fortran = path.endswith(FORTRAN) or path.endswith(".in")
    fixed = fixed_form(path)
    blocks, current = [], None
    for number, line in enumerate(lines, 1):
        if fortran:
            _, text, whole = split_comment(line, fixed)
        else:
            stripped = line.lstrip()
            whole = stripped.startswith("#")
            text = stripped[1:] if whole else None
        if whole:
            if current is None:
                current = (number, [])
                blocks.append((current[0], current[1], True))
            current[1].append(text.lstrip("><!").strip())
            continue
        current = None
        if text is not None:
            # a trailing comment, which whole-line comments below may continue
            current = (number, [text.lstrip("><!").strip()])
            blocks.append((current[0], current[1], False))
    return blocks


def header_problems(path, lines):
    fixed = fixed_form(path)
    problems = []
    starts = []
    # the file's opening block: comment lines before the first statement
    count = 0
    for number, line in enumerate(lines, 1):
        if not line.strip():
            continue
        _, _, whole = split_comment(line, fixed)
        if not whole:
            break
        count += 1
    starts.append((1, count))
    # the block just before every later module, submodule or program
    for index, line in enumerate(lines):
        if UNIT.match(line) and not split_comment(line, fixed)[2]:
            j = index - 1
            while j >= 0 and not lines[j].strip():
                j -= 1
            first, n = j + 1, 0
            while j >= 0 and split_comment(lines[j], fixed)[2]:
                n, first, j = n + 1, j + 1, j - 1
            if first > 1 + starts[0][1] or starts[0][1] == 0:
                starts.append((max(first, 1), n))
    for number, n in starts:
        if n > MAX_HEADER:
            problems.append(f"{path}:{number}: header: a module header of {n} comment "
                            f"lines (at most {MAX_HEADER}; the long explanation goes to docs/)")
    return problems


def measure_problems(path, lines):
    problems = []
    for number, texts, _ in comment_blocks(lines, path):
        text = " ".join(texts)
        for pattern, what in MEASURE:
            match = pattern.search(text)
            if match:
                # the line of the match within the block
                offset, line = match.start(), number
                for t in texts:
                    if offset <= len(t):
                        break
                    offset -= len(t) + 1
                    line += 1
                problems.append(f"{path}:{line}: measure: a comment carries {what} "
                                f"('{match.group(0)}'): measurements go to docs/ or "
                                f"the commit message")
                break
    return problems


def check(path, shown):
    try:
        with open(path, encoding="utf-8") as handle:
            lines = handle.read().splitlines()
    except (OSError, UnicodeDecodeError) as error:
        return [f"{shown}: cannot read: {error}"]
    problems = []
    if len(lines) > MAX_LINES:
        problems.append(f"{shown}:{len(lines)}: length: {len(lines)} lines "
                        f"(at most {MAX_LINES}: split the file)")
    fortran = path.endswith(FORTRAN) or path.endswith(".in")
    if fortran:
        problems += header_problems(shown, lines)
    if fortran or path.endswith(OTHER) or os.path.basename(path) == "CMakeLists.txt":
        problems += measure_problems(shown, lines)
    return problems


def sources(root):
    found = [os.path.join(root, "CMakeLists.txt")]
    for folder in FOLDERS:
        for directory, subdirs, files in os.walk(os.path.join(root, folder)):
            relative = os.path.relpath(directory, root)
            if relative == SKIP or relative.startswith(SKIP + os.sep):
                subdirs[:] = []
                continue
            subdirs.sort()
            for name in sorted(files):
                if (name.endswith(FORTRAN + OTHER) or name == "CMakeLists.txt"
                        or re.search(r"\.(f90|F90|f)\.in$", name)):
                    found.append(os.path.join(directory, name))
    return [path for path in found if os.path.isfile(path)]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--root", default=os.path.join(os.path.dirname(__file__), "..", ".."))
    parser.add_argument("--expect-failure-naming")
    parser.add_argument("files", nargs="*")
    args = parser.parse_args()
    root = os.path.abspath(args.root)
    paths = args.files or sources(root)
    problems = []
    for path in paths:
        shown = os.path.relpath(path, root) if not args.files else path
        problems += check(path, shown)
    for problem in problems:
        print(problem)
    if args.expect_failure_naming is not None:
        if problems and any(args.expect_failure_naming in p for p in problems):
            print(f"check_comments: caught, as expected ({args.expect_failure_naming})")
            return 0
        print(f"check_comments: expected a problem naming '{args.expect_failure_naming}'; "
              f"found {len(problems)} problem(s)", file=sys.stderr)
        return 1
    if not problems:
        print(f"check_comments: {len(paths)} files, no problem")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
