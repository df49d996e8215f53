#!/usr/bin/env bash
# Issue 55's target for a process system: a campaign of 40 scenarios with a
# trivial system in C++ through exec: costs at most 1.2x the same system
# in-process (frames included). The same code both ways: the GPS test
# lander of tests/scenario/plugins/, as a plug-in (in the host) and served by
# test_exec_child (its own process, the protocol carrying every frame's image).
# Prints each campaign's wall time, the medians of RUNS (default 3), their
# ratio, and the median of the runs' own ratios (each pair runs back to
# back, so it holds when the host's speed drifts over the runs).
#   tests/bench/exec_overhead.sh [BUILD]      # BUILD: default build
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build}
runs=${RUNS:-3}
app="$build/apps/landing_scenario"
common=(campaign --count 40 --map ground --seed 1 --threads 2 --json)
wall() { "$app" "${common[@]}" --system "$1" | python3 -c 'import json,sys; print(json.load(sys.stdin)["wall_s"])'; }
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }
in_host=() exec_=()
for ((i = 0; i < runs; i++)); do
  in_host+=("$(wall "plugin:$build/tests/libtest_plugin.so:test-gps-lander")")
  exec_+=("$(wall "exec:$build/tests/test_exec_child lander")")
  echo "run $((i + 1)): in the host ${in_host[-1]} s, through exec ${exec_[-1]} s"
done
a=$(printf '%s\n' "${in_host[@]}" | median)
b=$(printf '%s\n' "${exec_[@]}" | median)
pairs=$(for ((i = 0; i < runs; i++)); do python3 -c "print(${exec_[i]} / ${in_host[i]})"; done | median)
echo "median: in the host $a s, through exec $b s, ratio $(python3 -c "print(f'{$b / $a:.3f}')"); median of the runs' ratios $(python3 -c "print(f'{$pairs:.3f}')")"
