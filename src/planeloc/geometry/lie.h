// SO(3) and SE(3) exponential and logarithm maps.
//
// Tangent vectors: so(3) as a rotation vector omega (axis * angle, radians); se(3) as
// xi = [rho; omega] (translation part first, as in Sophus/basalt), with
//   exp(xi) = [ exp(omega), V(omega) * rho ; 0, 1 ],  V = left Jacobian of SO(3).
// Both maps are accurate near zero (Taylor branches below 1e-8 rad) and log(exp(x)) = x for
// |omega| < pi.
#pragma once

#include <Eigen/Core>

#include "planeloc/geometry/rigid3.h"

namespace planeloc {

using Vector6d = Eigen::Matrix<double, 6, 1>;

Eigen::Matrix3d Hat(const Eigen::Vector3d& v);  // skew-symmetric matrix, Hat(a) * b = a x b

Eigen::Matrix3d ExpSO3(const Eigen::Vector3d& omega);
Eigen::Vector3d LogSO3(const Eigen::Matrix3d& rotation);

Rigid3d ExpSE3(const Vector6d& xi);
Vector6d LogSE3(const Rigid3d& transform);

// Left Jacobian of SO(3) and its inverse.
Eigen::Matrix3d LeftJacobianSO3(const Eigen::Vector3d& omega);
Eigen::Matrix3d InverseLeftJacobianSO3(const Eigen::Vector3d& omega);

}  // namespace planeloc
