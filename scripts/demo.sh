#!/usr/bin/env bash
# The README's main command: installs dependencies if missing, builds
# Release, and runs the main job on bundled data. Until the landing sweep
# lands (issue 3), the main job is terrain_mesh on a bundled depth frame.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=${JOBS:-2}
scripts/setup-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$jobs" --target terrain_mesh terrain_synth >/dev/null
mkdir -p out
build/apps/terrain_mesh data/terrains/step.pcd --extrinsics data/terrains/step.extrinsics.yaml \
  --crop-radius 0.3 -o out/step.stl
