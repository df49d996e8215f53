#!/usr/bin/env bash
# Issue 32's overhead target: a 300-scenario rlaga campaign against
# `landing_scenario campaign` on the same 300 scenario files (with the
# campaign's DQN weights), three interleaved pairs A1 B1 A2 B2 A3 B3 on a
# quiet machine (~1 h on 2 cores). Prints each run's wall and user time
# and the pairs' wall-time ratios A/B (target: median <= 1.05).
#
#   tests/bench/overhead.sh BIN WORK   # BIN holds landing_fuzz and landing_scenario
set -euo pipefail
[ $# -eq 2 ] || { sed -n '2,8p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
bin=$1 work=$2
for app in landing_fuzz landing_scenario; do
  [ -x "$bin/$app" ] || { echo "overhead.sh: $bin/$app not found" >&2; exit 2; }
done
rm -rf "$work" && mkdir -p "$work"
for k in 1 2 3; do
  /usr/bin/time -f "A$k %e %U" -o "$work/a$k.time" "$bin/landing_fuzz" campaign --method rlaga --system opencv-mls \
    --map ground --budget 300 --population 20 --seed 1 --out "$work/a$k" >"$work/a$k.out" 2>/dev/null
  /usr/bin/time -f "B$k %e %U" -o "$work/b$k.time" "$bin/landing_scenario" campaign --system opencv-mls --threads 2 \
    --weights "$work/a$k/dqn_weights.txt" "$work"/a"$k"/scenarios/*.yaml >"$work/b$k.out" 2>/dev/null
  read -r _ a_wall a_user <"$work/a$k.time"
  read -r _ b_wall b_user <"$work/b$k.time"
  echo "pair $k: A ${a_wall} s wall ${a_user} s user, B ${b_wall} s wall ${b_user} s user, ratio $(awk -v a="$a_wall" -v b="$b_wall" 'BEGIN { printf "%.3f", a / b }')"
done
