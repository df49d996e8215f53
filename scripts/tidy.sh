#!/usr/bin/env bash
# The tree's clang-tidy checks (.clang-tidy): the naming convention
# (readability-identifier-naming, docs/architecture.md "Conventions") and no
# function over 150 lines (readability-function-size; a body's length is the
# line of its closing brace minus that of its opening brace, comments and
# blank lines included, a lambda counted in the function that holds it). It
# runs on every translation unit of a build tree's compilation database:
# src/, apps/, examples/ and the unity sources of the test binaries.
# Prints each finding with its file and line; exits 1 when there is one, 2
# when clang-tidy is missing or could not parse a file (no verdict).
#
# A cache of clean results (issue 59). After a run without a finding, each
# unit's key is stored: a SHA-256 of clang-tidy's version, .clang-tidy, the
# unit's command and the content of every file it reads (the source and each
# header of Ninja's dependency log, those of its precompiled header too). A
# later run skips a unit whose key is stored, so CI re-checks only what a
# change can reach; a tree without Ninja's log, or an empty cache, checks
# everything. Findings are never cached.
#
# The keys of the committed tree's clean units are also in the repository
# (scripts/tidy-clean.keys), read as a second cache, so that a fresh clone
# on a machine that never ran the checks (CI's) re-checks only what changed
# since they were recorded instead of all ~165 units (~20 min of 2 cores).
# TOUCHDOWN_TIDY_RECORD=1 rewrites that file after a clean run with the
# keys of every unit of this tree (commit it with the change).
#
#   scripts/tidy.sh [BUILD_DIR]    # default: build (configured when missing)
#   JOBS=4 scripts/tidy.sh         # parallel clang-tidy processes (default 2)
#   TOUCHDOWN_TIDY_CACHE=DIR       # the cache (default ~/.cache/touchdown/tidy;
#                                  # "off": check every unit, store nothing,
#                                  # and ignore scripts/tidy-clean.keys)
#   TOUCHDOWN_TIDY_RECORD=1        # after a clean run, rewrite scripts/tidy-clean.keys
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
build=${1:-build}
jobs=${JOBS:-2}
command -v run-clang-tidy >/dev/null 2>&1 || {
  echo "scripts/tidy.sh: run-clang-tidy not found (Debian clang-tidy; scripts/setup-deps.sh installs it)" >&2
  exit 2
}
[ -f "$build/compile_commands.json" ] || cmake -G Ninja -S . -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
build=$(cd "$build" && pwd)

# The build's precompiled headers are GCC's, which clang cannot read: a copy
# of the compilation database without them (each file then parses its own
# includes). GCC-only warning flags (-Wno-restrict) are not findings either.
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cache=${TOUCHDOWN_TIDY_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/touchdown/tidy}
python3 - "$root" "$build" "$work" "$cache" "$(clang-tidy --version)" <<'PY'
import hashlib, json, os, re, subprocess, sys
root, build, work, cache, version = sys.argv[1:]
# Keys do not depend on where the clone is: its path reads as @ROOT@ in
# commands, paths and generated files (unity sources name the tests by path).
here = lambda text: text.replace(root, "@ROOT@")
entries = json.load(open(os.path.join(build, "compile_commands.json")))
# Ninja's dependency log: object -> every file its compile read.
deps, current = {}, None
if os.path.exists(os.path.join(build, ".ninja_deps")) and cache != "off":
    log = subprocess.run(["ninja", "-C", build, "-t", "deps"], capture_output=True, text=True).stdout
    for line in log.splitlines():
        if line and not line[0].isspace():
            current = deps.setdefault(line.split(":")[0], [])
        elif line.strip() and current is not None:
            current.append(line.strip())
digests = {}
def digest(path):
    if path not in digests:
        try:
            data = open(path, "rb").read().replace(root.encode(), b"@ROOT@")
            digests[path] = hashlib.sha256(data).hexdigest()
        except OSError:
            digests[path] = "missing"
    return digests[path]
common = version + digest(os.path.join(root, ".clang-tidy"))
committed = set()
if cache != "off" and os.path.exists(os.path.join(root, "scripts", "tidy-clean.keys")):
    committed = set(open(os.path.join(root, "scripts", "tidy-clean.keys")).read().split())
