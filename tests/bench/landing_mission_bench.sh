#!/usr/bin/env bash
# Benchmark of landing_mission (issue 34): wall times of the bundled circle
# mission with the perception model (100 missions on 2 threads; one mission
# on one thread, as a multiple of real time) and with the tracker in the
# loop (20 render missions on 2 threads), medians of `repeats` runs. The
# app's own wall time ("seconds": the missions, not the process start) is
# used; the process's is printed beside it.
# Usage: tests/bench/landing_mission_bench.sh [build-dir] [repeats]
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build}
repeats=${2:-5}
app="$build/apps/landing_mission"
median() { sort -g | awk '{a[NR]=$1} END{print a[int((NR+1)/2)]}'; }
# One line per run: wall seconds, simulated seconds (sum of the missions), landed.
run() {
  local start end
  start=$(date +%s.%N)
  "$app" "$@" --json >/tmp/td_mission_bench.json
  end=$(date +%s.%N)
  python3 -c '
import json, sys
d = json.load(open("/tmp/td_mission_bench.json"))
sim = sum(m["duration_s"] for m in d["missions"])
print(d["seconds"], sim, d["summary"]["landed"], d["summary"]["runs"], float(sys.argv[2]) - float(sys.argv[1]))' "$start" "$end"
}
report() {
  local name=$1 file=$2
  local wall sim landed runs
  wall=$(cut -d' ' -f1 "$file" | median)
  sim=$(cut -d' ' -f2 "$file" | median)
  landed=$(cut -d' ' -f3 "$file" | median)
  runs=$(cut -d' ' -f4 "$file" | head -1)
  process=$(cut -d' ' -f5 "$file" | median)
  awk -v n="$name" -v w="$wall" -v s="$sim" -v l="$landed" -v r="$runs" -v k="$repeats" -v p="$process" \
    'BEGIN{printf "%s: median wall %.3f s for %d missions (%.1f s simulated, %.0fx real time; landed %d; process %.3f s), %d repeats\n", n, w, r, s, s / w, l, p, k}'
}
: >/tmp/td_b1; : >/tmp/td_b2; : >/tmp/td_b3
for _ in $(seq "$repeats"); do
  run data/missions/circle.yaml --runs 100 --threads 2 >>/tmp/td_b1
  run data/missions/circle.yaml --runs 1 --threads 1 >>/tmp/td_b2
  run data/missions/circle.yaml --runs 20 --threads 2 --perception render >>/tmp/td_b3
done
report "model, 100 missions, 2 threads" /tmp/td_b1
report "model, 1 mission, 1 thread" /tmp/td_b2
report "render, 20 missions, 2 threads" /tmp/td_b3
