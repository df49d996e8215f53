#!/usr/bin/env bash
# End-to-end benchmark of the terrain_mesh app (issue 2's speed goals):
#  1. a 1,024,000-point binary PCD (simulated 1280x800 depth frame over
#     rubble) -> 2 cm height-map STL: median wall time and peak RSS;
#  2. the bundled cloud data/terrains/step.pcd: median wall time.
# Usage: tests/bench/terrain_mesh_e2e.sh [build-dir] [runs]
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build}
runs=${2:-11}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$build/apps/terrain_synth" rubble -o "$tmp/big.pcd" --extrinsics-out "$tmp/big.yaml" \
  --width 1280 --height 800 --fx 640 --camera-height 1.5 --seed 1 >/dev/null
points=$(grep -a '^POINTS' "$tmp/big.pcd" | cut -d' ' -f2)
cloud_mb=$(awk "BEGIN{printf \"%.1f\", $points*12/1e6}")

median() { sort -g | awk '{a[NR]=$1} END{print a[int((NR+1)/2)]}'; }
measure() {  # args: label, command...; prints median wall s and median max RSS MB
  local label=$1; shift
  : > "$tmp/times"
  for _ in $(seq "$runs"); do
    /usr/bin/time -f "%e %M" -o "$tmp/t" "$@" >/dev/null
    cat "$tmp/t" >> "$tmp/times"
  done
  local wall rss
  wall=$(cut -d' ' -f1 "$tmp/times" | median)
  rss=$(cut -d' ' -f2 "$tmp/times" | median)
  printf '%-44s median wall %6.3f s   median peak RSS %6.1f MB\n' "$label" "$wall" "$(awk "BEGIN{print $rss/1024}")"
}

echo "cloud: $points points (${cloud_mb} MB as float xyz), $runs runs each, $(nproc) cores, single-threaded pipeline"
measure "1M-point binary PCD -> 2 cm STL" "$build/apps/terrain_mesh" "$tmp/big.pcd" --extrinsics "$tmp/big.yaml" -o "$tmp/big.stl"
measure "bundled data/terrains/step.pcd -> STL" "$build/apps/terrain_mesh" data/terrains/step.pcd \
  --extrinsics data/terrains/step.extrinsics.yaml -o "$tmp/step.stl"
printf '0 0 0\n1 1 0.1\n0 1 0\n1 0 0\n' > "$tmp/tiny.xyz"
measure "baseline: 4-point cloud (process + libraries)" "$build/apps/terrain_mesh" "$tmp/tiny.xyz" -o "$tmp/tiny.stl" --cell 1
