// Sliding-window bundle adjustment with optional LiDAR point-to-plane constraints:
//   E = lambda * sum rho(|r_reproj|^2_info) + (1 - lambda) * sum rho(|r_plane / sigma_i|^2)
// (sigma_i per point, WindowPoint::plane_sigma, else the global plane_sigma)
// over the window's keyframe poses (cam_from_world) and the points they observe. Keyframes that
// observe window points but are outside the window are held fixed (anchors), like ORB-SLAM2's
// local BA. A point with a `plane_id` gets one point-to-plane residual against that map plane.
// With lambda = 1 (or no planes) it is exactly the visual local BA of the baseline.
#pragma once

#include <Eigen/Core>
#include <map>
#include <optional>
#include <vector>

#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/plane.h"
#include "planeloc/geometry/rigid3.h"

namespace planeloc {

struct WindowKeyframe {
  int id = 0;
  Rigid3d cam_from_world;
  bool fixed = false;  // anchors and the gauge: at least one keyframe must be fixed
};

struct WindowPoint {
  int id = 0;
  Eigen::Vector3d point_in_world = Eigen::Vector3d::Zero();
  std::optional<int> plane_id;  // id of a WindowPlane this point lies on
  // Metres: sigma of its point-to-plane residual (point and plane uncertainty along the normal);
  // 0: WindowBaOptions::plane_sigma.
  double plane_sigma = 0;
};

struct WindowObservation {
  int keyframe_id = 0;
  int point_id = 0;
  double u_left = 0, v = 0, u_right = -1;  // pixels; u_right < 0: monocular
  double information = 1.0;                // 1 / sigma^2, 1/px^2
};

struct WindowPlane {
  int id = 0;
  Plane plane_in_world;  // the LiDAR prior
  // The plane's own map error as a nuisance the window estimates (cost_functions.h,
  // PointToCorrectedPlaneError): offset_sigma > 0 adds a correction (offset, tilt) with these
  // prior sigmas, and the points' plane_sigma is then their own uncertainty only.
  // offset_sigma = 0: the plane is held fixed (the map taken as exact up to plane_sigma). The
  // tracker (AssociateWindowPlanes) holds every plane fixed.
  double offset_sigma = 0;                           // metres
  double tilt_sigma = 0;                             // radians; 0 holds the tilt at 0 (offset only)
  Eigen::Vector3d anchor = Eigen::Vector3d::Zero();  // where the tilt pivots (the centroid)
};

struct WindowProblem {
  std::vector<WindowKeyframe> keyframes;
  std::vector<WindowPoint> points;
  std::vector<WindowObservation> observations;
  std::vector<WindowPlane> planes;
};

struct WindowBaOptions {
  // Weight of the reprojection term in (0, 1]; 1 = visual only (no plane residual is added).
  // lambda = 0 is rejected by Check(): without reprojection residuals the poses are unobserved.
  // Only lambda / (1 - lambda) matters for the minimizer (see docs/optim.md).
  double lambda = 1.0;
  // Metres: point-to-plane whitening of the points without their own WindowPoint::plane_sigma.
  double plane_sigma = 0.05;
  // Metres at plane_sigma: the plane term's Huber threshold is plane_huber / plane_sigma in
  // whitened units (standard deviations) for every point, whatever its own sigma.
  double plane_huber = 0.2;
  // Metres: after the first round, a point farther than this from its plane loses its plane
  // residual for the second round (wrong point-plane association).
  double plane_outlier_distance = 0.5;
  double chi2_mono = 5.991;    // 95 % for 2 DoF, whitened px^2; Huber delta = sqrt(chi2)
  double chi2_stereo = 7.815;  // 95 % for 3 DoF
  int iterations = 10;         // per round; two rounds with outlier removal between
  int num_threads = 1;         // Ceres threads; results may differ in the last bits for > 1
  // Windows with at most this many free keyframes factor the reduced camera system densely
  // (ceres::DENSE_SCHUR, measured faster there); larger ones use ceres::SPARSE_SCHUR.
  int dense_schur_max_keyframes = 40;
  void Check() const;
};

struct WindowBaResult {
  std::map<int, Rigid3d> cam_from_world;          // every non-fixed keyframe, by id
  std::map<int, Eigen::Vector3d> point_in_world;  // every point, by id
  std::vector<bool> observation_inlier;           // aligned with problem.observations
  // Ceres cost (0.5 * sum of scaled robust squared norms) before the first round and after the
  // second. The rounds differ in the active set and kernel, so compare them only as a trend.
  double initial_cost = 0, final_cost = 0;
  bool usable = false;          // ceres::Solver::Summary::IsSolutionUsable
  int num_plane_residuals = 0;  // point-to-plane residuals in the last round
  // Per corrected plane (WindowPlane::offset_sigma > 0) with residuals: its estimated correction
  // (offset metres, tilt_u, tilt_v radians), by plane id.
  std::map<int, Eigen::Vector3d> plane_correction;
};

WindowBaResult SolveWindowBa(const StereoCamera& camera, const WindowProblem& problem,
                             const WindowBaOptions& options);

}  // namespace planeloc
