#!/usr/bin/env python3
"""Run the example commands of README.md and docs/cli.md and compare what
they print with what the documents show (issue 31, item 7).

  scripts/readme_check.py                  # check (exit 1 on any mismatch)
  scripts/readme_check.py --list           # the commands found, with file:line
  scripts/readme_check.py --update         # rewrite the expected outputs
  scripts/readme_check.py --bin DIR        # the apps' directory (default build/apps)
  scripts/readme_check.py FILE.md ...      # other files (default README.md docs/cli.md)

What is a command. Inside a ``` fence, a line starting with `$ ` is a
command; a command line ending in `\\` continues on the next line (README
indents those). The lines after it, up to the next `$ ` line or the end of
the fence, are its expected output (stdout and stderr together). A fence
without a `$ ` line is not looked at. `<!-- readme-check: skip (reason) -->`
on the line before a fence skips it (listed as skipped, with the reason).
A command whose first word is neither an app in --bin (also written
`build/apps/APP`), a script in KNOWN_SCRIPTS nor a tool in KNOWN_TOOLS is
skipped, with the reason.

How it runs. Each command runs with `bash -c`, in file order (a later
command reads what an earlier one wrote), with --bin first on PATH, in a
scratch directory that holds a symlink to every top-level entry of the
repository except out/ (a fresh out/ is made there): the relative paths of
the examples (data/..., out/..., lawn11.yaml) work, and nothing they write
lands in the repository. Absolute /tmp/ paths in a command are moved into
the scratch directory too, one per markdown file (and moved back in what it
prints), so two checks can run at once, a second run does not find the
first one's /tmp/seq, and docs/cli.md does not find README's.
The scratch directory is removed at the end. Scripts in KNOWN_SCRIPTS run in
the repository itself (scripts/demo.sh builds there and writes only to its
git-ignored out/).

How outputs compare. stdout and stderr are read separately, line by line,
and kept in arrival order. The expected lines must be an interleaving of
the stdout lines and the stderr lines, each stream in its own order: which
of an app's stderr line and a later `echo` on stdout comes first depends on
buffering and scheduling, so that order is not checked, while the order
within each stream is. Trailing white space is ignored. Each line is cut
into numbers and the text between them; the text must be identical, and so
must every number except the timing fields of TIMING_PATTERNS below, which
only have to be numbers. That table is explicit on purpose: a result that
changes (a count, an error, a pose) fails the check; a time does not.

--update rewrites the expected output of each mismatching command with what
it prints now (in arrival order), keeping every line that still matches
(timings included) as it is, so a re-run gives a minimal diff; with
--update-timings it also rewrites lines that differ only in timings.
Everything outside the outputs stays byte-identical. Python 3 standard
library only.
"""

import argparse
import os
import re
import selectors
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

# Timing fields. In each pattern `#` stands for the number that is a timing
# (or a rate, a speed-up, a share of time); the rest of the pattern is the
# context that identifies it. Every other number on a line is a result and
# must match exactly.
TIMING_PATTERNS = [
    r"# ms\b",  # led_pose "time per frame median 0.146 ms", landing_plan "in 2.53 ms", "total 12.84 ms"
    r"# us\b",  # landing_plan "in 308.4 us", led_pose benchmark "EPnP+GN 52.1 us"
    r"\bin # s\b",  # landing_sweep "200 landings (...) in 1.356 s"
    r"# landings/s",  # landing_sweep rate
    r"#x faster",  # landing_sweep "simulates 376x faster than real time"
    r"\(#x real time\)",  # landing_scenario campaign speed-up
    r"^\s*time:?\s+# s\b",  # terrain_mesh "time: 0.091 s", landing_scenario "time 0.904 s ..."
    r"# s wall\b",  # landing_scenario campaign wall time
    r"per scenario # s\b",  # landing_scenario campaign
    r"\b(?:render|system|physics|oracle|other) #",  # landing_scenario time shares "(render 0.431, ..." / "render 47 %"
    r'"(?:seconds|ms|us)": ?#',  # JSON/JSONL timing keys (terrain_mesh, led_pose, landing_plan)
    r"\bETA:? #",  # progress lines
    r"own work # s \(# %\)",  # landing_fuzz campaign: "the search's own work 0.05 s (1.31 %)"
    r"^(?:f450|paper) .* (?:led|aruco) .* #$",  # led_pose benchmark: the last column, ms/frame (median)
    r"\b(?:ok|FAILED) +# s\b",  # landing_scenario contract: each clause's wall time
]

