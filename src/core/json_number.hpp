#pragma once
// Figures in JSON output, private to the library and its apps (not
// installed): every double a report writes as a JSON number goes through
// round3, so that one figure reads the same in every file and app.
#include <cmath>

namespace touchdown::detail {

/// `v` rounded to 3 decimals (mm, ms, 0.001 of a rate), never a negative zero.
inline double round3(double v) { return std::round(v * 1e3) / 1e3 + 0.0; }

}  // namespace touchdown::detail
