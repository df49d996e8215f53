#!/usr/bin/env bash
# The README's main command: installs dependencies if missing, builds
# Release, and runs the main job on bundled data: the landing sweep of the
# drone's twin (DJI F450) on a bundled depth frame of a 10 cm step, landing
# 12 cm from the step's edge, 20 headings x 10 noisy runs; prints the decision.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=${JOBS:-2}
scripts/setup-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$jobs" --target landing_sweep terrain_mesh terrain_synth >/dev/null
mkdir -p out
build/apps/landing_sweep data/terrains/step.pcd --extrinsics data/terrains/step.extrinsics.yaml \
  --landing-point 0.12,0 --plot out/step_sweep.svg --runs-csv out/step_runs.csv
echo "plot: out/step_sweep.svg, runs: out/step_runs.csv" >&2
