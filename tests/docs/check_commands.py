#!/usr/bin/env python3
"""Check the commands of the documentation: every fenced ```bash block of
README.md and docs/**/*.md is split into commands (and so is every inline code
span that is a whole command, as in the figure tables), and for each the
scripts, programs (build/bin/<name>), decks and files it names must exist,
and every --option it gives a program must be one that program knows (named
by its --help, or quoted in the sources of the repository). The drivers
named are run with --help; `ctest ... -R REGEX` must select at least one test.
A program only an option builds (build/bin/wellposed-point-user) counts when
an earlier `cmake -D...` of the same block configures it and the build
system names it. Relative links must reach a file and, with #anchor, one of
its headings.

With --run, every command is also pasted into bash, as a reader would, in
a scratch folder that holds the repository's files and build/bin: a command
that exits non-zero is a problem. Commands too long to run are shortened or
left out by the rules of tests/docs/commands.rules (docs/guide/testing.md,
"Documented commands"); a command with a placeholder (DECK, [--out ROOT])
is a template and is not run. Each distinct command runs once.

usage: check_commands.py --root REPO --bin BINDIR [--build BUILDDIR] [--run]
                         [--rules FILE] [--doc FILE ...] [--expect-failure-naming TEXT]

--doc       the Markdown files to read (default: REPO/README.md and every REPO/docs/**/*.md)
--expect-failure-naming TEXT
            the check itself must fail and its report must name TEXT (for
            the test that shows a broken document is caught); exit 0 then.
Prints one line per problem; exit status 1 when there is any.
"""
import argparse
import glob
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile

# Top-level folders of the repository a path in a command may start with.
REPO_DIRS = ("bench", "cmake", "docs", "host", "common", "point", "mpm", "apps", "inputs", "scripts", "src",
             "tests", "umat")
# Programs of the system: not checked, only what they are given.
SYSTEM = {"cmake", "gfortran", "apt-get", "sudo", "valgrind", "time", "git",
          "h5dump", "pvpython", "env", "nice", "export", "cd", "ls", "cat"}
# Launchers: their own options are skipped, the command after them checked.
LAUNCHERS = {"mpirun", "mpiexec"}
LAUNCHER_VALUED = {"-np", "-n", "--host", "--hostfile", "--map-by"}


def fenced_bash_blocks(text):
    """(first line number, body) of every ```bash block."""
    blocks, body, start, inside = [], [], 0, False
    for number, line in enumerate(text.splitlines(), 1):
        stripped = line.strip()
        if not inside and stripped.startswith("```bash"):
            inside, body, start = True, [], number + 1
        elif inside and stripped.startswith("```"):
            inside = False
            blocks.append((start, "\n".join(body)))
        elif inside:
            body.append(line)
    return blocks


def inline_commands(text):
    """(line number, command) of the inline code spans outside fenced blocks
    that are whole commands: `build/bin/...`, `python3 ...`, `bash scripts/...`,
    `mpirun ...` (the figure tables)."""
    out, inside = [], False
    for number, line in enumerate(text.splitlines(), 1):
        if line.strip().startswith("```"):
            inside = not inside
            continue
        if inside:
            continue
        for span in re.findall(r"`([^`]+)`", line):
            if re.match(r"(build/bin/\S|python3 \S|bash scripts/|mpirun )", span):
                out.append((number, span))
    return out


def commands_of(block):
    """Commands of a block: continuation lines joined, comments dropped,
    split at &&, ||, ; and |."""
    joined = re.sub(r"\\\n", " ", block)
    out = []
    for line in joined.splitlines():
        try:
            tokens = shlex.split(line, comments=True)
        except ValueError:
            tokens = line.split()
        command = []
        for token in tokens:
            if token in ("&&", "||", ";", "|"):
                if command:
                    out.append(command)
                command = []
            else:
                command.append(token)
        if command:
            out.append(command)
    return out


