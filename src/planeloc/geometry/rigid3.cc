#include "planeloc/geometry/rigid3.h"

#include <algorithm>
#include <cmath>

namespace planeloc {

Rigid3d Rigid3d::FromMatrix3x4(const Eigen::Matrix<double, 3, 4>& m) {
  return Rigid3d(Eigen::Matrix3d(m.leftCols<3>()), Eigen::Vector3d(m.col(3)));
}

Rigid3d Rigid3d::FromMatrix4d(const Eigen::Matrix4d& m) { return FromMatrix3x4(m.topRows<3>()); }

Eigen::Matrix<double, 3, 4> Rigid3d::Matrix3x4() const {
  Eigen::Matrix<double, 3, 4> m;
  m.leftCols<3>() = RotationMatrix();
  m.col(3) = translation;
  return m;
}

Eigen::Matrix4d Rigid3d::Matrix4d() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topRows<3>() = Matrix3x4();
  return m;
}

Rigid3d Rigid3d::Inverse() const {
  const Eigen::Quaterniond inverse_rotation = rotation.conjugate();
  return Rigid3d(inverse_rotation, -(inverse_rotation * translation));
}

double RotationAngle(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  const double w = std::abs((a.conjugate() * b).normalized().w());
  return 2.0 * std::acos(std::clamp(w, 0.0, 1.0));
}

}  // namespace planeloc
