#!/usr/bin/env bash
# Lists every function in src/ and apps/ whose body is longer than a line
# limit (default 150, DESIGN.md "no function over ~150"), with clang-tidy's
# readability-function-size check and nothing else. A body's length is the
# line of its closing brace minus the line of its opening brace, comments
# and blank lines included; a lambda's lines count in the function that
# holds it (the check does not report a lambda on its own).
#
#   scripts/function_size.sh [BUILD_DIR] [LIMIT]
#
# BUILD_DIR (default: build) must hold compile_commands.json: configure with
# -DCMAKE_EXPORT_COMPILE_COMMANDS=ON. Exit status 1 when a function is over
# the limit, 2 when a file could not be parsed, 0 otherwise.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:-build}" && pwd)
limit=${2:-150}
[[ -f "$build/compile_commands.json" ]] || {
  echo "$build/compile_commands.json: missing (configure with -DCMAKE_EXPORT_COMPILE_COMMANDS=ON)" >&2
  exit 2
}
command -v clang-tidy >/dev/null || {
  echo "clang-tidy not installed" >&2
  exit 2
}

# The build's precompiled headers are GCC's: clang-tidy cannot read them, so
# a copy of the compilation database without them (each file then parses
# its own includes).
db=$(mktemp -d)
trap 'rm -rf "$db"' EXIT
python3 - "$build/compile_commands.json" "$db/compile_commands.json" <<'EOF'
import json, re, sys
entries = json.load(open(sys.argv[1]))
for e in entries:
    e["command"] = re.sub(r" -include \S+cmake_pch\.hxx| -Winvalid-pch", "", e["command"])
json.dump(entries, open(sys.argv[2], "w"))
EOF

config="{Checks: '-*,readability-function-size', CheckOptions: [{key: readability-function-size.LineThreshold, value: $limit}]}"
# One output file per source (parallel runs must not interleave lines);
# GCC-only warning flags (-Wno-restrict) are not errors for clang.
export db config root
(cd "$root" && git ls-files -z 'src/*.cpp' 'apps/*.cpp') |
  xargs -0 -P "$(nproc)" -I{} sh -c 'cd "$root" && clang-tidy -quiet -p "$db" \
    --extra-arg=-Wno-unknown-warning-option --config="$config" --header-filter="^$root/(src|apps)/" \
    "$1" >"$db/$(printf %s "$1" | tr / _).log" 2>&1 || true' _ {}
out=$(cat "$db"/*.log)
# A file clang could not parse is not a file without long functions.
if grep -q ": error: " <<<"$out"; then
  grep ": error: " <<<"$out" >&2
  echo "clang-tidy could not parse every file: no verdict" >&2
  exit 2
fi
# One line per function: file:line: name: N lines.
report=$(printf '%s\n' "$out" | awk -v root="$root/" '
  /warning: function .* exceeds recommended size/ {
    split($0, a, ": warning: "); loc = a[1]; sub(root, "", loc)
    match($0, /function '\''[^'\'']*'\''/); name = substr($0, RSTART + 10, RLENGTH - 11)
  }
  /note: [0-9]+ lines including whitespace and comments/ && loc != "" {
    match($0, /[0-9]+ lines/); print loc ": " name ": " substr($0, RSTART, RLENGTH); loc = ""
  }' | sort -u)
if [[ -n "$report" ]]; then
  echo "functions over $limit lines:"
  echo "$report"
  exit 1
fi
echo "no function in src/ or apps/ over $limit lines"