todo, keys, every = [], [], []
for e in entries:
    if e["file"].endswith("_pch_host.cpp"):
        continue
    command = e["command"]
    pch = re.search(r" -include (\S+cmake_pch\.hxx)", command)
    e["command"] = re.sub(r" -include \S+cmake_pch\.hxx| -Winvalid-pch", "", command)
    out = re.search(r" -o (\S+)", command)
    files = deps.get(out.group(1)) if out else None
    if pch and files is not None:
        gch = os.path.relpath(pch.group(1) + ".gch", build)
        files = files + deps[gch] if gch in deps else None
    if not files:
        todo.append(e)  # no dependency record: always checked
        continue
    h = hashlib.sha256(here(common + e["command"] + e["file"]).encode())
    # In the order of the path-free names: sorting the paths themselves put
    # a clone's own files before or after /usr's by where the clone is.
    for f in sorted(set(files), key=here):
        h.update(here(f + digest(f if os.path.isabs(f) else os.path.join(build, f))).encode())
    key = h.hexdigest()
    every.append(key)
    stored = os.path.join(cache, key[:2], key)
    if os.path.exists(stored):
        os.utime(stored)  # last met now: kept by the 60-day pruning
    elif key in committed:
        keys.append(key)  # clean when recorded: stored in the local cache too
    else:
        todo.append(e)
        keys.append(key)
json.dump(todo, open(os.path.join(work, "compile_commands.json"), "w"))
open(os.path.join(work, "keys"), "w").write("".join(k + "\n" for k in keys))
# Every unit has a key only when each has a dependency record.
complete = len(every) == sum(not e["file"].endswith("_pch_host.cpp") for e in entries)
open(os.path.join(work, "every"), "w").write("".join(k + "\n" for k in sorted(every)) if complete else "")
open(os.path.join(work, "counts"), "w").write(f"{len(entries) - sum(e['file'].endswith('_pch_host.cpp') for e in entries)} {len(todo)}\n")
PY
status=0
read -r units todo <"$work/counts"
if [ "$todo" -gt 0 ]; then
  run-clang-tidy -p "$work" -j "$jobs" -quiet -extra-arg=-Wno-unknown-warning-option >"$work/log" 2>&1 || status=$?
else
  : >"$work/log"
fi
sed 's/\x1b\[[0-9;]*m//g' "$work/log" >"$work/plain"
findings=$(grep -E "^$root/.*: (warning|error): .*\[(readability-[a-z-]+)" "$work/plain" |
  sed -E "s|^$root/||; s/ \[readability-([a-z-]+).*\]$/ [\1]/" | sort -u || true)
[ -z "$findings" ] || echo "$findings"
if grep -qE "clang-diagnostic-error|^Error while processing" "$work/plain"; then
  grep -E ": error: .*clang-diagnostic-error|^Error while processing" "$work/plain" | sed "s|^$root/||" | sort -u | head -20 >&2
  echo "scripts/tidy.sh: clang-tidy could not parse every file: no verdict" >&2
  exit 2
fi
if [ -n "$findings" ]; then
  echo "scripts/tidy.sh: $(echo "$findings" | wc -l) finding(s) (.clang-tidy)" >&2
  exit 1
fi
if [ "$status" != 0 ]; then
  tail -30 "$work/plain" >&2
  echo "scripts/tidy.sh: run-clang-tidy failed (exit $status)" >&2
  exit 2
fi
# Clean: store the keys of the units just checked.
if [ "$cache" != off ] && [ -s "$work/keys" ]; then
  while read -r key; do
    mkdir -p "$cache/${key:0:2}" && : >"$cache/${key:0:2}/$key"
  done <"$work/keys"
  # Keys of units no run has met for 60 days go.
  find "$cache" -type f -mtime +60 -delete 2>/dev/null || true
fi
if [ "${TOUCHDOWN_TIDY_RECORD:-0}" = 1 ]; then
  if [ -s "$work/every" ]; then
    cp "$work/every" scripts/tidy-clean.keys
    echo "scripts/tidy.sh: recorded $(wc -l <scripts/tidy-clean.keys) clean units in scripts/tidy-clean.keys" >&2
  else
    echo "scripts/tidy.sh: not recorded (a unit has no dependency record: build the tree with Ninja first)" >&2
  fi
fi
echo "scripts/tidy.sh: $units translation units, $todo checked ($((units - todo)) unchanged since a clean run: $cache), no findings" >&2
