#!/usr/bin/env bash
# Behaviour check for refactors: runs every app on the bundled data with two
# builds and compares the outputs byte for byte, after dropping only the
# wall-clock fields (timings differ by nature).
#
#   tests/bench/compare_outputs.sh OLD NEW
#   tests/bench/compare_outputs.sh --save DIR BUILD   # keep BUILD's outputs as a reference
#
# OLD/NEW are build trees (their apps/ folder is used), each run on the
# bundled data of its own source tree (a format change in a data file is then
# not a difference; what the apps make of it is), or OLD is a directory saved
# with --save. Prints one line per output (same / DIFFERENT) and exits 1 when
# any output differs. The landing_scenario campaigns run CAMPAIGN_COUNT
# random scenarios (default 10) per map and system; issue 30's check uses 40.
set -euo pipefail
[ $# -eq 2 ] || { [ $# -eq 3 ] && [ "$1" = --save ]; } || { echo "usage: $0 OLD NEW | --save DIR BUILD" >&2; exit 2; }
work=$(mktemp -d)
[ -n "${KEEP:-}" ] || trap 'rm -rf "$work"' EXIT; echo "outputs in $work" >&2

# Drops wall-clock keys from JSON (objects or JSON Lines) and the SVG/CSV
# lines that carry timings.
strip_timing() {
  python3 -c '
import json, sys
TIMING = {"seconds", "landings_per_second", "simulated_to_wall", "run_simulated_to_wall", "ms", "ms_median",
          "ms_p90", "solvers_us_median", "elapsed_s", "wall_s", "timing"}
def clean(x):
    if isinstance(x, dict):
        return {k: clean(v) for k, v in x.items() if k not in TIMING}
    if isinstance(x, list):
        return [clean(v) for v in x]
    return x
text = sys.stdin.read()
try:
    print(json.dumps(clean(json.loads(text)), sort_keys=True, indent=1))
except ValueError:
    out = []
    for line in text.splitlines():
        try:
            out.append(json.dumps(clean(json.loads(line)), sort_keys=True))
        except ValueError:
            out.append(line)
    print("\n".join(out))
'
}

# Drops the CSV columns that hold wall-clock figures (a campaign's wall_s,
# render_s, system_s).
strip_csv_timing() {
  python3 -c '
import csv, sys
rows = list(csv.reader(sys.stdin))
keep = [i for i, h in enumerate(rows[0]) if h not in ("wall_s", "render_s", "system_s")]
w = csv.writer(sys.stdout, lineterminator="\n")
for r in rows:
    w.writerow([r[i] for i in keep])
'
}

run_all() {
  local apps=$1/apps out=$2
  local source data=data
  source=$(sed -n 's/^CMAKE_HOME_DIRECTORY:INTERNAL=//p' "$1/CMakeCache.txt")
  apps=$(cd "$apps" && pwd)
  mkdir -p "$out"
  cd "$source"  # relative data paths: the outputs name them
  "$apps/terrain_synth" step -o "$out/step.pcd" --extrinsics-out "$out/step.extrinsics.yaml" --seed 3 2>/dev/null
  "$apps/terrain_mesh" "$data/terrains/plateau.pcd" --extrinsics "$data/terrains/plateau.extrinsics.yaml" \
    -o "$out/plateau.stl" 2>/dev/null
  "$apps/landing_sweep" "$data/terrains/step.pcd" --extrinsics "$data/terrains/step.extrinsics.yaml" \
    --landing-point 0.12,0 --headings 8 --runs 3 --threads 2 --json --runs-csv "$out/step_runs.csv" \
    --plot "$out/step.svg" 2>/dev/null | strip_timing > "$out/step_sweep.json"
  "$apps/landing_sweep" "$data/terrains/post.pcd" --extrinsics "$data/terrains/post.extrinsics.yaml" \
    --landing-point 0.205,0.205 --headings 6 --runs 2 --threads 2 --json 2>/dev/null | strip_timing > "$out/post_sweep.json"
  "$apps/led_pose" render "$out/static" --frames 30 --seed 3 2>/dev/null
  "$apps/led_pose" render "$out/board" --frames 30 --seed 5 --trajectory moving \
    --constellation "$data/constellations/f450_board.yaml" 2>/dev/null
  for seq in static board; do
    "$apps/led_pose" "$out/$seq" --jsonl 2>/dev/null | strip_timing > "$out/$seq.led.jsonl"
    "$apps/led_pose" "$out/$seq" --jsonl --no-depth 2>/dev/null | strip_timing > "$out/$seq.nodepth.jsonl"
    "$apps/led_pose" "$out/$seq" --jsonl --method aruco 2>/dev/null | strip_timing > "$out/$seq.aruco.jsonl"
  done
  "$apps/led_pose" benchmark --frames 30 --json 2>/dev/null | strip_timing > "$out/benchmark.json"
  "$apps/landing_scenario" run "$data/scenarios/clear_ground.yaml" --json --log "$out/clear_ground.log.csv" \
    --snapshot "$out/clear_ground.png" --snapshot-t 9 2>/dev/null | strip_timing > "$out/clear_ground.json"
  local map system
  for map in ground lawn; do
    for system in opencv-mls mm-mls; do
      "$apps/landing_scenario" campaign --count "${CAMPAIGN_COUNT:-10}" --map "$map" --seed 1 --threads 2 \
        --system "$system" --csv "$out/campaign_${map}_${system}.csv" >/dev/null 2>&1
      strip_csv_timing < "$out/campaign_${map}_${system}.csv" > "$out/campaign_${map}_${system}.outcomes.csv"
      rm "$out/campaign_${map}_${system}.csv"
    done
  done
}

trap 'echo "$0: failed at line $LINENO: $BASH_COMMAND" >&2' ERR
if [ "$1" = "--save" ]; then
  rm -rf "$2" && (run_all "$3" "$2") && touch "$2/.outputs" && echo "saved $2" >&2
  exit 0
fi
if [ -f "$1/.outputs" ]; then
  work_old=$(cd "$1" && pwd)
else
  (run_all "$1" "$work/old")
  work_old=$work/old
fi
(run_all "$2" "$work/new")
status=0
while IFS= read -r -d '' f; do
  rel=${f#"$work_old/"}
  if cmp -s "$f" "$work/new/$rel"; then
    echo "same       $rel"
  else
    echo "DIFFERENT  $rel"
    status=1
  fi
done < <(find "$work_old" -type f ! -name .outputs -print0 | sort -z)
exit $status
