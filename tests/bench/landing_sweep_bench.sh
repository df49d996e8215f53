#!/usr/bin/env bash
# Benchmark of the default landing sweep (n = 20 headings x m = 10 runs =
# 200 landings) on the demo's terrain (the bundled step, landing point 12 cm
# from its edge: scripts/demo.sh), 1 and 2 threads: median wall time of the
# whole process (loading and meshing the cloud included), landings per
# second, simulated-to-wall time ratio (all runs, and one run: the median
# over the 200), speed-up. Then, with --terrains, the same sweep on every
# bundled terrain (2 threads, median wall of the process).
# MODE (issue 57): "--full" (every landing, the default before the decision
# mode) or "decide" (landing_sweep's default: only the landings that can
# change the decision); its "sweep" time is the decision's.
# CONTACT (issue 57): "height-field" (the default) or "trimesh".
# Usage: tests/bench/landing_sweep_bench.sh [build-dir] [repeats] [--terrains|-] [--full|decide] [height-field|trimesh]
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build}
repeats=${2:-5}
terrains=${3:-}
mode=${4:---full}
contact=${5:-height-field}
mode_flag=(--contact "$contact")
[ "$mode" = "--full" ] && mode_flag+=(--full)
echo "mode: $mode, contact: $contact"

median() { sort -g | awk '{a[NR]=$1} END{print a[int((NR+1)/2)]}'; }
# One sweep: prints "process_wall sweep_seconds landings/s sim/wall best_yaw run_sim/wall".
sweep() {
  local t0 t1 json
  t0=$(date +%s.%N)
  json=$("$build/apps/landing_sweep" "$@" "${mode_flag[@]}" --json)
  t1=$(date +%s.%N)
  python3 -c 'import json,sys; d=json.loads(sys.argv[2]); print(float(sys.argv[1]), d["seconds"], d["landings_per_second"], d["simulated_to_wall"], d["best"]["yaw_deg"], d["run_simulated_to_wall"])' \
    "$(awk "BEGIN{print $t1 - $t0}")" "$json"
}
demo=(data/terrains/step.pcd --extrinsics data/terrains/step.extrinsics.yaml --landing-point 0.12,0)
declare -A wall
for threads in 1 2; do
  : > /tmp/td_sweep_times
  for _ in $(seq "$repeats"); do sweep "${demo[@]}" --threads "$threads" >> /tmp/td_sweep_times; done
  wall[$threads]=$(cut -d' ' -f1 /tmp/td_sweep_times | median)
  sweep_s=$(cut -d' ' -f2 /tmp/td_sweep_times | median)
  lps=$(cut -d' ' -f3 /tmp/td_sweep_times | median)
  ratio=$(cut -d' ' -f4 /tmp/td_sweep_times | median)
  best=$(cut -d' ' -f5 /tmp/td_sweep_times | sort -u | tr '\n' ' ')
  per_run=$(cut -d' ' -f6 /tmp/td_sweep_times | median)
  printf 'threads %d: median wall %.2f s (sweep %.2f s), %.0f landings/s, simulated/wall %.0f (all threads), %.0f (one run, median), best heading %s(of %d repeats)\n' \
    "$threads" "${wall[$threads]}" "$sweep_s" "$lps" "$ratio" "$per_run" "$best" "$repeats"
done
awk "BEGIN{printf \"speed-up 1 -> 2 threads: %.2fx\n\", ${wall[1]}/${wall[2]}}"
if [ "$terrains" = "--terrains" ]; then
  for f in data/terrains/*.pcd; do
    name=$(basename "$f" .pcd)
    : > /tmp/td_sweep_times
    for _ in $(seq "$repeats"); do
      sweep "$f" --extrinsics "data/terrains/$name.extrinsics.yaml" --threads 2 >> /tmp/td_sweep_times
    done
    printf '%-13s median wall %.2f s, one run %4.0fx real time (median), best heading %s\n' "$name" \
      "$(cut -d' ' -f1 /tmp/td_sweep_times | median)" "$(cut -d' ' -f6 /tmp/td_sweep_times | median)" \
      "$(cut -d' ' -f5 /tmp/td_sweep_times | sort -u | tr '\n' ' ')"
  done
fi
