#pragma once
/// \file
/// The one set of order statistics (issue 54: seven copies of median and
/// percentile were folded into these). Two medians, named for what they
/// return, because touchdown's figures use both and must not change:
///  - `median`: the mean of the two middle values for an even count (the
///    textbook median: the height map's cell, the campaign table);
///  - `upper_median`: the element of rank n/2 (0-based), a value of the
///    sample itself (timing figures, noise levels, depth at a blob).
/// `quantile(v, q)` is the element of rank ⌊q (n − 1)⌋ (the lower
/// nearest rank, no interpolation); `nearest_rank(v, q)` the element of
/// 1-based rank ⌈q n⌉ (the nearest-rank percentile: the mission's error
/// figures). The `_in_place` forms reorder their
/// span and do not allocate (hot loops); the others take a copy.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <vector>

#include "touchdown/core/error.hpp"

namespace touchdown {

/// The element of 0-based rank k of `v` (v reordered around it); k < size.
template <class T>
T nth_smallest(std::span<T> v, std::size_t k) {
  TD_ASSERT(k < v.size());
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

/// The element of rank n/2 (v reordered, not empty).
template <class T>
T upper_median_in_place(std::span<T> v) {
  return nth_smallest(v, v.size() / 2);
}

/// The median, the two middle values averaged for an even count (v
/// reordered, not empty).
template <class T>
T median_in_place(std::span<T> v) {
  const std::size_t mid = v.size() / 2;
  const T upper = nth_smallest(v, mid);
  if (v.size() % 2 != 0) return upper;
  const T lower = *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid));
  return static_cast<T>(0.5) * (upper + lower);
}

/// The element of rank ⌊q (n − 1)⌋, q clamped to [0, 1] (v reordered, not
/// empty).
template <class T>
T quantile_in_place(std::span<T> v, double q) {
  const auto k = static_cast<std::size_t>(std::clamp(q, 0.0, 1.0) * static_cast<double>(v.size() - 1));
  return nth_smallest(v, k);
}

/// The element of 1-based rank max(1, ⌈q n⌉), q clamped to [0, 1] (v
/// reordered, not empty).
template <class T>
T nearest_rank_in_place(std::span<T> v, double q) {
  const double rank = std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(v.size()));
  const auto k = static_cast<std::size_t>(std::max(1.0, rank)) - 1;
  return nth_smallest(v, std::min(k, v.size() - 1));
}

/// median_in_place of a copy; 0 for an empty sample.
inline double median(std::vector<double> v) { return v.empty() ? 0.0 : median_in_place(std::span<double>(v)); }

/// upper_median_in_place of a copy; 0 for an empty sample.
inline double upper_median(std::vector<double> v) {
  return v.empty() ? 0.0 : upper_median_in_place(std::span<double>(v));
}

/// quantile_in_place of a copy; 0 for an empty sample.
inline double quantile(std::vector<double> v, double q) {
  return v.empty() ? 0.0 : quantile_in_place(std::span<double>(v), q);
}

/// nearest_rank_in_place of a copy; 0 for an empty sample.
inline double nearest_rank(std::vector<double> v, double q) {
  return v.empty() ? 0.0 : nearest_rank_in_place(std::span<double>(v), q);
}

}  // namespace touchdown
