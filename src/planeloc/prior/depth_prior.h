// The depth-to-map residual of Kim, Jeong and Kim, "Stereo camera localization in 3D LiDAR maps"
// (IROS 2018), in the frame's pose optimisation (`planeloc run --map-cloud map.pcd --prior
// depth`). The LiDAR map's points in view are projected into the left image; where the dense
// stereo (features/dense_stereo.h) has a disparity there, the residual is
//
//   r = (d_stereo(pi(x_cam)) - f*b / z_cam) / sigma_d,   x_cam = R * x_world + t,
//
// the stereo surface against the map point along the ray, in disparity (inverse depth). To first
// order it is Kim et al.'s depth residual z_stereo - z_cam weighted by sigma_z = z^2 sigma_d /
// (f b) (docs/depth-prior.md), without its blow-up at long range. Its Jacobian includes the
// disparity image's gradient at the projection (bilinear), as Kim et al.'s does.
//
// Depth edges: a map point whose pixel's disparity neighbourhood is not one surface is not used
// (interpolation across an edge gives a disparity of neither surface and a huge gradient).
//
// Depth edges: a map point whose pixel's disparity neighbourhood is not one surface is not used
// (interpolation across an edge gives a disparity of neither surface and a huge gradient).
//
// Occlusion: a map point hidden by nearer map points (a z-buffer of splats) or lying behind
// the stereo surface by more than max(occlusion_margin, 3 sigma_z) is not evidence: the camera
// sees something in front of it that the map does not have (a parked car, a new wall).
#pragma once

#include <ceres/jet.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "planeloc/features/dense_stereo.h"
#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/rigid3.h"
#include "planeloc/optim/cost_functions.h"
#include "planeloc/optim/pose_optimizer.h"
#include "planeloc/prior/depth_prior_options.h"
#include "planeloc/prior/map_cloud_index.h"

namespace planeloc {

// Why each candidate map point was or was not used in a frame.
struct DepthSelectionStats {
  int candidates = 0;     // within max_range of the camera
  int in_view = 0;        // projected into the image at a depth in [min_depth, max_range]
  int hidden_by_map = 0;  // behind nearer map points (z-buffer)
  int no_disparity = 0;   // the stereo has no disparity at its pixel
  int on_edge = 0;        // its pixel is on a depth edge of the stereo (edge_tolerance)
  int occluded = 0;       // behind the stereo surface
  int used = 0;           // after the per-cell sampling
};

// The map points whose depth residual the frame uses at `cam_from_world`.
std::vector<Eigen::Vector3d> SelectDepthPoints(const MapCloudIndex& map, const StereoCamera& camera,
                                               const Rigid3d& cam_from_world,
                                               const DenseDisparity& disparity,
                                               const DepthPriorOptions& options,
                                               DepthSelectionStats* stats = nullptr);

// One map point's disparity residual; blocks q[4] (cam_from_world rotation, x y z w) and t[3].
// A projection without disparity at its pixel (or behind the camera) contributes 0: the point
// was selected where the stereo had one, and a pose step that leaves it is judged by the rest.
class DisparityToMapError {
 public:
  // `disparity` must outlive the functor.
  DisparityToMapError(const DenseDisparity& disparity, const PinholeStereoIntrinsics& k,
                      const Eigen::Vector3d& point_in_world, double sigma_px)
      : disparity_(&disparity), k_(k), point_in_world_(point_in_world), inv_sigma_(1 / sigma_px) {}

  template <typename T>
  bool operator()(const T* const q, const T* const t, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> rotation(q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> translation(t);
    const Eigen::Matrix<T, 3, 1> p = rotation * point_in_world_.cast<T>() + translation;
    residual[0] = T(0);
    if (Scalar(p.z()) < kMinDepth) return true;
    const T u = T(k_.fx) * p.x() / p.z() + T(k_.cx);
    const T v = T(k_.fy) * p.y() / p.z() + T(k_.cy);
    T stereo;
    if (!Sample(u, v, stereo)) return true;
    residual[0] = (stereo - T(k_.bf) / p.z()) * T(inv_sigma_);
    return true;
  }

  static ceres::CostFunction* Create(const DenseDisparity& disparity,
                                     const PinholeStereoIntrinsics& k,
                                     const Eigen::Vector3d& point_in_world, double sigma_px);

 private:
  static double Scalar(double x) { return x; }
  template <typename J, int N>
  static double Scalar(const ceres::Jet<J, N>& x) {
    return x.a;
  }

  // Bilinear disparity at a level-0 pixel, differentiable in (u, v) within a cell; false when a
  // corner of the cell has none.
  template <typename T>
  bool Sample(const T& u, const T& v, T& value) const {
    const int s = disparity_->downsample;
    const T x = (u + 0.5) / double(s) - 0.5;
    const T y = (v + 0.5) / double(s) - 0.5;
    const double xs = Scalar(x), ys = Scalar(y);
    if (!(xs >= 0) || !(ys >= 0)) return false;
    const int x0 = static_cast<int>(std::floor(xs)), y0 = static_cast<int>(std::floor(ys));
    const cv::Mat& d = disparity_->disparity;
    if (x0 + 1 >= d.cols || y0 + 1 >= d.rows) return false;
    const float* row0 = d.ptr<float>(y0);
    const float* row1 = d.ptr<float>(y0 + 1);
    const double d00 = row0[x0], d01 = row0[x0 + 1], d10 = row1[x0], d11 = row1[x0 + 1];
    if (d00 <= 0 || d01 <= 0 || d10 <= 0 || d11 <= 0) return false;
    const T fx = x - double(x0), fy = y - double(y0);
    value = (1.0 - fy) * ((1.0 - fx) * d00 + fx * d01) + fy * ((1.0 - fx) * d10 + fx * d11);
    return true;
  }

  const DenseDisparity* disparity_;
  PinholeStereoIntrinsics k_;
  Eigen::Vector3d point_in_world_;
  double inv_sigma_;
};

struct DepthRefinement {
  Rigid3d cam_from_world;
  DepthSelectionStats selection;  // at the pose the refinement started from
  bool applied = false;           // false: too few map points, the pose is the initial one
  bool refused = false;  // the refinement moved the pose beyond options.max_correction(_deg)
  double median_abs_residual_px = 0;  // of the used points at the refined pose, level-0 px
};

// The frame's pose from its ORB inliers (`visual`: the tracker's last pose-only problem, outliers
// already removed) together with the depth residuals of the map points in view: two rounds, the
// map points selected again at the first round's pose.
DepthRefinement RefinePoseWithMapDepth(const StereoCamera& camera,
                                       const Rigid3d& cam_from_world_initial,
                                       const std::vector<PoseObservation>& visual,
                                       const MapCloudIndex& map, const DenseDisparity& disparity,
                                       const DepthPriorOptions& options);

}  // namespace planeloc
