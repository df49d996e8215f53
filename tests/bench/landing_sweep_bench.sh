#!/usr/bin/env bash
# Benchmark of the default landing sweep (n = 20 headings x m = 10 runs =
# 200 landings) on the bundled step terrain, 1 and 2 threads: median wall
# time, landings per second, simulated-to-wall time ratio, speed-up.
# Usage: tests/bench/landing_sweep_bench.sh [build-dir] [repeats]
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build}
repeats=${2:-5}
args=(data/terrains/step.pcd --extrinsics data/terrains/step.extrinsics.yaml --landing-point 0.12,0 --json)
median() { sort -g | awk '{a[NR]=$1} END{print a[int((NR+1)/2)]}'; }
declare -A wall
for threads in 1 2; do
  : > /tmp/td_sweep_times
  for _ in $(seq "$repeats"); do
    "$build/apps/landing_sweep" "${args[@]}" --threads "$threads" |
      python3 -c 'import json,sys; d=json.load(sys.stdin); print(d["seconds"], d["landings_per_second"], d["simulated_to_wall"], d["best"]["yaw_deg"], d["run_simulated_to_wall"])' \
      >> /tmp/td_sweep_times
  done
  wall[$threads]=$(cut -d' ' -f1 /tmp/td_sweep_times | median)
  lps=$(cut -d' ' -f2 /tmp/td_sweep_times | median)
  ratio=$(cut -d' ' -f3 /tmp/td_sweep_times | median)
  best=$(cut -d' ' -f4 /tmp/td_sweep_times | sort -u | tr '\n' ' ')
  per_run=$(cut -d' ' -f5 /tmp/td_sweep_times | median)
  printf 'threads %d: median wall %.2f s, %.0f landings/s, simulated/wall %.0f (all threads), %.0f (one run, median), best heading %s(of %d repeats)\n' \
    "$threads" "${wall[$threads]}" "$lps" "$ratio" "$per_run" "$best" "$repeats"
done
awk "BEGIN{printf \"speed-up 1 -> 2 threads: %.2fx\n\", ${wall[1]}/${wall[2]}}"
