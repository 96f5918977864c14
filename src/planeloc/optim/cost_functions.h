// Ceres residuals of planeloc's optimization problems.
//
// Parameterization (all functors): a pose cam_from_world is two parameter blocks,
//   q = [qx, qy, qz, qw]  (Eigen's storage order; use ceres::EigenQuaternionManifold)
//   t = [tx, ty, tz]      (metres)
// so that x_cam = R(q) * x_world + t (geometry/rigid3.h). A point is one block point_in_world [3].
//
// Reprojection (camera/stereo model in geometry/camera.h): with p = R(q) X + t = (px, py, pz),
//   u_L = fx px / pz + cx,   v = fy py / pz + cy,   u_R = u_L - bf / pz     (bf = fx * baseline)
// and the residual is the measurement minus the projection, whitened by the square root of the
// (isotropic) information 1 / sigma^2 of the keypoint's pyramid level:
//   r = sqrt(info) * ([u_L, v, u_R]_observed - [u_L, v, u_R](p))          (stereo, 3 rows)
//   r = sqrt(info) * ([u_L, v]_observed - [u_L, v](p))                     (mono, 2 rows)
// so |r|^2 is chi-square distributed with 3 (2) DoF for inliers, which is what the chi2
// thresholds and the Huber delta = sqrt(chi2) of ORB-SLAM2 are expressed in.
// Points at or behind the camera (pz <= kMinDepth) make the functor return false: Ceres then
// rejects the step that moved them there; callers must drop such observations before solving.
//
// Point-to-plane (the paper's E_point-to-plane): for a fixed plane n . x + d = 0 (|n| = 1),
//   r = (n . X + d) / sigma_plane                                           (1 row, metres/metres)
// A plane of the map has its own error (registration, blur), the same for every point on it. As a
// random effect, a window estimates a correction c = (offset, tilt_u, tilt_v) per plane, with the
// prior c ~ N(0, diag(sigma_offset^2, sigma_tilt^2, sigma_tilt^2)): the corrected plane pivots
// about an anchor a on the map plane (its centroid), n' = (n + tilt_u u + tilt_v v) / |.| with
// (u, v, n) orthonormal, and
//   r = (n' . (X - a) + offset) / sigma_point                               (1 row)
//   r_prior = (offset / sigma_offset, tilt_u / sigma_tilt, tilt_v / sigma_tilt) (3 rows)
// so N points on a plane tie their keyframes to the map once, through the prior, not N times.
// The lambda weighting of the paper's total cost lambda * E_reproj + (1 - lambda) * E_plane is NOT
// inside these functors: callers wrap each residual's loss in ceres::ScaledLoss(lambda) or
// ceres::ScaledLoss(1 - lambda) (see window_ba.cc), so each functor stays a pure whitened residual.
//
// Which one to use:
//   StereoReprojectionError / MonoReprojectionError   templated autodiff functors (reference)
//   StereoReprojectionAnalytic / MonoReprojectionPadded   same residuals, analytic Jacobians
//                                                          (window BA)
//   StereoPoseOnlyError / MonoPoseOnlyError           point fixed, analytic (OptimizePose)
//   PointToPlaneError                                  templated autodiff functor
//   PointToPlanePadded                                 same, analytic, 3 rows (window BA)
//   PointToCorrectedPlaneError, PlaneCorrectionPrior   the plane's map error as a nuisance
//   PointToCorrectedPlanePadded                        same, 3 rows (window BA)
// Derivations and design notes: docs/optim.md.
#pragma once

#include <ceres/autodiff_cost_function.h>
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/plane.h"

namespace planeloc {

// Points closer than this (metres, along the optical axis) are treated as invalid projections.
inline constexpr double kMinDepth = 1e-3;

// Intrinsics copied into the functors (value type, so functors own no references).
struct PinholeStereoIntrinsics {
  double fx = 0, fy = 0, cx = 0, cy = 0, bf = 0;
  static PinholeStereoIntrinsics From(const StereoCamera& camera) {
    return {camera.fx, camera.fy, camera.cx, camera.cy, camera.BaselineTimesFx()};
  }
};

// Stereo reprojection error of a point in a pose; parameter blocks q[4], t[3], X[3]; 3 residuals.
class StereoReprojectionError {
 public:
  StereoReprojectionError(const PinholeStereoIntrinsics& k, const Eigen::Vector3d& observed,
                          double sqrt_information)
      : k_(k), observed_(observed), sqrt_information_(sqrt_information) {}

