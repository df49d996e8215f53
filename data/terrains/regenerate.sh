#!/usr/bin/env bash
# Regenerates the bundled sample terrains: simulated RealSense D435 depth
# frames (424x240 mode, f = 215 px) from 1.2 m above each synthetic terrain,
# in the camera's optical frame, each with the camera pose it was taken from.
#   data/terrains/regenerate.sh [path/to/terrain_synth]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
synth=${1:-$here/../../build/apps/terrain_synth}
common=(--width 424 --height 240 --fx 215 --camera-height 1.2 --encoding binary_compressed)
"$synth" flat    -o "$here/flat.pcd"    --extrinsics-out "$here/flat.extrinsics.yaml"    "${common[@]}" --seed 1
"$synth" incline -o "$here/incline.pcd" --extrinsics-out "$here/incline.extrinsics.yaml" "${common[@]}" --seed 2 --slope 12 --azimuth 30
"$synth" step    -o "$here/step.pcd"    --extrinsics-out "$here/step.extrinsics.yaml"    "${common[@]}" --seed 3 --step-height 0.10
"$synth" plateau -o "$here/plateau.pcd" --extrinsics-out "$here/plateau.extrinsics.yaml" "${common[@]}" --seed 4 --plateau-height 0.15 --plateau-size 0.6,0.4
"$synth" rubble  -o "$here/rubble.pcd"  --extrinsics-out "$here/rubble.extrinsics.yaml"  "${common[@]}" --seed 5 --rubble-count 60 --rubble-height 0.08

# Terrains with a known landing answer (issue 3):
#  - slope_gentle: 5 deg, every heading safe;  - slope_steep: 32 deg, none safe;
#  - post: a 25 cm post of 4 cm radius at (0.205, 0.205) under a propeller at
#    most headings, clear of everything at headings 36-54 and 126-144 deg.
#  (step.pcd with --landing-point 0.12,0 is the step only the aligned heading clears.)
"$synth" incline -o "$here/slope_gentle.pcd" --extrinsics-out "$here/slope_gentle.extrinsics.yaml" "${common[@]}" --seed 6 --slope 5
"$synth" incline -o "$here/slope_steep.pcd"  --extrinsics-out "$here/slope_steep.extrinsics.yaml"  "${common[@]}" --seed 7 --slope 32
"$synth" post    -o "$here/post.pcd"         --extrinsics-out "$here/post.extrinsics.yaml"         "${common[@]}" --seed 8 --post 0.205,0.205,0.04,0.25
