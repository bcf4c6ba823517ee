#!/usr/bin/env python3
"""Check the numbers the documentation states against the code: every claim
of the manifest (tests/docs/numbers/*.ini) names a page, the sentence
fragment that states the number, the run that reproduces it, how to read
the value from the run's outputs, the stated value and its tolerance with
the reason for it. Each run is made once, into a temporary folder, and
every claim on it is checked; one report line per claim.

usage: check_numbers.py --root REPO --bin BINDIR [--manifest PATH ...] [--pages DIR]
                        [--keep DIR] [--programs LIST] [--jobs N]
                        [--expect-failure-naming TEXT]

--pages     where the pages are looked up by file name (default: REPO/docs,
            any depth, and REPO/README.md)
--keep      make the runs in DIR and leave them there (default: a temporary
            folder, removed at the end)
--programs  make only the runs of these programs (comma-separated, e.g.
            wellposed-point); the other claims' pages and fragments are
            still checked (the unoptimized build, where the MPM runs cost
            minutes)
--jobs      runs made at a time (default 2)
--expect-failure-naming TEXT
            the check itself must fail, on the claims whose names contain
            TEXT and on no other (for the tests that show a wrong claim is
            caught); exit 0 then.
Exit status 1 when any claim fails.

The manifest is an INI file (configparser, no interpolation). A section
[run NAME] holds `command`: the documented command, build/bin/PROGRAM ...
with its deck and overrides, to which --no-plot and --out FOLDER are added.
Every other section is a claim:
  page       file name of the page (README.md, or found under docs/)
  fragment   the words of the page that state the number (white space and
             line breaks do not matter); it must contain `stated`
  run        the NAME of the [run NAME] section
  read       a Python expression of summary('KEY'), csv('FILE', 'COLUMN',
             'max'|'min'|'first'|'last'), log(r'REGEX') (group 1 of the first
             match in the run's output), ln, sqrt, abs, min, max; FILE is
             relative to the run's folder, summary.txt unless summary(KEY, FILE)
  stated     the number as the page prints it
  tolerance  absolute (0.05), relative (1%), a factor (x10: within a
             factor of 10, for the orders of magnitude of round-off),
             below / above (the page states a bound: "min R < 0"), or exact
             (a count, or a word of the summary such as not_applicable)
  why        the reason for that tolerance
"""
import argparse
import concurrent.futures
import configparser
import csv as csv_module
import glob
import math
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time

CLAIM_KEYS = ("page", "fragment", "run", "read", "stated", "tolerance", "why")
RUN_TIMEOUT = 600


def normalized(text):
    """Text with every run of white space one blank (pages wrap lines)."""
    return " ".join(text.split())


def contains(text, words):
    """True if text holds words, and a number at either end of words is not
    part of a longer one in text (a fragment ending in 1.1807 is not found
    in a page that now says 1.18073)."""
    pattern = re.escape(words)
    if words[:1].isdigit() or words[:1] in ".-":
        pattern = r"(?<![\d.])" + pattern
    if words[-1:].isdigit():
        pattern += r"(?!\.?\d)"
    return re.search(pattern, text) is not None


class Pages:
    """The pages by file name: README.md at the root, the others anywhere
    under the pages folder, so that moving a page keeps its claims."""

    def __init__(self, root, pages_dir):
        self.by_name = {}
        if pages_dir is None:
            readme = os.path.join(root, "README.md")
            if os.path.isfile(readme):
                self.by_name.setdefault("README.md", []).append(readme)
            pages_dir = os.path.join(root, "docs")
        for path in glob.glob(os.path.join(pages_dir, "**", "*.md"), recursive=True):
            if "README.md" in self.by_name and os.path.basename(path) == "README.md":
                continue          # README.md is the repository's own
            self.by_name.setdefault(os.path.basename(path), []).append(path)
        self.text = {}

    def find(self, name):
        """(normalized text, None) or (None, why not)."""
        paths = self.by_name.get(name, [])
        if len(paths) != 1:
            return None, ("no page " + name if not paths
                          else "page name %s is not unique: %s" % (name, ", ".join(paths)))
        if name not in self.text:
            with open(paths[0], encoding="utf-8") as handle:
                self.text[name] = normalized(handle.read())
        return self.text[name], None