  template <typename T>
  bool operator()(const T* const q, const T* const t, const T* const point, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> rotation(q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> translation(t);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> point_in_world(point);
    const Eigen::Matrix<T, 3, 1> p = rotation * point_in_world + translation;
    if (p[2] <= T(kMinDepth)) return false;
    const T inv_z = T(1) / p[2];
    const T u_left = T(k_.fx) * p[0] * inv_z + T(k_.cx);
    residual[0] = T(sqrt_information_) * (T(observed_[0]) - u_left);
    residual[1] = T(sqrt_information_) * (T(observed_[1]) - (T(k_.fy) * p[1] * inv_z + T(k_.cy)));
    residual[2] = T(sqrt_information_) * (T(observed_[2]) - (u_left - T(k_.bf) * inv_z));
    return true;
  }

  // `observed` = (u_L, v, u_R) in pixels; information = 1 / sigma^2 (1/px^2).
  static ceres::CostFunction* Create(const PinholeStereoIntrinsics& k,
                                     const Eigen::Vector3d& observed, double information) {
    return new ceres::AutoDiffCostFunction<StereoReprojectionError, 3, 4, 3, 3>(
        new StereoReprojectionError(k, observed, std::sqrt(information)));
  }

 private:
  const PinholeStereoIntrinsics k_;
  const Eigen::Vector3d observed_;
  const double sqrt_information_;
};

// Monocular reprojection error (left image only); blocks q[4], t[3], X[3]; 2 residuals.
class MonoReprojectionError {
 public:
  MonoReprojectionError(const PinholeStereoIntrinsics& k, const Eigen::Vector2d& observed,
                        double sqrt_information)
      : k_(k), observed_(observed), sqrt_information_(sqrt_information) {}

