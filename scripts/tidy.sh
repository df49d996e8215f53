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
#   scripts/tidy.sh [BUILD_DIR]    # default: build (configured when missing)
#   JOBS=4 scripts/tidy.sh         # parallel clang-tidy processes (default 2)
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
python3 - "$build/compile_commands.json" "$work/compile_commands.json" <<'PY'
import json, re, sys
entries = json.load(open(sys.argv[1]))
for e in entries:
    e["command"] = re.sub(r" -include \S+cmake_pch\.hxx| -Winvalid-pch", "", e["command"])
json.dump([e for e in entries if not e["file"].endswith("_pch_host.cpp")], open(sys.argv[2], "w"))
PY
status=0
run-clang-tidy -p "$work" -j "$jobs" -quiet -extra-arg=-Wno-unknown-warning-option >"$work/log" 2>&1 || status=$?
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
units=$(python3 -c 'import json, sys; print(len(json.load(open(sys.argv[1]))))' "$work/compile_commands.json")
echo "scripts/tidy.sh: $units translation units, no findings" >&2
