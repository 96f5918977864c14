#include "planeloc/eval/rpe.h"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

IndexPairs ConsecutivePairs(const std::vector<std::size_t>& checkpoints) {
  IndexPairs pairs;
  for (std::size_t k = 1; k < checkpoints.size(); ++k) {
    pairs.emplace_back(checkpoints[k - 1], checkpoints[k]);
  }
  return pairs;
}

IndexPairs PairsByFrames(std::size_t n, std::size_t delta, bool all_pairs) {
  IndexPairs pairs;
  if (all_pairs) {
    for (std::size_t i = 0; i + delta < n; ++i) pairs.emplace_back(i, i + delta);
    return pairs;
  }
  std::vector<std::size_t> checkpoints;
  for (std::size_t i = 0; i < n; i += delta) checkpoints.push_back(i);
  return ConsecutivePairs(checkpoints);
}

// evo filters.bounded_binary_search over j in [0, n) for arc_len(positions[i:j+1]) ~ target.
// Returns the index or -1. The search runs over all indices (not only j > i) exactly as evo's,
// since the path from i to any j <= i is 0, below every bound.
long BoundedBinarySearch(const std::vector<double>& cumulative, std::size_t i, double target,
                         double lower, double upper) {
  const long n = static_cast<long>(cumulative.size());
  const auto path = [&](long x) {
    const long last = std::min(x, n - 1);
    return last > static_cast<long>(i) ? cumulative[last] - cumulative[i] : 0.0;
  };
  long start = 0;
  long end = n - 1;
  long mid = -1;
  while (start <= end) {
    mid = (start + end) / 2;
    const double value = path(mid);
    if (lower <= value && value <= upper) {
      const double residual = std::abs(value - target);
      if (std::abs(path(mid - 1) - target) <= residual) {
        end = mid - 1;
        continue;
      }
      if (std::abs(path(mid + 1) - target) < residual) {
        start = mid + 1;
        continue;
      }
      return mid;
    }
    if (target < value) {
      end = mid - 1;
    } else {
      start = mid + 1;
    }
  }
  return -1;
}

IndexPairs PairsByPath(const PoseMatrices& poses, double delta, double tolerance, bool all_pairs) {
  IndexPairs pairs;
  if (all_pairs) {
    const std::vector<double> cumulative = AccumulatedDistances(poses);
    for (std::size_t i = 0; i < poses.size(); ++i) {
      const long j =
          BoundedBinarySearch(cumulative, i, delta, delta - tolerance, delta + tolerance);
      if (j >= 0) pairs.emplace_back(i, static_cast<std::size_t>(j));
    }
    return pairs;
  }
  std::vector<std::size_t> checkpoints;
  double path = 0.0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (i > 0) path += (poses[i].block<3, 1>(0, 3) - poses[i - 1].block<3, 1>(0, 3)).norm();
    if (path >= delta) {
      checkpoints.push_back(i);
      path = 0.0;
    }
  }
  return ConsecutivePairs(checkpoints);
}

}  // namespace

DeltaUnit ParseDeltaUnit(const std::string& name) {
  if (name == "frames" || name == "f") return DeltaUnit::kFrames;
  if (name == "m" || name == "meters" || name == "metres") return DeltaUnit::kMeters;
  throw InputError("", fmt::format("unknown RPE delta unit '{}'", name), "use frames or m");
}

std::string ToString(DeltaUnit unit) { return unit == DeltaUnit::kFrames ? "frames" : "m"; }

void RpeOptions::Check() const {
  if (!(delta > 0.0) || !std::isfinite(delta)) {
    throw OptionsError(fmt::format("RpeOptions.delta must be > 0, got {}", delta));
  }
  if (delta_unit == DeltaUnit::kFrames && delta != std::floor(delta)) {
    throw OptionsError(
        fmt::format("RpeOptions.delta must be a whole number of frames, got {}", delta));
  }
  if (!(relative_tolerance >= 0.0)) {
    throw OptionsError(
        fmt::format("RpeOptions.relative_tolerance must be >= 0, got {}", relative_tolerance));
  }
}

IndexPairs RpePairs(const PoseMatrices& poses, const RpeOptions& options) {
  options.Check();
  if (options.delta_unit == DeltaUnit::kFrames) {
    return PairsByFrames(poses.size(), static_cast<std::size_t>(options.delta), options.all_pairs);
  }
  return PairsByPath(poses, options.delta, options.delta * options.relative_tolerance,
                     options.all_pairs);
}

RpeResult ComputeRpe(const PoseMatrices& reference_in, PoseMatrices estimate,
                     const RpeOptions& options) {
  options.Check();
  if (reference_in.empty() || reference_in.size() != estimate.size()) {
    throw InputError("",
                     fmt::format("RPE needs two equally long, non-empty trajectories ({} vs {})",
                                 reference_in.size(), estimate.size()),
                     "associate the trajectories first (same frames, or TUM timestamps)");
  }
  PoseMatrices reference = reference_in;
  RpeResult result;
  result.alignment = AlignTrajectory(reference, options.alignment, &estimate);
  ProjectToPlane(options.plane, &reference);
  ProjectToPlane(options.plane, &estimate);
  result.pairs = RpePairs(options.pairs_from_reference ? reference : estimate, options);
  if (result.pairs.empty()) {
    throw InputError("",
                     fmt::format("RPE delta {} {} gives no pose pair on a trajectory of {} poses",
                                 options.delta, ToString(options.delta_unit), estimate.size()),
                     "use a smaller --rpe-delta");
  }
  for (const auto& [i, j] : result.pairs) {
    const Eigen::Matrix4d error = RelativePose(RelativePose(reference[i], reference[j]),
                                               RelativePose(estimate[i], estimate[j]));
    result.translation_errors.push_back(error.block<3, 1>(0, 3).norm());
    result.rotation_errors_deg.push_back(RotationAngleOf(error.topLeftCorner<3, 3>()) * 180.0 /
                                         std::numbers::pi);
  }
  result.translation = ComputeStatistics(result.translation_errors);
  result.rotation_deg = ComputeStatistics(result.rotation_errors_deg);
  return result;
}

}  // namespace planeloc
