#include "planeloc/eval/statistics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace planeloc {

ErrorStatistics ComputeStatistics(const std::vector<double>& errors) {
  if (errors.empty()) throw std::invalid_argument("ComputeStatistics: empty error vector");
  ErrorStatistics stats;
  stats.n = errors.size();
  const double count = static_cast<double>(errors.size());
  double sum = 0.0;
  for (const double e : errors) {
    sum += e;
    stats.sse += e * e;
  }
  stats.mean = sum / count;
  stats.rmse = std::sqrt(stats.sse / count);
  double squared_deviation = 0.0;
  for (const double e : errors) squared_deviation += (e - stats.mean) * (e - stats.mean);
  stats.std = std::sqrt(squared_deviation / count);
  const auto [min_it, max_it] = std::minmax_element(errors.begin(), errors.end());
  stats.min = *min_it;
  stats.max = *max_it;
  std::vector<double> sorted = errors;
  std::sort(sorted.begin(), sorted.end());
  const std::size_t half = sorted.size() / 2;
  stats.median = sorted.size() % 2 == 1 ? sorted[half] : 0.5 * (sorted[half - 1] + sorted[half]);
  return stats;
}

}  // namespace planeloc
