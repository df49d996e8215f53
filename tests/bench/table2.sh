#!/usr/bin/env bash
# The source's Table 2 comparison (issue 32), run across sessions: 48
# campaigns of 300 scenarios (4 methods x 2 maps x 3 seeds x 2 systems),
# 7-15 min each on 2 cores, more than one session's machine time. The
# campaigns resume (landing_fuzz compare resumes every campaign it finds in
# --out), and what a campaign needs to resume or to be reported -
# campaign.json, results.jsonl and the rlaga DQN's dqn_weights.txt; not
# state.json or the scenario files: resuming without them replays the
# search from results.jsonl, runs nothing again and writes the scenario
# files back - is kept in the repository under docs/results/table2/, so a
# new machine continues where the last one stopped.
#
#   tests/bench/table2.sh restore SYSTEM WORK   # docs/results/table2/SYSTEM -> WORK/SYSTEM
#   tests/bench/table2.sh run SYSTEM WORK       # landing_fuzz compare (resumes), table + plot in WORK
#   tests/bench/table2.sh save SYSTEM WORK      # WORK/SYSTEM -> docs/results/table2/SYSTEM
#
# SYSTEM: opencv-mls, learned-mls, mm-mls, or mm-mls-learned (mm-mls on the
# learned detector, the source's pairing). BIN (default build/apps) holds landing_fuzz.
# SEEDS (default 3) and BUDGET (default 300) as in the issue. Issue 52's
# comparison of distinct causes keeps its campaigns apart:
#   KEPT=docs/results/causes METHODS=rlaga,rlaga+diversity,rlaga+cover+near-miss tests/bench/table2.sh run opencv-mls WORK
# (KEPT: the kept tree, default docs/results/table2; METHODS and MAPS: as
# landing_fuzz compare's, default all four methods on ground,lawn). The
# source's Table 1 (issue 53) is rlaga alone on the three systems:
#   KEPT=docs/results/table1 METHODS=rlaga tests/bench/table2.sh run learned-mls WORK
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$(pwd)
usage() {
  sed -n '13,26p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
}
[ $# -eq 3 ] || usage
action=$1 system=$2 work=$3
case "$action" in restore | save | run) ;; *) usage ;; esac
detector=aruco
case "$system" in opencv-mls | mm-mls) ;; learned-mls | mm-mls-learned) detector=learned ;; *)
  echo "table2.sh: unknown system '$system' (expected opencv-mls, learned-mls, mm-mls or mm-mls-learned)" >&2
  exit 2
  ;;
esac
kept="$root/${KEPT:-docs/results/table2}/$system"
bin=${BIN:-$root/build/apps}
seeds=${SEEDS:-3}
budget=${BUDGET:-300}

# Copies each campaign's small files from $1 to $2 (same MAP/METHOD/seed-K tree).
copy_campaigns() {
  local from=$1 to=$2 dir rel f
  [ -d "$from" ] || return 0
  while IFS= read -r dir; do
    dir=$(dirname "$dir")
    rel=${dir#"$from"/}
    mkdir -p "$to/$rel"
    for f in campaign.json results.jsonl dqn_weights.txt; do
      if [ -f "$dir/$f" ]; then cp "$dir/$f" "$to/$rel/$f.tmp" && mv "$to/$rel/$f.tmp" "$to/$rel/$f"; fi
    done
    echo "$rel: $(wc -l <"$dir/results.jsonl" 2>/dev/null || echo 0) scenarios" >&2
  done < <(find -H "$from" -name campaign.json | sort)
}

case "$action" in
  restore) copy_campaigns "$kept" "$work/$system" ;;
  save) copy_campaigns "$work/$system" "$kept" ;;
  run)
    mkdir -p "$work"
    "$bin/landing_fuzz" compare --system "${system%-learned}" --detector "$detector" --maps "${MAPS:-ground,lawn}" --seeds "$seeds" --budget "$budget" \
      --methods "${METHODS:-rlaga,diverse-ga,many-objective-ga,random}" \
      --out "$work/$system" --plot "$work/table2-$system.svg" | tee "$work/table2-$system.txt"
    ;;
  *) usage ;;
esac