  template <typename T>
  bool operator()(const T* const q, const T* const t, const T* const point, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> rotation(q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> translation(t);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> point_in_world(point);
    const Eigen::Matrix<T, 3, 1> p = rotation * point_in_world + translation;
    if (p[2] <= T(kMinDepth)) return false;
    const T inv_z = T(1) / p[2];
    residual[0] = T(sqrt_information_) * (T(observed_[0]) - (T(k_.fx) * p[0] * inv_z + T(k_.cx)));
    residual[1] = T(sqrt_information_) * (T(observed_[1]) - (T(k_.fy) * p[1] * inv_z + T(k_.cy)));
    return true;
  }

  static ceres::CostFunction* Create(const PinholeStereoIntrinsics& k,
                                     const Eigen::Vector2d& observed, double information) {
    return new ceres::AutoDiffCostFunction<MonoReprojectionError, 2, 4, 3, 3>(
        new MonoReprojectionError(k, observed, std::sqrt(information)));
  }

 private:
  const PinholeStereoIntrinsics k_;
  const Eigen::Vector2d observed_;
  const double sqrt_information_;
};

// Analytic versions of the reprojection errors (the autodiff functors above are the reference
// they are tested against; these are 5-8x faster to evaluate, see docs/bench-optim.md).
// Jacobians, with p = R(q) X + t, q = (v, w), v = (qx, qy, qz):
//   d proj / d p = [fx/pz, 0, -fx px/pz^2; 0, fy/pz, -fy py/pz^2; fx/pz, 0, -(fx px - bf)/pz^2]
//   d p / d t = I,   d p / d X = R(q)
//   d p / d w = 2 v x X
//   d p / d v = -2 w [X]x + 2 ((v . X) I + v X^T - 2 X v^T)
// The last two differentiate Eigen's q * X = X + 2 w (v x X) + 2 v x (v x X), which is the
// ambient function Ceres sees (EigenQuaternionManifold's PlusJacobian maps them to the tangent
// space), so they agree with autodiff of StereoReprojectionError exactly.
namespace internal {

// Whitened residual (kMeasured rows: u_L, v[, u_R]) of a point p in the camera frame, and
// d r / d p when dr_dp is not null. False when p is not in front of the camera.
template <int kMeasured>
bool ReprojectionResidual(const PinholeStereoIntrinsics& k,
                          const Eigen::Matrix<double, kMeasured, 1>& observed,
                          double sqrt_information, const Eigen::Vector3d& p, double* residuals,
                          Eigen::Matrix<double, kMeasured, 3>* dr_dp) {
  static_assert(kMeasured == 2 || kMeasured == 3);
  if (p.z() <= kMinDepth) return false;
  const double inv_z = 1.0 / p.z();
  const double u_left = k.fx * p.x() * inv_z + k.cx;
  residuals[0] = sqrt_information * (observed[0] - u_left);
  residuals[1] = sqrt_information * (observed[1] - (k.fy * p.y() * inv_z + k.cy));
  if constexpr (kMeasured == 3) {
    residuals[2] = sqrt_information * (observed[2] - (u_left - k.bf * inv_z));
  }
  if (dr_dp == nullptr) return true;
  const double inv_z2 = inv_z * inv_z;
  const double s = -sqrt_information;  // r = sqrt_info * (observed - proj)
  dr_dp->row(0) << s * k.fx * inv_z, 0.0, -s * k.fx * p.x() * inv_z2;
  dr_dp->row(1) << 0.0, s * k.fy * inv_z, -s * k.fy * p.y() * inv_z2;
  if constexpr (kMeasured == 3) {
    dr_dp->row(2) << s * k.fx * inv_z, 0.0, -s * (k.fx * p.x() - k.bf) * inv_z2;
  }
  return true;
}

// d (q * X) / d q in Eigen's ambient quaternion coordinates (x, y, z, w).
inline Eigen::Matrix<double, 3, 4> RotatedPointJacobian(const Eigen::Quaterniond& q,
                                                        const Eigen::Vector3d& x) {
  const Eigen::Vector3d v = q.vec();
  const double w = q.w();
  Eigen::Matrix3d x_hat;
  x_hat << 0.0, -x.z(), x.y(), x.z(), 0.0, -x.x(), -x.y(), x.x(), 0.0;
  Eigen::Matrix<double, 3, 4> dp_dq;
  dp_dq.leftCols<3>() = -2.0 * w * x_hat + 2.0 * (v.dot(x) * Eigen::Matrix3d::Identity() +
                                                  v * x.transpose() - 2.0 * x * v.transpose());
  dp_dq.col(3) = 2.0 * v.cross(x);
  return dp_dq;
}

// Copies the top kMeasured rows of `m` into a row-major kRows x N Ceres Jacobian, zero-padding.
template <int kRows, int kMeasured, int kCols>
void WriteJacobian(const Eigen::Matrix<double, kMeasured, kCols>& m, double* out) {
  Eigen::Map<Eigen::Matrix<double, kRows, kCols, Eigen::RowMajor>> j(out);
  j.template topRows<kMeasured>() = m;
  if constexpr (kRows > kMeasured) j.template bottomRows<kRows - kMeasured>().setZero();
}

}  // namespace internal

// Reprojection error of a free point in a free pose; blocks q[4], t[3], X[3]. kMeasured = 3
// (stereo) or 2 (mono). kRows >= kMeasured residual rows, the extra ones identically zero: a
// window with both stereo and mono observations then has one row size, which lets Ceres use its
// compiled <3, 3, 3> Schur eliminator instead of the generic dynamic one (~2x faster solve).
template <int kMeasured, int kRows = kMeasured>
class AnalyticReprojectionError : public ceres::SizedCostFunction<kRows, 4, 3, 3> {
  static_assert(kRows >= kMeasured);

 public:
  AnalyticReprojectionError(const PinholeStereoIntrinsics& k,
                            const Eigen::Matrix<double, kMeasured, 1>& observed, double information)
      : k_(k), observed_(observed), sqrt_information_(std::sqrt(information)) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Map<const Eigen::Quaterniond> rotation(parameters[0]);
    const Eigen::Map<const Eigen::Vector3d> translation(parameters[1]);
    const Eigen::Map<const Eigen::Vector3d> x(parameters[2]);
    const Eigen::Vector3d p = rotation * x + translation;
    Eigen::Matrix<double, kMeasured, 3> dr_dp;
    if (!internal::ReprojectionResidual<kMeasured>(k_, observed_, sqrt_information_, p, residuals,
                                                   jacobians != nullptr ? &dr_dp : nullptr)) {
      return false;
    }
    for (int i = kMeasured; i < kRows; ++i) residuals[i] = 0.0;
    if (jacobians == nullptr) return true;
    if (jacobians[0] != nullptr) {
      const Eigen::Matrix<double, kMeasured, 4> dr_dq =
          dr_dp * internal::RotatedPointJacobian(rotation, x);
      internal::WriteJacobian<kRows>(dr_dq, jacobians[0]);
    }
    if (jacobians[1] != nullptr) internal::WriteJacobian<kRows>(dr_dp, jacobians[1]);
    if (jacobians[2] != nullptr) {
      const Eigen::Matrix<double, kMeasured, 3> dr_dx = dr_dp * rotation.toRotationMatrix();
      internal::WriteJacobian<kRows>(dr_dx, jacobians[2]);
    }
    return true;
  }

