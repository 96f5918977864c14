// The vehicle's axes at a camera, in which the registration and the lock name their DoF.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace planeloc {

// A unit vector perpendicular to the unit vector n.
inline Eigen::Vector3d AnyPerpendicular(const Eigen::Vector3d& n) {
  const Eigen::Vector3d seed =
      std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  return n.cross(seed).normalized();
}

// Named axes at a camera: along-track (horizontal forward), lateral (left), vertical (up).
struct VehicleAxes {
  Eigen::Vector3d along, lateral, up;
};

// The axes at a camera looking along `forward` with `up` (any along-track when it looks straight
// up or down).
inline VehicleAxes AxesAt(const Eigen::Vector3d& forward, const Eigen::Vector3d& up) {
  VehicleAxes axes;
  axes.up = up.normalized();
  Eigen::Vector3d along = forward - forward.dot(axes.up) * axes.up;
  if (along.norm() < 1e-6) along = AnyPerpendicular(axes.up);
  axes.along = along.normalized();
  axes.lateral = axes.up.cross(axes.along);
  return axes;
}

}  // namespace planeloc