class Run:
    """One documented command, made once into its own output root."""

    def __init__(self, name, command, bindir, out_root):
        self.name = name
        self.command = command
        self.out = os.path.join(out_root, name)
        self.bindir = bindir
        self.error = None
        self.skipped = False
        self.output = ""
        self.seconds = 0.0
        self.folder = None
        self.summaries = {}

    def argv(self):
        tokens = shlex.split(self.command)
        if not tokens or not tokens[0].startswith("build/bin/"):
            raise ValueError("command must start with build/bin/PROGRAM: " + self.command)
        program = os.path.join(self.bindir, tokens[0][len("build/bin/"):])
        return [program] + tokens[1:] + ["--no-plot", "--out", self.out]

    def program(self):
        return shlex.split(self.command)[0].rsplit("/", 1)[-1] if self.command.strip() else ""

    def make(self, root):
        try:
            argv = self.argv()
        except ValueError as exc:
            self.error = str(exc)
            return
        os.makedirs(self.out, exist_ok=True)
        start = time.monotonic()
        try:
            done = subprocess.run(argv, cwd=root, capture_output=True, text=True,
                                  timeout=RUN_TIMEOUT, stdin=subprocess.DEVNULL)
        except (OSError, subprocess.TimeoutExpired) as exc:
            self.error = "run failed: " + str(exc)
            return
        finally:
            self.seconds = time.monotonic() - start
        self.output = done.stdout + done.stderr
        if done.returncode != 0:
            tail = " | ".join(self.output.strip().splitlines()[-3:])
            self.error = "run exits %d: %s" % (done.returncode, tail)
            return
        folders = [d for d in sorted(os.listdir(self.out))
                   if os.path.isfile(os.path.join(self.out, d, "summary.txt"))]
        if len(folders) != 1:
            self.error = "expected one run folder with a summary.txt in %s, found %s" % (
                self.out, folders)
            return
        self.folder = os.path.join(self.out, folders[0])

    # readers offered to the manifest's `read` expressions
    def summary(self, key, name="summary.txt"):
        if name not in self.summaries:
            values = {}
            with open(os.path.join(self.folder, name), encoding="utf-8") as handle:
                for line in handle:
                    left, sep, right = line.partition("=")
                    if sep:
                        values[left.strip()] = right.split("#", 1)[0].strip()
            self.summaries[name] = values
        if key not in self.summaries[name]:
            raise KeyError("no key %s in %s" % (key, name))
        text = self.summaries[name][key]
        try:
            return float(text)
        except ValueError:
            return text           # a word: not_applicable, true, none

    def csv(self, name, column, which):
        with open(os.path.join(self.folder, name), encoding="utf-8", newline="") as handle:
            rows = list(csv_module.DictReader(handle))
        if not rows or column not in rows[0]:
            raise KeyError("no column %s in %s" % (column, name))
        values = [float(row[column]) for row in rows]
        pick = {"max": max, "min": min, "first": lambda v: v[0], "last": lambda v: v[-1]}
        if which not in pick:
            raise ValueError("csv(): which must be max, min, first or last, not " + which)
        return pick[which](values)

    def log(self, regex):
        found = re.search(regex, self.output, re.M)
        if found is None:
            raise KeyError("no line of the run's output matches " + regex)
        return float(found.group(1).replace(" ", ""))

    def value(self, expression):
        names = {"summary": self.summary, "csv": self.csv, "log": self.log,
                 "ln": math.log, "sqrt": math.sqrt, "abs": abs, "min": min, "max": max,
                 "range": range, "__builtins__": {}}
        value = eval(expression, names)  # the repository's own manifest
        return value if isinstance(value, str) else float(value)


def parse_tolerance(text, stated):
    """(allowed test on the measured value, how it reads): absolute, n% or xN."""
    text = text.strip()
    if isinstance(stated, str) or text == "exact":
        if text != "exact":
            raise ValueError("a word is stated: the tolerance must be exact")
        return (lambda m: m == stated), "exact"
    if text in ("below", "above"):
        if text == "below":
            return (lambda m: m < stated), "< stated"
        return (lambda m: m > stated), "> stated"
    if text.startswith("x"):
        factor = float(text[1:])
        if factor <= 1.0 or stated == 0.0:
            raise ValueError("a factor tolerance needs a factor > 1 and a nonzero value")
        low, high = sorted((stated / factor, stated * factor))
        return (lambda m: low <= m <= high), "within x" + text[1:]
    if text.endswith("%"):
        bound = abs(stated) * float(text[:-1]) / 100.0
        return (lambda m: abs(m - stated) <= bound), "+-" + text
    bound = float(text)
    if bound < 0.0:
        raise ValueError("negative tolerance " + text)
    return (lambda m: abs(m - stated) <= bound), "+-" + text


def stated_value(text):
    """The stated value: a float (`12 271` in groups of three, 1e-13,
    -38.117), or a word of the summary (not_applicable, true)."""
    try:
        return float(text.replace(" ", ""))
    except ValueError:
        return text