 private:
  const PinholeStereoIntrinsics k_;
  const Eigen::Matrix<double, kMeasured, 1> observed_;
  const double sqrt_information_;
};

using StereoReprojectionAnalytic = AnalyticReprojectionError<3>;
using MonoReprojectionAnalytic = AnalyticReprojectionError<2>;
using MonoReprojectionPadded = AnalyticReprojectionError<2, 3>;  // third row always 0

// Pose-only reprojection error with the point fixed (motion-only BA), analytic Jacobians.
// kResiduals = 3 (stereo) or 2 (mono); blocks q[4], t[3].
template <int kResiduals>
class PoseOnlyReprojectionError : public ceres::SizedCostFunction<kResiduals, 4, 3> {
 public:
  // `observed` holds (u_L, v[, u_R]) in pixels.
  PoseOnlyReprojectionError(const PinholeStereoIntrinsics& k,
                            const Eigen::Matrix<double, kResiduals, 1>& observed,
                            const Eigen::Vector3d& point_in_world, double information)
      : k_(k),
        observed_(observed),
        point_in_world_(point_in_world),
        sqrt_information_(std::sqrt(information)) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Map<const Eigen::Quaterniond> rotation(parameters[0]);
    const Eigen::Map<const Eigen::Vector3d> translation(parameters[1]);
    const Eigen::Vector3d p = rotation * point_in_world_ + translation;
    Eigen::Matrix<double, kResiduals, 3> dr_dp;
    if (!internal::ReprojectionResidual<kResiduals>(k_, observed_, sqrt_information_, p, residuals,
                                                    jacobians != nullptr ? &dr_dp : nullptr)) {
      return false;
    }
    if (jacobians == nullptr) return true;
    if (jacobians[0] != nullptr) {
      const Eigen::Matrix<double, kResiduals, 4> dr_dq =
          dr_dp * internal::RotatedPointJacobian(rotation, point_in_world_);
      internal::WriteJacobian<kResiduals>(dr_dq, jacobians[0]);
    }
    if (jacobians[1] != nullptr) internal::WriteJacobian<kResiduals>(dr_dp, jacobians[1]);
    return true;
  }

  const Eigen::Vector3d& point_in_world() const { return point_in_world_; }

 private:
  const PinholeStereoIntrinsics k_;
  const Eigen::Matrix<double, kResiduals, 1> observed_;
  const Eigen::Vector3d point_in_world_;
  const double sqrt_information_;
};

using StereoPoseOnlyError = PoseOnlyReprojectionError<3>;
using MonoPoseOnlyError = PoseOnlyReprojectionError<2>;

// Point-to-plane distance of a free point to a fixed plane; block X[3]; 1 residual.
class PointToPlaneError {
 public:
  PointToPlaneError(const Plane& plane, double sigma)
      : normal_(plane.normal), d_(plane.d), inv_sigma_(1.0 / sigma) {}

  template <typename T>
  bool operator()(const T* const point, T* residual) const {
    residual[0] = T(inv_sigma_) * (T(normal_[0]) * point[0] + T(normal_[1]) * point[1] +
                                   T(normal_[2]) * point[2] + T(d_));
    return true;
  }

  // sigma in metres (> 0): the standard deviation of the point-to-plane distance.
  static ceres::CostFunction* Create(const Plane& plane, double sigma) {
    return new ceres::AutoDiffCostFunction<PointToPlaneError, 1, 3>(
        new PointToPlaneError(plane, sigma));
  }

 private:
  const Eigen::Vector3d normal_;
  const double d_;
  const double inv_sigma_;
};

// PointToPlaneError with analytic Jacobian and two identically zero rows, for the window BA: with
// the (padded) reprojection rows it gives the window a single row size of 3, so Ceres runs its
// compiled <3, 3, 3> Schur eliminator instead of the dynamic one. Same cost and gradient.
class PointToPlanePadded : public ceres::SizedCostFunction<3, 3> {
 public:
  // sigma in metres (> 0), as PointToPlaneError.
  PointToPlanePadded(const Plane& plane, double sigma)
      : normal_(plane.normal), d_(plane.d), inv_sigma_(1.0 / sigma) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Map<const Eigen::Vector3d> x(parameters[0]);
    residuals[0] = inv_sigma_ * (normal_.dot(x) + d_);
    residuals[1] = residuals[2] = 0.0;
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> j(jacobians[0]);
      j.setZero();
      j.row(0) = inv_sigma_ * normal_.transpose();
    }
    return true;
  }

 private:
  const Eigen::Vector3d normal_;
  const double d_;
  const double inv_sigma_;
};

