// Summary statistics of an error vector, defined exactly as evo's PE.get_all_statistics (numpy):
// population std (ddof 0), median as numpy (mean of the two middle values for an even count).
#pragma once

#include <cstddef>
#include <vector>

namespace planeloc {

struct ErrorStatistics {
  double rmse = 0.0;    // sqrt(mean(e^2))
  double mean = 0.0;    // mean(e)
  double median = 0.0;  // numpy.median(e)
  double std = 0.0;     // sqrt(mean((e - mean)^2)), ddof 0
  double min = 0.0;
  double max = 0.0;
  double sse = 0.0;   // sum(e^2)
  std::size_t n = 0;  // number of errors
};

// Throws std::invalid_argument for an empty vector (callers check their inputs first).
ErrorStatistics ComputeStatistics(const std::vector<double>& errors);

}  // namespace planeloc