def launched(tokens):
    """The command of `tokens` without VAR=value prefixes and a launcher
    with its options (mpirun -np 2 PROGRAM ...: PROGRAM ...)."""
    while tokens and re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*=\S*", tokens[0]):
        tokens = tokens[1:]
    if tokens and tokens[0] in LAUNCHERS:
        i = 1
        while i < len(tokens) and tokens[i].startswith("-"):
            i += 2 if tokens[i] in LAUNCHER_VALUED else 1
        tokens = tokens[i:]
    return tokens


def heading_anchor(heading):
    """GitHub's anchor of a Markdown heading."""
    text = heading.strip().lower()
    text = re.sub(r"[^a-z0-9 _-]", "", text)
    return text.replace(" ", "-")


def takes_help(exe):
    """The drivers answer --help; the benchmarks and test programs would run
    (or take it for a file name), so they are only checked to exist."""
    name = os.path.basename(exe)
    return name.startswith("wellposed-") and name != "wellposed-demo"


def is_placeholder(token):
    """DECK, ROOT, FILE, <name>, ...: words a user replaces."""
    bare = token.strip("[]").split("=")[-1]
    return (bare == "" or "<" in bare or "..." in bare or "$" in bare
            or re.fullmatch(r"[A-Z][A-Z0-9_]*(,[A-Z0-9_]+)*", bare) is not None)


