// The search metrics of RLaGA §4.3 (metrics.hpp).
#include "touchdown/search/metrics.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <string>

#include "touchdown/core/error.hpp"

namespace touchdown::search {
namespace {

// eq. 7 (parameter distance): mean pairwise Euclidean distance between the
// violating scenarios' normalised chromosomes, over sqrt(dimension) so that
// two opposite corners of the unit cube are 1 apart.
double parameter_distance(const std::vector<const EvaluationRecord*>& violating) {
  if (violating.size() < 2) return 0.0;
  const std::size_t dim = violating.front()->genes.size();
  if (dim == 0) return 0.0;
  double sum = 0;
  long long pairs = 0;
  for (std::size_t i = 0; i < violating.size(); ++i) {
    for (std::size_t j = i + 1; j < violating.size(); ++j) {
      const auto& a = violating[i]->genes;
      const auto& b = violating[j]->genes;
      double d2 = 0;
      for (std::size_t g = 0; g < dim; ++g) d2 += (a[g] - b[g]) * (a[g] - b[g]);
      sum += std::sqrt(d2);
      ++pairs;
    }
  }
  return sum / static_cast<double>(pairs) / std::sqrt(static_cast<double>(dim));
}

}  // namespace

SearchMetrics compute_metrics(const std::vector<EvaluationRecord>& records, int k, Count count) {
  if (k < 1) throw InvalidArgument("compute_metrics: k: must be at least 1, got " + std::to_string(k));
  SearchMetrics m;
  m.evaluated = static_cast<int>(records.size());
  m.facts_recorded = std::all_of(records.begin(), records.end(),
                                 [](const EvaluationRecord& r) { return r.evaluation.facts.recorded; });
  std::vector<const EvaluationRecord*> violating;
  std::set<std::array<int, 3>> cells;
  for (std::size_t i = 0; i < records.size(); ++i) {
    const EvaluationRecord& r = records[i];
    if (r.index != static_cast<int>(i)) {
      throw InvalidArgument("compute_metrics: record " + std::to_string(i) + " has index " + std::to_string(r.index) +
                            " (records must be in index order)");
    }
    const scenario::Violation v = r.evaluation.violation;
    if (v == scenario::Violation::SystemFailed) ++m.system_failed;
    if (!scenario::is_violation(v)) continue;
    if (!r.evaluation.fair_violation()) {
      ++m.unfair;
      if (count == Count::Fair) continue;
    }
    if (!violating.empty() && r.genes.size() != violating.front()->genes.size()) {
      throw InvalidArgument("compute_metrics: record " + std::to_string(i) + " has " + std::to_string(r.genes.size()) +
                            " genes, record " + std::to_string(violating.front()->index) + " has " +
                            std::to_string(violating.front()->genes.size()));
    }
    violating.push_back(&r);
    ++m.violations;
    if (v == scenario::Violation::TypeI) ++m.type_i;
    if (v == scenario::Violation::TypeII) ++m.type_ii;
    if (v == scenario::Violation::TypeIII) ++m.type_iii;
    if (v == scenario::Violation::OffMarker) ++m.off_marker;
    // Top-K and rounds count scenarios evaluated, this one included.
    if (m.violations == k) m.top_k = static_cast<int>(i) + 1;
    if (!m.rounds_all_types && m.type_i > 0 && m.type_ii > 0 && m.type_iii > 0) {
      m.rounds_all_types = static_cast<int>(i) + 1;
    }
    cells.insert(r.evaluation.cells.begin(), r.evaluation.cells.end());
  }
  if (m.evaluated > 0) m.violation_percent = 100.0 * m.violations / m.evaluated;
  m.parameter_distance = parameter_distance(violating);
  m.coverage_cells = static_cast<int>(cells.size());
  return m;
}

std::vector<int> cumulative_violations(const std::vector<EvaluationRecord>& records, Count count) {
  std::vector<int> out;
  out.reserve(records.size());
  int n = 0;
  for (const EvaluationRecord& r : records) {
    if (count == Count::Fair ? r.evaluation.fair_violation() : r.evaluation.violation_found()) ++n;
    out.push_back(n);
  }
  return out;
}

}  // namespace touchdown::search
