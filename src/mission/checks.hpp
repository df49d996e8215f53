#pragma once
// The range checks of the mission's options (internal to src/mission).
#include <cmath>

namespace touchdown::mission::detail {

inline bool positive(double x) { return x > 0 && std::isfinite(x); }
inline bool non_negative(double x) { return x >= 0 && std::isfinite(x); }
inline bool probability(double x) { return x >= 0 && x < 1; }  ///< [0, 1): a NaN is refused too

}  // namespace touchdown::mission::detail