class Checker:
    def __init__(self, root, bindir, builddir):
        self.root = root
        self.bindir = bindir
        self.builddir = builddir
        self.problems = []
        self.help_cache = {}
        self.configured = False
        self.sources = None

    def problem(self, where, text):
        self.problems.append(where + ": " + text)

    def repo_path(self, token):
        """The file a token names in the repository, or None if it names
        none (an option, a value, an output under out/, a user's file)."""
        bare = token.strip("[](),'\"")
        if "=" in bare:
            bare = bare.split("=", 1)[1]
        if is_placeholder(bare) or bare.startswith(("-", "/", "out/")):
            return None
        first = bare.split("/", 1)[0]
        if "/" in bare and first in REPO_DIRS:
            return bare.rstrip("/")
        return None

    def program(self, token):
        """Path of build/bin/<name> in the build being checked, or None."""
        if token.startswith("build/bin/"):
            return os.path.join(self.bindir, token[len("build/bin/"):])
        return None

    def cmake_target(self, name):
        """True if the build system names program `name` (one that only an
        option builds, configured by an earlier cmake -D... of the block)."""
        pattern = re.compile(r"\b" + re.escape(name) + r"\b")
        for path in glob.glob(os.path.join(self.root, "**", "CMakeLists.txt"), recursive=True) \
                + glob.glob(os.path.join(self.root, "cmake", "*.cmake")):
            if os.path.relpath(path, self.root).startswith("build"):
                continue
            with open(path, encoding="utf-8", errors="replace") as handle:
                if any(pattern.search(line) and not line.lstrip().startswith("#")
                       for line in handle):
                    return True
        return False

    def help_text(self, exe, where):
        if exe not in self.help_cache:
            try:
                run = subprocess.run([exe, "--help"], capture_output=True, text=True,
                                     timeout=60, stdin=subprocess.DEVNULL)
                self.help_cache[exe] = run.stdout + run.stderr
                if run.returncode != 0:
                    self.problem(where, os.path.basename(exe) + " --help exits "
                                 + str(run.returncode))
            except (OSError, subprocess.TimeoutExpired) as exc:
                self.help_cache[exe] = ""
                self.problem(where, os.path.basename(exe) + " --help failed: " + str(exc))
        return self.help_cache[exe]

    def source_text(self):
        """Every host, program, bench, test and script source of the repository."""
        if self.sources is None:
            parts = []
            for pattern in ("host/**/*.f90", "common/**/*.f90", "common/**/*.py",
                            "point/**/*.f90", "point/**/*.py", "mpm/**/*.f90",
                            "mpm/**/*.py", "apps/**/*.f90", "bench/*.f90",
                            "tests/**/*.py", "tests/**/*.f90", "scripts/*.sh"):
                for path in glob.glob(os.path.join(self.root, pattern), recursive=True):
                    with open(path, encoding="utf-8", errors="replace") as handle:
                        parts.append(handle.read())
            self.sources = "\n".join(parts)
        return self.sources

    def option_known(self, option, exe, script):
        """An option exists if the program's --help names it, or the script
        (for python3 SCRIPT) or the sources quote it."""
        if exe is not None and re.search(re.escape(option) + r"\b", self.help_cache.get(exe, "")):
            return True
        if script is not None:
            with open(script, encoding="utf-8", errors="replace") as handle:
                if option in handle.read():
                    return True
            return False
        quoted = ("'" + option + "'", '"' + option + '"')
        return any(q in self.source_text() for q in quoted)

    def check_command(self, tokens, where):
        tokens = launched(tokens)
        if tokens and tokens[0] in ("nice", "time"):
            tokens = tokens[1:]
        if not tokens:
            return
        head = tokens[0]
        exe = script = None
        args = tokens[1:]
        if head in ("bash", "sh", "python3", "python"):
            if not args:
                return
            path = self.repo_path(args[0])
            if path is None:
                self.problem(where, "'" + head + " " + args[0] + "': not a file of the repository")
                return
            script = os.path.join(self.root, path)
            if not os.path.isfile(script):
                self.problem(where, "missing script " + path)
                return
            args = args[1:]
            if path == "scripts/run.sh":       # its arguments go to wellposed-mpm
                exe = os.path.join(self.bindir, "wellposed-mpm")
                script = None
            elif path.startswith("scripts/"):  # test.sh: arguments go to ctest
                args = []
        elif head == "ctest":
            self.check_ctest(args, where)
            return
        elif head in SYSTEM or head in LAUNCHERS:
            pass
        elif self.program(head) is not None:
            exe = self.program(head)
            if not os.access(exe, os.X_OK):
                if not (self.configured and self.cmake_target(os.path.basename(exe))):
                    self.problem(where, "missing program " + head)
                return
        elif head.startswith("build/"):
            self.problem(where, "not a program of the build: " + head)
            return
        elif self.repo_path(head) is not None and not os.path.exists(
                os.path.join(self.root, self.repo_path(head))):
            self.problem(where, "missing " + self.repo_path(head))
            return
        if exe is not None and os.access(exe, os.X_OK) and takes_help(exe):
            self.help_text(exe, where)
        for token in args:
            path = self.repo_path(token)
            if path is not None and not os.path.exists(os.path.join(self.root, path)):
                self.problem(where, "missing file " + path)
            program = self.program(token.strip("[]"))
            if program is not None and not os.access(program, os.X_OK):
                self.problem(where, "missing program " + token.strip("[]"))
            bare = token.strip("[]")
            if bare.startswith("--") and head not in SYSTEM and (exe or script):
                option = bare.split("=", 1)[0]
                if option != "--" and not self.option_known(option, exe, script):
                    self.problem(where, "unknown option " + option + " of "
                                 + os.path.basename(exe or script))

    def check_ctest(self, args, where):
        """`ctest ... -R REGEX` must select a test of the build."""
        regex = None
        for i, token in enumerate(args):
            if token == "-R" and i + 1 < len(args):
                regex = args[i + 1]
        if regex is None or self.builddir is None or is_placeholder(regex):
            return
        run = subprocess.run(["ctest", "--test-dir", self.builddir, "-N", "-R", regex],
                             capture_output=True, text=True, timeout=120)
        found = re.search(r"Total Tests: (\d+)", run.stdout)
        if not found or int(found.group(1)) == 0:
            self.problem(where, "ctest -R " + regex + " selects no test")

    def check_links(self, path, text):
        """Relative links [text](file#anchor) must reach a file of the
        repository and, with an anchor, one of its headings."""
        name = os.path.relpath(path, self.root)
        for number, line in enumerate(text.splitlines(), 1):
            for target in re.findall(r"\]\(([^)\s]+)\)", line):
                if re.match(r"[a-z]+:", target):
                    continue
                file_part, _, anchor = target.partition("#")
                linked = os.path.normpath(os.path.join(os.path.dirname(path), file_part)) \
                    if file_part else path
                if not os.path.exists(linked):
                    self.problem(name + ":" + str(number), "broken link " + target)
                elif anchor and linked.endswith(".md"):
                    with open(linked, encoding="utf-8") as handle:
                        anchors = {heading_anchor(h) for h in
                                   re.findall(r"^#+\s+(.*)$", handle.read(), re.M)}
                    if anchor not in anchors:
                        self.problem(name + ":" + str(number), "no heading for link " + target)

    def check_file(self, path):
        with open(path, encoding="utf-8") as handle:
            text = handle.read()
        name = os.path.relpath(path, self.root)
        self.check_links(path, text)
        for start, block in fenced_bash_blocks(text):
            self.configured = False
            for command in commands_of(block):
                self.check_command(command, name + ":" + str(start))
                if command[:1] == ["cmake"] and any(t.startswith("-D") for t in command):
                    self.configured = True
        self.configured = False
        for number, span in inline_commands(text):
            for command in commands_of(span):
                self.check_command(command, name + ":" + str(number))


