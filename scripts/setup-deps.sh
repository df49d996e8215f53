#!/usr/bin/env bash
# Installs touchdown's build and test dependencies from Debian's archive.
# Idempotent: packages already present are not reinstalled, and nothing is
# fetched when everything is there. Needs root (or sudo) only when something
# is missing.
set -euo pipefail

packages=(
  build-essential cmake pkg-config ninja-build
  libeigen3-dev
  libode-dev
  libfcl-dev libccd-dev
  libopencv-dev libopencv-contrib-dev
  libceres-dev
  libnlopt-cxx-dev
  libassimp-dev
  libtbb-dev
  libyaml-cpp-dev
  nlohmann-json3-dev
  libcli11-dev
  libgtest-dev libgmock-dev
  libbenchmark-dev
  # the violation search: NSGA-II and Pareto utilities, campaigns across processes
  libpagmo-dev
  libopenmpi-dev openmpi-bin
  # xmllint: the SVG plot test's independent XML parser
  libxml2-utils
  # libFuzzer and the sanitizer runtimes for clang
  clang libclang-rt-14-dev clang-format
  # the naming checks (scripts/tidy.sh, .clang-tidy)
  clang-tidy
  # scripts/readme_check.py (the README-commands check) and scripts/tidy.sh
  python3
  # the independent LED renderer (../shared/tools/render_led_sequence.py):
  # tests/bench/led_independent.py and its ctest
  python3-numpy python3-opencv
  # rendering the SVG plots to PNG to look at them (docs/images/)
  librsvg2-bin
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup-deps: all ${#packages[@]} packages present" >&2
  exit 0
fi

echo "setup-deps: installing ${missing[*]}" >&2
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "setup-deps: done" >&2
