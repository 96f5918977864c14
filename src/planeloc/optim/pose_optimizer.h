// Motion-only bundle adjustment: the pose of one stereo frame from fixed 3-D points, as in
// ORB-SLAM2's PoseOptimization, solved with Ceres (Huber loss, four rounds with chi-square outlier
// classification, outliers switched off between rounds, robust kernel dropped in the last round).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/rigid3.h"

namespace planeloc {

// One measurement of a map point in a frame. `u_right` < 0 means a monocular observation
// (no stereo match): only (u_left, v) is used.
struct PoseObservation {
  Eigen::Vector3d point_in_world;
  double u_left = 0, v = 0, u_right = -1;  // pixels, level 0
  double information = 1.0;                // 1 / sigma^2 in 1/px^2 (1 / LevelSigma2(octave))
};

struct PoseOptimizerOptions {
  int rounds = 4;
  int iterations_per_round = 10;
  double chi2_mono = 5.991;    // 95 % for 2 DoF
  double chi2_stereo = 7.815;  // 95 % for 3 DoF
  void Check() const;
};

struct PoseOptimizerResult {
  Rigid3d cam_from_world;
  std::vector<bool> inlier;  // per observation, after the last round
  int num_inliers = 0;
};

PoseOptimizerResult OptimizePose(const StereoCamera& camera, const Rigid3d& cam_from_world_initial,
                                 const std::vector<PoseObservation>& observations,
                                 const PoseOptimizerOptions& options = {});

}  // namespace planeloc
