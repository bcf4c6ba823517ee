#!/usr/bin/env python3
"""Check the shape of the documentation (docs/README.md says what goes where):
README.md opens with the two commands and has at most 120 lines; docs/ holds
its pages only in guide/ and research/ (docs/README.md is the index); the
guide states what is true of the current code, so it carries no dates, times
of day, commit hashes or branch names (those belong to research/README.md's
one table of where the expensive numbers come from, and to git).

usage: check_layout.py --root REPO [--expect-failure-naming TEXT]

Prints one line per problem; exit status 1 when there is any (with
--expect-failure-naming: 0 only when there is a problem naming TEXT).
"""
import argparse
import glob
import os
import re
import sys

README_MAX_LINES = 120
FIRST_COMMANDS = ("bash scripts/run.sh", "bash scripts/test.sh")
PARTS = ("guide", "research")
# A date (ISO, or day month year), a time of day in UTC, a commit hash
# (7 to 40 hex digits with at least one letter and one digit), a branch.
DATED = [
    (re.compile(r"\b20\d\d-[01]\d-[0-3]\d\b"), "a date"),
    (re.compile(r"\b\d{1,2} (January|February|March|April|May|June|July|August|"
                r"September|October|November|December) 20\d\d\b"), "a date"),
    (re.compile(r"\b\d{1,2}:\d\d(:\d\d)? ?UTC\b"), "a time of day"),
    (re.compile(r"\b(?=[0-9a-f]*[a-f])(?=[0-9a-f]*[0-9])[0-9a-f]{7,40}\b"), "a commit hash"),
    (re.compile(r"\b(main|master) at\b|\bunmerged\b|\b(this|the previous|that) (branch|main)\b",
                re.IGNORECASE), "a branch"),
]


def problems_of(root):
    out = []
    readme = os.path.join(root, "README.md")
    with open(readme, encoding="utf-8") as handle:
        lines = handle.read().splitlines()
    if len(lines) > README_MAX_LINES:
        out.append("README.md: %d lines, more than %d" % (len(lines), README_MAX_LINES))
    head = "\n".join(lines[:12])
    for command in FIRST_COMMANDS:
        if command not in head:
            out.append("README.md: does not open with `%s`" % command)
    docs = os.path.join(root, "docs")
    for path in sorted(glob.glob(os.path.join(docs, "*.md"))):
        if os.path.basename(path) != "README.md":
            out.append("%s: a page outside guide/ and research/"
                       % os.path.relpath(path, root))
    for part in PARTS:
        if not glob.glob(os.path.join(docs, part, "*.md")):
            out.append("docs/%s/: no pages" % part)
    for path in sorted(glob.glob(os.path.join(docs, "guide", "**", "*.md"), recursive=True)):
        name = os.path.relpath(path, root)
        with open(path, encoding="utf-8") as handle:
            for number, line in enumerate(handle, 1):
                for pattern, what in DATED:
                    found = pattern.search(line)
                    if found:
                        out.append("%s:%d: %s in the guide: %s" % (name, number, what,
                                                                   found.group(0)))
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--root", required=True)
    parser.add_argument("--expect-failure-naming")
    args = parser.parse_args()
    problems = problems_of(args.root)
    for problem in problems:
        print(problem)
    if args.expect_failure_naming is not None:
        named = any(args.expect_failure_naming in p for p in problems)
        if not named:
            print("check_layout: expected a problem naming '%s'" % args.expect_failure_naming)
        return 0 if named else 1
    print("check_layout: %d problem(s)" % len(problems))
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