// The point-to-plane residual against a map plane corrected by c (see the file comment).
class PointToCorrectedPlaneError {
 public:
  // sigma in metres (> 0): the point's own uncertainty along the normal (not the map's).
  PointToCorrectedPlaneError(const Plane& plane, const Eigen::Vector3d& anchor, double sigma)
      : normal_(plane.normal), inv_sigma_(1.0 / sigma) {
    // The anchor projected onto the plane, so that c = 0 is exactly the map plane.
    anchor_ = anchor - plane.SignedDistance(anchor) * plane.normal;
    const Eigen::Vector3d seed =
        std::abs(normal_.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    u_ = normal_.cross(seed).normalized();
    v_ = normal_.cross(u_);
  }

  template <typename T>
  bool operator()(const T* const point, const T* const correction, T* residual) const {
    T n[3], offset[3];
    T norm2 = T(0);
    for (int i = 0; i < 3; ++i) {
      n[i] = T(normal_[i]) + correction[1] * T(u_[i]) + correction[2] * T(v_[i]);
      offset[i] = point[i] - T(anchor_[i]);
      norm2 += n[i] * n[i];
    }
    const T distance = (n[0] * offset[0] + n[1] * offset[1] + n[2] * offset[2]) / sqrt(norm2);
    residual[0] = T(inv_sigma_) * (distance + correction[0]);
    return true;
  }

  static ceres::CostFunction* Create(const Plane& plane, const Eigen::Vector3d& anchor,
                                     double sigma) {
    return new ceres::AutoDiffCostFunction<PointToCorrectedPlaneError, 1, 3, 3>(
        new PointToCorrectedPlaneError(plane, anchor, sigma));
  }
  const Eigen::Vector3d& anchor() const { return anchor_; }

 private:
  Eigen::Vector3d normal_, anchor_, u_, v_;
  double inv_sigma_;
};

// PointToCorrectedPlaneError with two identically zero rows, for the window BA (see
// PointToPlanePadded); blocks X[3], c[3]. Same cost and gradient.
class PointToCorrectedPlanePadded {
 public:
  explicit PointToCorrectedPlanePadded(const PointToCorrectedPlaneError& error) : error_(error) {}

  template <typename T>
  bool operator()(const T* const point, const T* const correction, T* residual) const {
    residual[1] = residual[2] = T(0);
    return error_(point, correction, residual);
  }

  static ceres::CostFunction* Create(const Plane& plane, const Eigen::Vector3d& anchor,
                                     double sigma) {
    return new ceres::AutoDiffCostFunction<PointToCorrectedPlanePadded, 3, 3, 3>(
        new PointToCorrectedPlanePadded(PointToCorrectedPlaneError(plane, anchor, sigma)));
  }

 private:
  const PointToCorrectedPlaneError error_;
};

// The prior of a plane correction c = (offset, tilt_u, tilt_v): c whitened by its sigmas.
// sigma_tilt = 0 writes 0 for the tilt rows (the caller then holds the tilt at 0).
class PlaneCorrectionPrior {
 public:
  PlaneCorrectionPrior(double sigma_offset, double sigma_tilt)
      : inv_offset_(1.0 / sigma_offset), inv_tilt_(sigma_tilt > 0 ? 1.0 / sigma_tilt : 0.0) {}

  template <typename T>
  bool operator()(const T* const correction, T* residual) const {
    residual[0] = T(inv_offset_) * correction[0];
    residual[1] = T(inv_tilt_) * correction[1];
    residual[2] = T(inv_tilt_) * correction[2];
    return true;
  }

  // sigma_offset metres (> 0), sigma_tilt radians (>= 0).
  static ceres::CostFunction* Create(double sigma_offset, double sigma_tilt) {
    return new ceres::AutoDiffCostFunction<PlaneCorrectionPrior, 3, 3>(
        new PlaneCorrectionPrior(sigma_offset, sigma_tilt));
  }

 private:
  double inv_offset_, inv_tilt_;
};

}  // namespace planeloc
