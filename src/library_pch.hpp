// Precompiled header of every library target (src/CMakeLists.txt): the
// standard and Eigen headers most library sources include, parsed once per
// build instead of once per source (1-3 s each; docs/journal/
// build-and-test-cost.md, 2026-12-04). Nothing of touchdown's own, so that
// editing the library never rebuilds it, and nothing a public header may not
// name (the standard library and Eigen). clang-tidy checks every source
// without it (scripts/tidy.sh), so a source still includes what it uses.
#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>