def command_lines(text):
    """(line number, command line as printed) of every ```bash block (its
    continuation lines joined) and every inline whole-command span."""
    out = []
    for start, block in fenced_bash_blocks(text):
        number, pending = start, ""
        for offset, line in enumerate(block.split("\n")):
            if not pending:
                number = start + offset
            if line.rstrip().endswith("\\"):
                pending += line.rstrip()[:-1] + " "
                continue
            line, pending = pending + line, ""
            if line.strip() and not line.strip().startswith("#"):
                out.append((number, line.strip()))
    for number, span in inline_commands(text):
        out.append((number, span.replace("\\|", "|")))
    return out


def strip_comment(line):
    """`line` without its trailing comment (a # after a blank, outside quotes)."""
    quote = None
    for i, ch in enumerate(line):
        if quote:
            quote = None if ch == quote else quote
        elif ch in "'\"":
            quote = ch
        elif ch == "#" and (i == 0 or line[i - 1] in " \t"):
            return line[:i].rstrip()
    return line.rstrip()


def load_rules(path):
    """[(how, compiled regex, why)] of a rules file (HOW | REGEX | WHY)."""
    rules = []
    with open(path, encoding="utf-8") as handle:
        for line in handle:
            if not line.strip() or line.lstrip().startswith("#"):
                continue
            how, regex, why = (part.strip() for part in line.split(" | ", 2))
            if how not in ("check", "skip"):
                raise SystemExit(path + ": unknown rule " + how)
            rules.append((how, re.compile(regex), why))
    return rules


