// KITTI odometry drift as the devkit's evaluate_odometry.cpp computes it:
// segments of 100, 200, ..., 800 m of GT path, starting every 10th frame; a segment from frame
// `first` ends at the first frame whose GT path distance exceeds dist[first] + length. For each
// segment E = (P_first^-1 P_last)^-1 (Q_first^-1 Q_last) (P = estimate, Q = GT),
// t_err = |trans(E)| / length, r_err = angle(rot(E)) / length, angle = acos((trace - 1) / 2).
// The result averages over all segments of all lengths.
#pragma once

#include <vector>

#include "planeloc/eval/pose_path.h"

namespace planeloc {

struct KittiDriftOptions {
  std::vector<double> segment_lengths_m = {100, 200, 300, 400, 500, 600, 700, 800};
  int step_frames = 10;  // a segment starts every step_frames frames (10 = 1 s at 10 Hz)

  // Throws OptionsError naming the field.
  void Check() const;
};

struct KittiDriftSegment {
  std::size_t first = 0;
  std::size_t last = 0;
  double length_m = 0.0;
  double translation_error = 0.0;  // |trans(E)| / length, fraction (multiply by 100 for %)
  double rotation_error = 0.0;     // angle(rot(E)) / length, rad/m
};

struct KittiDriftResult {
  double translation_percent = 0.0;    // mean t_err * 100
  double rotation_deg_per_100m = 0.0;  // mean r_err * 180/pi * 100
  std::vector<KittiDriftSegment> segments;
};

// `reference` and `estimate` are associated frame by frame. Throws InputError when the GT path
// is shorter than the shortest segment length (no segment at all).
KittiDriftResult ComputeKittiDrift(const PoseMatrices& reference, const PoseMatrices& estimate,
                                   const KittiDriftOptions& options = {});

}  // namespace planeloc