# Scripts the check runs, in the repository itself (not the scratch directory).
KNOWN_SCRIPTS = {"scripts/demo.sh"}
# Standard tools an example may use to prepare an input (run in the scratch
# directory like an app: `sed ... data/plans/landing.yaml > tight.yaml`),
# Debian's Python for the independent LED renderer
# (../shared/tools/render_led_sequence.py, seeded: same files every run),
# and CMake for the plug-in example (installed into and built under /tmp/,
# which the check moves into its scratch directory).
KNOWN_TOOLS = {"sed", "cp", "printf", "/usr/bin/python3", "cmake"}

SKIP_MARKER = re.compile(r"<!--\s*readme-check:\s*skip\s*\((.*)\)\s*-->")
NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
NUM_IN_PATTERN = r"([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)"
TIMING_RES = [re.compile(p.replace("#", NUM_IN_PATTERN)) for p in TIMING_PATTERNS]
TMP_PATH = re.compile(r"(?<![\w./-])/tmp/")


@dataclass
class Command:
    path: Path  # the markdown file
    line: int  # 1-based line of the `$ ` line
    text: str  # the command, continuation lines joined with newlines
    cmd_lines: tuple  # (first, last) 0-based indices of its lines in the file
    expected: list  # expected output lines
    out_range: tuple  # (first, end) 0-based indices of the output lines
    skip: str = ""  # reason, when skipped
    actual: list = field(default_factory=list)  # [(stream, line)] in arrival order


def parse(path):
    """The commands of one markdown file, in order."""
    lines = path.read_text(encoding="utf-8").split("\n")
    commands = []
    i = 0
    while i < len(lines):
        if not lines[i].startswith("```"):
            i += 1
            continue
        skip = ""
        j = i - 1
        while j >= 0 and lines[j].strip() == "":
            j -= 1
        if j >= 0:
            m = SKIP_MARKER.search(lines[j])
            if m:
                skip = m.group(1).strip() or "marked skip"
        k = i + 1
        block = []
        while k < len(lines) and not lines[k].startswith("```"):
            block.append(k)
            k += 1
        pos = 0
        while pos < len(block):
            n = block[pos]
            if not lines[n].startswith("$ "):
                pos += 1
                continue
            first = n
            text = [lines[n][2:]]
            while lines[n].endswith("\\") and pos + 1 < len(block):
                pos += 1
                n = block[pos]
                text.append(lines[n])
            pos += 1
            out_first = pos
            while pos < len(block) and not lines[block[pos]].startswith("$ "):
                pos += 1
            out = block[out_first:pos]
            start = out[0] if out else n + 1
            end = out[-1] + 1 if out else n + 1
            commands.append(
                Command(path, first + 1, "\n".join(text), (first, n), [lines[x] for x in out], (start, end), skip)
            )
        i = k + 1
    return commands


def first_word(text):
    words = text.split()
    return words[0] if words else ""


def classify(cmd, bin_dir):
    """Sets cmd.skip when the command is not something the check can run."""
    if cmd.skip:
        return
    word = first_word(cmd.text)
    if word in KNOWN_SCRIPTS or word in KNOWN_TOOLS:
        return
    app = word[len("build/apps/") :] if word.startswith("build/apps/") else word
    if "/" in app or not (bin_dir / app).is_file():
        cmd.skip = f"'{word}' is not an app in {bin_dir} or a known script"


def make_scratch(root):
    scratch = Path(tempfile.mkdtemp(prefix="readme_check."))
    for entry in root.iterdir():
        if entry.name not in ("out", ".git"):
            (scratch / entry.name).symlink_to(entry)
    (scratch / "out").mkdir()
    return scratch


