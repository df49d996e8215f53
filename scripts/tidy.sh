#!/usr/bin/env bash
# The naming checks (.clang-tidy: readability-identifier-naming, the
# convention in docs/architecture.md) on every translation unit of src/,
# apps/, tests/ and examples/, through the compilation database of a build
# tree (the unity sources of the test binaries included). Prints each
# offending name with its file and line; exits 1 when there is one.
#
#   scripts/tidy.sh [BUILD_DIR]    # default: build (configured when missing)
#   JOBS=4 scripts/tidy.sh         # parallel clang-tidy processes (default 2)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
jobs=${JOBS:-2}
command -v run-clang-tidy >/dev/null 2>&1 || {
  echo "scripts/tidy.sh: run-clang-tidy not found (Debian clang-tidy; scripts/setup-deps.sh installs it)" >&2
  exit 2
}
if [ ! -f "$build/compile_commands.json" ]; then
  cmake -G Ninja -S . -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
fi
log=$(mktemp)
trap 'rm -f "$log"' EXIT
# GCC-only warning flags in the database are unknown to clang: not a finding.
status=0
run-clang-tidy -p "$build" -j "$jobs" -quiet -extra-arg=-Wno-unknown-warning-option \
  >"$log" 2>&1 || status=$?
findings=$(sed 's/\x1b\[[0-9;]*m//g' "$log" | grep -E '^/.*: (warning|error): ' | sort -u || true)
if [ "$status" != 0 ] || [ -n "$findings" ]; then
  if [ -n "$findings" ]; then
    echo "$findings" | sed "s|^$(pwd)/||"
    echo "scripts/tidy.sh: $(echo "$findings" | wc -l) naming finding(s) (.clang-tidy)" >&2
  else
    tail -30 "$log" >&2
    echo "scripts/tidy.sh: clang-tidy failed (exit $status)" >&2
  fi
  exit 1
fi
echo "scripts/tidy.sh: $(grep -c '"file"' "$build/compile_commands.json") translation units, no naming findings" >&2