class Runner:
    """Runs documented commands in bash in a scratch folder that links the
    repository's top-level entries and build/bin."""

    # an MPI program started without mpirun: a quick isolated singleton;
    # mpirun -np 4 on a smaller machine: oversubscribed
    ENV = {"OMPI_MCA_ess_singleton_isolated": "1", "OMPI_MCA_pml": "ob1",
           "OMPI_MCA_btl": "self,vader", "OMPI_MCA_rmaps_base_oversubscribe": "1"}

    def __init__(self, root, bindir, rules):
        self.rules = rules
        self.done = {}
        self.counts = {"full": 0, "check": 0, "skip": 0, "template": 0}
        self.folder = tempfile.mkdtemp(prefix="docs_commands.")
        for entry in os.listdir(root):
            if entry.startswith((".", "build", "out")):
                continue
            os.symlink(os.path.join(root, entry), os.path.join(self.folder, entry))
        os.makedirs(os.path.join(self.folder, "build"))
        os.symlink(bindir, os.path.join(self.folder, "build", "bin"))
        self.env = dict(os.environ)
        for key, value in self.ENV.items():
            self.env.setdefault(key, value)
        # `python3` is the interpreter the build found (the one running this)
        self.env["PATH"] = os.path.dirname(sys.executable) + os.pathsep + self.env["PATH"]

    def close(self):
        shutil.rmtree(self.folder, ignore_errors=True)

    def how(self, command):
        """'full', 'check', 'skip' or 'template', and why."""
        try:
            tokens = shlex.split(command)
        except ValueError:
            return "full", ""
        if not launched(tokens):
            return "template", "a launcher alone (prose)"
        if any(is_placeholder(t) or t.startswith("[") for t in tokens):
            return "template", "a placeholder"
        for how, regex, why in self.rules:
            if regex.search(command):
                return how, why
        return "full", ""

    def run(self, checker, where, line):
        command = strip_comment(line)
        how, _ = self.how(command)
        if command in self.done:
            return
        self.done[command] = how
        self.counts[how] += 1
        if how in ("skip", "template"):
            return
        text = command + (" --check" if how == "check" else "")
        try:
            run = subprocess.run(["bash", "-c", text], cwd=self.folder, env=self.env,
                                 capture_output=True, text=True, errors="replace",
                                 timeout=600, stdin=subprocess.DEVNULL)
        except subprocess.TimeoutExpired:
            checker.problem(where, "'" + text + "' run in bash did not end in 600 s")
            return
        if run.returncode != 0:
            said = (run.stderr.strip() or run.stdout.strip()).splitlines()
            checker.problem(where, "'" + text + "' run in bash exits " + str(run.returncode)
                            + (": " + said[-1] if said else ""))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--root", required=True)
    parser.add_argument("--bin", required=True)
    parser.add_argument("--build")
    parser.add_argument("--doc", action="append")
    parser.add_argument("--expect-failure-naming")
    parser.add_argument("--run", action="store_true")
    parser.add_argument("--rules", default=os.path.join(os.path.dirname(
        os.path.abspath(__file__)), "commands.rules"))
    opts = parser.parse_args()
    root = os.path.abspath(opts.root)
    docs = opts.doc or ([os.path.join(root, "README.md")]
                        + sorted(glob.glob(os.path.join(root, "docs", "**", "*.md"),
                                           recursive=True)))
    checker = Checker(root, os.path.abspath(opts.bin),
                      os.path.abspath(opts.build) if opts.build else None)
    runner = Runner(root, os.path.abspath(opts.bin), load_rules(opts.rules)) \
        if opts.run else None
    ncommands = 0
    for doc in docs:
        if not os.path.isfile(doc):
            checker.problem(doc, "no such document")
            continue
        checker.check_file(doc)
        if runner is not None:
            with open(doc, encoding="utf-8") as handle:
                for number, line in command_lines(handle.read()):
                    runner.run(checker, os.path.relpath(doc, root) + ":" + str(number), line)
        with open(doc, encoding="utf-8") as handle:
            text = handle.read()
            ncommands += sum(len(commands_of(b)) for _, b in fenced_bash_blocks(text))
            ncommands += len(inline_commands(text))
    for line in checker.problems:
        print(line)
    print("check_commands: %d document(s), %d command(s), %d problem(s), %d program(s) run"
          " with --help" % (len(docs), ncommands, len(checker.problems), len(checker.help_cache)))
    if runner is not None:
        runner.close()
        print("check_commands --run: of %d distinct commands, %d run in full, %d with --check, "
              "%d not run by a rule, %d templates" % (
                  len(runner.done), runner.counts["full"], runner.counts["check"],
                  runner.counts["skip"], runner.counts["template"]))
    if opts.expect_failure_naming is not None:
        named = any(opts.expect_failure_naming in line for line in checker.problems)
        if checker.problems and named:
            print("check_commands: the broken document was caught, as expected")
            return 0
        print("check_commands: expected a problem naming '%s'" % opts.expect_failure_naming)
        return 1
    return 1 if checker.problems else 0


if __name__ == "__main__":
    sys.exit(main())