def run(cmd, bin_dir, root, scratch, tmp, timeout):
    """Runs one command, with /tmp/ moved to tmp; fills cmd.actual. Returns its exit code (None on timeout)."""
    text = cmd.text
    cwd = root
    if first_word(text) not in KNOWN_SCRIPTS:
        cwd = scratch
        text = TMP_PATH.sub(str(tmp) + "/", text)
        text = re.sub(r"(^|[\s;|&(])build/apps/", lambda m: m.group(1) + str(bin_dir) + "/", text)
    env = dict(os.environ)
    env["PATH"] = f"{bin_dir}{os.pathsep}{env.get('PATH', '')}"
    env["LC_ALL"] = "C"
    # Progress lines off a terminal come after 5 s and every 10 s: how many
    # depends on the machine's speed, so the examples are checked without.
    env["TOUCHDOWN_PROGRESS"] = "off"
    proc = subprocess.Popen(
        ["bash", "-c", text], cwd=cwd, env=env, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE
    )
    sel = selectors.DefaultSelector()
    partial = {"out": b"", "err": b""}
    sel.register(proc.stdout, selectors.EVENT_READ, "out")
    sel.register(proc.stderr, selectors.EVENT_READ, "err")
    deadline = time.monotonic() + timeout
    scratch_tmp = str(tmp) + "/"
    scratch_dir = str(scratch) + "/"

    def emit(stream, raw):
        line = raw.decode("utf-8", "replace").replace(scratch_tmp, "/tmp/").replace(scratch_dir, "")
        cmd.actual.append((stream, line.rstrip()))

    timed_out = False
    while sel.get_map():
        left = deadline - time.monotonic()
        if left <= 0:
            proc.kill()
            timed_out = True
            break
        for key, _ in sel.select(min(left, 1.0)):
            chunk = os.read(key.fileobj.fileno(), 65536)
            if not chunk:
                sel.unregister(key.fileobj)
                continue
            data = partial[key.data] + chunk
            *done, partial[key.data] = data.split(b"\n")
            for raw in done:
                emit(key.data, raw)
    for stream in ("out", "err"):
        if partial[stream]:
            emit(stream, partial[stream])
    proc.wait()
    return None if timed_out else proc.returncode


def timing_mask(line):
    """Spans of line that are timing numbers."""
    spans = []
    for regex in TIMING_RES:
        for m in regex.finditer(line):
            for g in range(1, (m.lastindex or 0) + 1):
                if m.group(g) is not None:
                    spans.append(m.span(g))
    return spans


def normalize(line):
    """The line with its timing numbers replaced by a placeholder: the key two lines compare on."""
    line = line.rstrip()
    spans = timing_mask(line)
    out = []
    last = 0
    for m in NUMBER.finditer(line):
        if any(a <= m.start() and m.end() <= b for a, b in spans):
            # A right-aligned column pads a timing to its width: the spaces
            # before it change with its digits ("  9.8" / " 10.5"), so they
            # count as one.
            before = line[last : m.start()]
            out.append(before.rstrip(" ") + " " if before.endswith(" ") else before)
            out.append("<time>")
            last = m.end()
    out.append(line[last:])
    return "".join(out)


def interleaves(expected, actual):
    """Whether expected (normalized lines) is an interleaving of the actual
    stdout and stderr lines, each stream in its own order."""
    out = [normalize(line) for s, line in actual if s == "out"]
    err = [normalize(line) for s, line in actual if s == "err"]
    if len(expected) != len(out) + len(err):
        return False
    # reach[j] after row i: expected[:i+j] can be made of out[:i] and err[:j].
    reach = [False] * (len(err) + 1)
    reach[0] = True
    for j in range(1, len(err) + 1):
        reach[j] = reach[j - 1] and expected[j - 1] == err[j - 1]
    for i in range(1, len(out) + 1):
        reach[0] = reach[0] and expected[i - 1] == out[i - 1]
        for j in range(1, len(err) + 1):
            e = expected[i + j - 1]
            reach[j] = (reach[j] and e == out[i - 1]) or (reach[j - 1] and e == err[j - 1])
    return reach[len(err)]


def matches(cmd):
    return interleaves([normalize(x) for x in cmd.expected], cmd.actual)


def short_diff(cmd, limit=12):
    """The differing lines (expected vs the actual arrival order), at most limit of them."""
    import difflib

    new = [line for _, line in cmd.actual]
    a = [normalize(x) for x in cmd.expected]
    b = [normalize(x) for x in new]
    lines = []
    for tag, i1, i2, j1, j2 in difflib.SequenceMatcher(a=a, b=b, autojunk=False).get_opcodes():
        if tag == "equal":
            continue
        lines += ["    - " + x for x in cmd.expected[i1:i2]]
        lines += ["    + " + x for x in new[j1:j2]]
    if len(lines) > limit:
        lines = lines[:limit] + [f"    ... ({len(lines) - limit} more)"]
    if not lines:
        lines = ["    (the same lines, in an order the streams cannot produce)"]
    return lines


