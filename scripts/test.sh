#!/usr/bin/env bash
# The README's test command: installs dependencies if missing, builds, runs
# the whole ctest suite, then the same suite under ASan+UBSan, then each
# libFuzzer target for a short fixed time (when clang is present).
#
#   scripts/test.sh            # everything
#   FUZZ_SECONDS=0 scripts/test.sh   # skip the fuzzers
#   SKIP_ASAN=1 scripts/test.sh      # skip the sanitizer pass
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
jobs=${JOBS:-2}
fuzz_seconds=${FUZZ_SECONDS:-20}

scripts/setup-deps.sh

step() { printf '\n=== %s ===\n' "$*" >&2; }

step "Release build"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DTOUCHDOWN_WERROR=ON >/dev/null
cmake --build build -j"$jobs"
step "Tests (Release)"
ctest --test-dir build -j"$jobs" --output-on-failure

if [ "${SKIP_ASAN:-0}" != "1" ]; then
  step "ASan+UBSan build"
  san="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
  cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTOUCHDOWN_WERROR=ON \
        -DTOUCHDOWN_BUILD_BENCHMARKS=OFF \
        "-DCMAKE_CXX_FLAGS=$san" "-DCMAKE_EXE_LINKER_FLAGS=$san" "-DCMAKE_SHARED_LINKER_FLAGS=$san" >/dev/null
  cmake --build build-asan -j"$jobs"
  step "Tests (ASan+UBSan)"
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=0 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    LSAN_OPTIONS="suppressions=$root/tests/lsan.supp:print_suppressions=0" \
    ctest --test-dir build-asan -j"$jobs" --output-on-failure
fi

if [ "$fuzz_seconds" != "0" ] && command -v clang++ >/dev/null 2>&1; then
  step "libFuzzer targets (${fuzz_seconds}s each)"
  cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
        -DTOUCHDOWN_BUILD_FUZZERS=ON -DTOUCHDOWN_BUILD_TESTS=OFF -DTOUCHDOWN_BUILD_APPS=OFF \
        -DTOUCHDOWN_BUILD_EXAMPLES=OFF -DTOUCHDOWN_BUILD_BENCHMARKS=OFF >/dev/null
  cmake --build build-fuzz -j"$jobs" --target fuzz_pcd fuzz_ply fuzz_xyz fuzz_extrinsics fuzz_ground_truth \
    fuzz_camera fuzz_constellation
  for target in fuzz_pcd fuzz_ply fuzz_xyz fuzz_extrinsics fuzz_ground_truth fuzz_camera fuzz_constellation; do
    corpus="build-fuzz/corpus/$target"
    rm -rf "$corpus" && mkdir -p "$corpus"
    seeds="$root/tests/fuzz/seeds/${target#fuzz_}"
    echo "$target: ${fuzz_seconds}s" >&2
    "build-fuzz/tests/fuzz/$target" -max_total_time="$fuzz_seconds" -max_len=65536 -print_final_stats=0 \
      "$corpus" "$seeds" 2> "build-fuzz/$target.log" || { tail -40 "build-fuzz/$target.log" >&2; exit 1; }
    grep -E "^Done|#[0-9]+.*DONE" "build-fuzz/$target.log" | tail -1 >&2 || true
  done
else
  step "fuzzers skipped (FUZZ_SECONDS=0 or no clang++)"
fi
step "all tests passed"
