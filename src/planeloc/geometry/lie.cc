#include "planeloc/geometry/lie.h"

#include <algorithm>
#include <cmath>

namespace planeloc {
namespace {
constexpr double kSmallAngle = 1e-8;
}  // namespace

Eigen::Matrix3d Hat(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

Eigen::Matrix3d ExpSO3(const Eigen::Vector3d& omega) {
  const double theta = omega.norm();
  const Eigen::Matrix3d k = Hat(omega);
  if (theta < kSmallAngle) return Eigen::Matrix3d::Identity() + k + 0.5 * k * k;
  return Eigen::Matrix3d::Identity() + std::sin(theta) / theta * k +
         (1.0 - std::cos(theta)) / (theta * theta) * k * k;
}

Eigen::Vector3d LogSO3(const Eigen::Matrix3d& rotation) {
  // The quaternion route is stable for all angles including those near pi.
  Eigen::Quaterniond q(rotation);
  q.normalize();
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  const double sin_half = q.vec().norm();
  if (sin_half < kSmallAngle) return 2.0 * q.vec() / q.w();
  const double theta = 2.0 * std::atan2(sin_half, q.w());
  return theta / sin_half * q.vec();
}

Eigen::Matrix3d LeftJacobianSO3(const Eigen::Vector3d& omega) {
  const double theta = omega.norm();
  const Eigen::Matrix3d k = Hat(omega);
  if (theta < kSmallAngle) return Eigen::Matrix3d::Identity() + 0.5 * k + k * k / 6.0;
  const double t2 = theta * theta;
  return Eigen::Matrix3d::Identity() + (1.0 - std::cos(theta)) / t2 * k +
         (theta - std::sin(theta)) / (t2 * theta) * k * k;
}

Eigen::Matrix3d InverseLeftJacobianSO3(const Eigen::Vector3d& omega) {
  const double theta = omega.norm();
  const Eigen::Matrix3d k = Hat(omega);
  if (theta < kSmallAngle) return Eigen::Matrix3d::Identity() - 0.5 * k + k * k / 12.0;
  const double t2 = theta * theta;
  const double coefficient = 1.0 / t2 - (1.0 + std::cos(theta)) / (2.0 * theta * std::sin(theta));
  return Eigen::Matrix3d::Identity() - 0.5 * k + coefficient * k * k;
}

Rigid3d ExpSE3(const Vector6d& xi) {
  const Eigen::Vector3d rho = xi.head<3>();
  const Eigen::Vector3d omega = xi.tail<3>();
  return Rigid3d(ExpSO3(omega), LeftJacobianSO3(omega) * rho);
}

Vector6d LogSE3(const Rigid3d& transform) {
  const Eigen::Vector3d omega = LogSO3(transform.RotationMatrix());
  Vector6d xi;
  xi.head<3>() = InverseLeftJacobianSO3(omega) * transform.translation;
  xi.tail<3>() = omega;
  return xi;
}

}  // namespace planeloc