def updated_output(cmd, keep_timings):
    """The new expected lines: what it prints now, keeping old lines that still match."""
    import difflib

    new = [line for _, line in cmd.actual]
    if keep_timings and matches(cmd):
        return list(cmd.expected)
    if not keep_timings:
        return new
    a = [normalize(x) for x in cmd.expected]
    b = [normalize(x) for x in new]
    result = list(new)
    for tag, i1, i2, j1, _ in difflib.SequenceMatcher(a=a, b=b, autojunk=False).get_opcodes():
        if tag == "equal":
            result[j1 : j1 + (i2 - i1)] = cmd.expected[i1:i2]
    return result


def rewrite(path, commands, keep_timings):
    """Replaces the output lines of the commands run in path; returns whether the file changed."""
    original = path.read_text(encoding="utf-8")
    lines = original.split("\n")
    for cmd in sorted(commands, key=lambda c: c.out_range[0], reverse=True):
        start, end = cmd.out_range
        lines[start:end] = updated_output(cmd, keep_timings)
    text = "\n".join(lines)
    if text != original:
        path.write_text(text, encoding="utf-8")
        return True
    return False


def main():
    root = Path(__file__).resolve().parent.parent
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("files", nargs="*", help="markdown files (default README.md docs/cli.md)")
    parser.add_argument("--bin", default=str(root / "build" / "apps"), help="directory of the built apps")
    parser.add_argument("--list", action="store_true", help="print the commands found and exit")
    parser.add_argument("--update", action="store_true", help="rewrite the expected outputs that changed")
    parser.add_argument("--update-timings", action="store_true", help="with --update: also refresh timings")
    parser.add_argument("--timeout", type=float, default=300, help="seconds per command (default 300)")
    parser.add_argument("--root", default=str(root), help="directory the commands run in (default the repository)")
    args = parser.parse_args()
    root = Path(args.root).resolve()
    bin_dir = Path(args.bin).resolve()
    files = [Path(f) for f in args.files] or [root / "README.md", root / "docs" / "cli.md"]
    for f in files:
        if not f.is_file():
            print(f"readme_check: {f}: no such file", file=sys.stderr)
            return 2
    if not args.list and not bin_dir.is_dir():
        print(f"readme_check: --bin: {bin_dir}: no such directory (build the apps first)", file=sys.stderr)
        return 2

    def where(cmd):
        try:
            return f"{cmd.path.resolve().relative_to(root)}:{cmd.line}"
        except ValueError:
            return f"{cmd.path}:{cmd.line}"

    commands = [c for f in files for c in parse(f)]
    for cmd in commands:
        classify(cmd, bin_dir)
    if args.list:
        for cmd in commands:
            note = f"  [skip: {cmd.skip}]" if cmd.skip else ""
            print(f"{where(cmd)}: $ {cmd.text}{note}")
        return 0

    scratch = make_scratch(root)
    failures = 0
    ran = []
    started = time.monotonic()
    try:
        for cmd in commands:
            if cmd.skip:
                print(f"skip  {where(cmd)}: $ {first_line(cmd.text)}  ({cmd.skip})")
                continue
            t0 = time.monotonic()
            tmp = scratch / "tmp" / str(files.index(cmd.path))
            tmp.mkdir(parents=True, exist_ok=True)
            code = run(cmd, bin_dir, root, scratch, tmp, args.timeout)
            took = time.monotonic() - t0
            ran.append(cmd)
            if code is None:
                failures += 1
                print(f"FAIL  {where(cmd)}: $ {first_line(cmd.text)}  (timed out after {args.timeout:.0f} s)")
            elif matches(cmd):
                print(f"ok    {where(cmd)}: $ {first_line(cmd.text)}  ({took:.1f} s)")
            else:
                failures += 1
                print(f"FAIL  {where(cmd)}: $ {first_line(cmd.text)}  ({took:.1f} s, exit {code})")
                print("\n".join(short_diff(cmd)))
            sys.stdout.flush()
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    elapsed = time.monotonic() - started
    skipped = len(commands) - len(ran)
    if args.update:
        changed = []
        for f in files:
            mine = [c for c in ran if c.path == f]
            if rewrite(f, mine, keep_timings=not args.update_timings):
                changed.append(str(f))
        print(f"readme_check: updated {', '.join(changed) if changed else 'nothing'}")
        return 0
    print(
        f"readme_check: {len(ran) - failures} of {len(ran)} commands match, {skipped} skipped, "
        f"{failures} mismatched, in {elapsed:.1f} s"
    )
    return 1 if failures else 0


def first_line(text):
    lines = text.split("\n")
    return lines[0] + (" ..." if len(lines) > 1 else "")


if __name__ == "__main__":
    sys.exit(main())