def check_claim(name, claim, pages, runs):
    """(report fields, failure text or None) of one claim."""
    missing = [key for key in CLAIM_KEYS if not claim.get(key, "").strip()]
    if missing:
        return None, "manifest entry lacks " + ", ".join(missing)
    text, why_not = pages.find(claim["page"])
    if text is None:
        return None, why_not
    fragment = normalized(claim["fragment"])
    if not contains(text, fragment):
        return None, "fragment not in %s: '%s'" % (claim["page"], fragment)
    stated_text = normalized(claim["stated"])
    if not contains(fragment, stated_text):
        return None, "stated value %s is not in the fragment" % stated_text
    run = runs.get(claim["run"])
    if run is None:
        return None, "no [run %s] in the manifest" % claim["run"]
    if run.skipped:
        return ("skipped",), None
    if run.error is not None:
        return None, run.error
    try:
        stated = stated_value(stated_text)
        allowed, tolerance = parse_tolerance(claim["tolerance"], stated)
        measured = run.value(claim["read"])
        if isinstance(measured, str) != isinstance(stated, str):
            raise ValueError("measured %r against stated %r" % (measured, stated))
    except (ArithmeticError, KeyError, OSError, SyntaxError, TypeError, ValueError,
            NameError, IndexError) as exc:
        return None, "cannot read %s: %s" % (claim["read"], exc)
    shown = measured if isinstance(measured, str) else "%.10g" % measured
    fields = (stated_text, shown, tolerance)
    if not allowed(measured):
        return fields, "measured %s, stated %s %s (%s)" % (
            shown, stated_text, tolerance, claim["why"])
    return fields, None


def read_manifests(paths):
    """(section name, entries) of the manifests: files, or the *.ini of
    folders; a section name given twice, in one file or two, is an error."""
    files = []
    for path in paths:
        files += sorted(glob.glob(os.path.join(path, "*.ini"))) if os.path.isdir(path) else [path]
    sections, seen = [], {}
    for path in files:
        config = configparser.ConfigParser(interpolation=None)
        config.optionxform = str
        with open(path, encoding="utf-8") as handle:
            config.read_file(handle)
        for section in config.sections():
            if section in seen:
                raise SystemExit("check_numbers: [%s] in both %s and %s" % (
                    section, seen[section], path))
            seen[section] = path
            sections.append((section, dict(config[section])))
    if not sections:
        raise SystemExit("check_numbers: no claims in " + ", ".join(paths))
    return sections


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--root", required=True)
    parser.add_argument("--bin", required=True)
    parser.add_argument("--manifest", action="append")
    parser.add_argument("--pages")
    parser.add_argument("--keep")
    parser.add_argument("--programs")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--expect-failure-naming")
    opts = parser.parse_args()
    root = os.path.abspath(opts.root)
    sections = read_manifests(opts.manifest or [os.path.join(root, "tests", "docs", "numbers")])
    pages = Pages(root, os.path.abspath(opts.pages) if opts.pages else None)

    out_root = os.path.abspath(opts.keep) if opts.keep else tempfile.mkdtemp(prefix="docs_numbers_")
    bindir = os.path.abspath(opts.bin)
    runs, claims = {}, []
    for section, entry in sections:
        if section.startswith("run "):
            name = section[4:].strip()
            runs[name] = Run(name, entry.get("command", ""), bindir, out_root)
        else:
            claims.append((section, entry))
    used = {claim.get("run", "") for _, claim in claims}
    try:
        programs = opts.programs.split(",") if opts.programs else None
        todo = []
        for name, run in runs.items():
            if name not in used:
                continue
            if programs is not None and run.program() not in programs:
                run.skipped = True
                print("run %-28s skipped (--programs %s)" % (name, opts.programs))
            else:
                todo.append(run)
        start = time.monotonic()
        with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, opts.jobs)) as pool:
            list(pool.map(lambda run: run.make(root), todo))
        wall = time.monotonic() - start
        for run in todo:
            print("run %-28s %6.1f s  %s" % (run.name, run.seconds, run.error or "ok"))
        failures, skipped = [], 0
        for name, claim in claims:
            fields, failure = check_claim(name, claim, pages, runs)
            if fields == ("skipped",):
                skipped += 1
                print("skip %-16s %-34s (its page and fragment hold; not run)" % (
                    claim["page"], name))
                continue
            fields = fields or ("-", "-", "-")
            print("%-4s %-16s %-34s stated %-10s measured %-14s %s%s" % (
                "FAIL" if failure else "ok", claim.get("page", "?"), name, fields[0],
                fields[1], fields[2], "  <- " + failure if failure else ""))
            if failure:
                failures.append(name)
    finally:
        if not opts.keep:
            shutil.rmtree(out_root, ignore_errors=True)
    seconds = sum(run.seconds for run in runs.values())
    print("check_numbers: %d claim(s) on %d run(s) (%.1f s of runs, %.1f s wall), %d not run,"
          " %d failure(s)%s" % (len(claims), len(todo), seconds, wall, skipped, len(failures),
        ": " + ", ".join(failures) if failures else ""))
    if opts.expect_failure_naming is not None:
        named = [name for name in failures if opts.expect_failure_naming in name]
        if named and len(named) == len(failures):
            print("check_numbers: the wrong claim was caught, as expected")
            return 0
        print("check_numbers: expected the claims named '%s', and only those, to fail"
              % opts.expect_failure_naming)
        return 1
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
