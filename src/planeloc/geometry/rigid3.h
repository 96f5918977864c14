// Rigid transforms and the frame-naming convention used everywhere in planeloc.
//
// A transform is named `<to>_from_<from>`: `cam_from_world` maps a point expressed in the world
// frame into the camera frame, x_cam = R * x_world + t. Composition reads right to left:
//   cam_from_map = cam_from_world * world_from_map.
// A camera *pose* as stored in KITTI/TUM files is `world_from_cam` (camera centre = translation).
// KITTI camera frames: x right, y down, z forward.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace planeloc {

struct Rigid3d {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();  // unit quaternion
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Rigid3d() = default;
  Rigid3d(const Eigen::Quaterniond& r, const Eigen::Vector3d& t)
      : rotation(r.normalized()), translation(t) {}
  Rigid3d(const Eigen::Matrix3d& r, const Eigen::Vector3d& t)
      : rotation(Eigen::Quaterniond(r).normalized()), translation(t) {}

  static Rigid3d Identity() { return Rigid3d(); }
  // From the top 3x4 of a homogeneous matrix (e.g. one KITTI pose line). The rotation block is
  // re-orthonormalized through the quaternion.
  static Rigid3d FromMatrix3x4(const Eigen::Matrix<double, 3, 4>& m);
  static Rigid3d FromMatrix4d(const Eigen::Matrix4d& m);

  Eigen::Matrix3d RotationMatrix() const { return rotation.toRotationMatrix(); }
  Eigen::Matrix<double, 3, 4> Matrix3x4() const;
  Eigen::Matrix4d Matrix4d() const;

  Rigid3d Inverse() const;
  Eigen::Vector3d operator*(const Eigen::Vector3d& point) const {
    return rotation * point + translation;
  }
  Rigid3d operator*(const Rigid3d& other) const {
    return Rigid3d(rotation * other.rotation, rotation * other.translation + translation);
  }
};

// Angle of the relative rotation between a and b, radians in [0, pi].
double RotationAngle(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b);

}  // namespace planeloc
