#pragma once
// The range checks every Options::validate uses (internal: the modules'
// sources and the apps). A NaN fails each of them.
#include <cmath>

namespace touchdown::detail {

inline bool positive(double x) { return x > 0 && std::isfinite(x); }
inline bool non_negative(double x) { return x >= 0 && std::isfinite(x); }
inline bool probability(double x) { return x >= 0 && x < 1; }  ///< [0, 1)
/// In [lo, hi] and finite.
inline bool in_range(double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; }
/// An integer in [lo, hi].
inline bool in_range_int(int v, int lo, int hi) { return v >= lo && v <= hi; }

}  // namespace touchdown::detail
