#include "planeloc/eval/kitti_drift.h"

#include <fmt/format.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

// devkit lastFrameFromSegmentLength: first frame whose distance exceeds dist[first] + length.
long LastFrameFromSegmentLength(const std::vector<double>& distances, std::size_t first,
                                double length) {
  for (std::size_t i = first; i < distances.size(); ++i) {
    if (distances[i] > distances[first] + length) return static_cast<long>(i);
  }
  return -1;
}

}  // namespace

void KittiDriftOptions::Check() const {
  if (segment_lengths_m.empty()) throw OptionsError("KittiDriftOptions.segment_lengths_m is empty");
  for (const double length : segment_lengths_m) {
    if (!(length > 0.0)) {
      throw OptionsError(
          fmt::format("KittiDriftOptions.segment_lengths_m must be > 0, got {}", length));
    }
  }
  if (step_frames < 1) {
    throw OptionsError(
        fmt::format("KittiDriftOptions.step_frames must be >= 1, got {}", step_frames));
  }
}

KittiDriftResult ComputeKittiDrift(const PoseMatrices& reference, const PoseMatrices& estimate,
                                   const KittiDriftOptions& options) {
  options.Check();
  if (reference.size() != estimate.size()) {
    throw InputError("",
                     fmt::format("KITTI drift needs equally long trajectories ({} vs {})",
                                 reference.size(), estimate.size()),
                     "associate the trajectories first");
  }
  const std::vector<double> distances = AccumulatedDistances(reference);
  KittiDriftResult result;
  const std::size_t step = static_cast<std::size_t>(options.step_frames);
  for (std::size_t first = 0; first < reference.size(); first += step) {
    for (const double length : options.segment_lengths_m) {
      const long last = LastFrameFromSegmentLength(distances, first, length);
      if (last < 0) continue;
      // The devkit inverts with a general matrix inverse; so do we.
      const Eigen::Matrix4d delta_gt = reference[first].inverse() * reference[last];
      const Eigen::Matrix4d delta_est = estimate[first].inverse() * estimate[last];
      const Eigen::Matrix4d error = delta_est.inverse() * delta_gt;
      const double cos_angle = 0.5 * (error(0, 0) + error(1, 1) + error(2, 2) - 1.0);
      KittiDriftSegment segment;
      segment.first = first;
      segment.last = static_cast<std::size_t>(last);
      segment.length_m = length;
      segment.rotation_error = std::acos(std::clamp(cos_angle, -1.0, 1.0)) / length;
      segment.translation_error = error.block<3, 1>(0, 3).norm() / length;
      result.segments.push_back(segment);
    }
  }
  if (result.segments.empty()) {
    throw InputError("",
                     fmt::format("the GT path ({:.1f} m) is shorter than the shortest KITTI "
                                 "segment ({} m)",
                                 distances.empty() ? 0.0 : distances.back(),
                                 *std::min_element(options.segment_lengths_m.begin(),
                                                   options.segment_lengths_m.end())),
                     "drop --kitti-drift for short trajectories");
  }
  double t_sum = 0.0;
  double r_sum = 0.0;
  for (const KittiDriftSegment& segment : result.segments) {
    t_sum += segment.translation_error;
    r_sum += segment.rotation_error;
  }
  const double count = static_cast<double>(result.segments.size());
  result.translation_percent = 100.0 * t_sum / count;
  result.rotation_deg_per_100m = 100.0 * (r_sum / count) * 180.0 / std::numbers::pi;
  return result;
}

}  // namespace planeloc
