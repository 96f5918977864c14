#include "planeloc/eval/pose_path.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

// transformations.py euler_from_matrix(M, 'sxyz'): static x-y-z axes.
Eigen::Vector3d EulerSxyz(const Eigen::Matrix3d& m) {
  constexpr double kEps = std::numeric_limits<double>::epsilon() * 4.0;
  const double cy = std::sqrt(m(0, 0) * m(0, 0) + m(1, 0) * m(1, 0));
  if (cy > kEps) {
    return {std::atan2(m(2, 1), m(2, 2)), std::atan2(-m(2, 0), cy), std::atan2(m(1, 0), m(0, 0))};
  }
  return {std::atan2(-m(1, 2), m(1, 1)), std::atan2(-m(2, 0), cy), 0.0};
}

}  // namespace

PoseMatrices ToPoseMatrices(const Trajectory& trajectory) {
  PoseMatrices poses;
  poses.reserve(trajectory.size());
  for (const Rigid3d& pose : trajectory.world_from_cam) poses.push_back(pose.Matrix4d());
  return poses;
}

PoseMatrices ToPoseMatrices(const std::vector<Eigen::Matrix<double, 3, 4>>& rows) {
  PoseMatrices poses;
  poses.reserve(rows.size());
  for (const auto& row : rows) {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.topRows<3>() = row;
    poses.push_back(m);
  }
  return poses;
}

Eigen::Matrix3Xd Positions(const PoseMatrices& poses) {
  Eigen::Matrix3Xd positions(3, poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    positions.col(static_cast<Eigen::Index>(i)) = poses[i].block<3, 1>(0, 3);
  }
  return positions;
}

Eigen::Matrix4d InverseRigid(const Eigen::Matrix4d& pose) {
  Eigen::Matrix4d inverse = Eigen::Matrix4d::Identity();
  const Eigen::Matrix3d rotation_t = pose.topLeftCorner<3, 3>().transpose();
  inverse.topLeftCorner<3, 3>() = rotation_t;
  inverse.block<3, 1>(0, 3) = -rotation_t * pose.block<3, 1>(0, 3);
  return inverse;
}

Eigen::Matrix4d RelativePose(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b) {
  return InverseRigid(a) * b;
}

double RotationAngleOf(const Eigen::Matrix3d& rotation) {
  const Eigen::Quaterniond q = Eigen::Quaterniond(rotation).normalized();
  return 2.0 * std::atan2(q.vec().norm(), std::abs(q.w()));
}

ProjectionPlane ParseProjectionPlane(const std::string& name) {
  if (name.empty()) return ProjectionPlane::kNone;
  if (name == "xy") return ProjectionPlane::kXy;
  if (name == "xz") return ProjectionPlane::kXz;
  if (name == "yz") return ProjectionPlane::kYz;
  throw InputError("", fmt::format("unknown projection plane '{}'", name),
                   "use xz (KITTI ground plane), xy or yz");
}

std::string ToString(ProjectionPlane plane) {
  switch (plane) {
    case ProjectionPlane::kXy:
      return "xy";
    case ProjectionPlane::kXz:
      return "xz";
    case ProjectionPlane::kYz:
      return "yz";
    case ProjectionPlane::kNone:
      break;
  }
  return "none";
}

void ProjectToPlane(ProjectionPlane plane, PoseMatrices* poses) {
  if (plane == ProjectionPlane::kNone) return;
  const int null_dim = plane == ProjectionPlane::kXy ? 2 : plane == ProjectionPlane::kXz ? 1 : 0;
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();
  axis[null_dim] = 1.0;
  for (Eigen::Matrix4d& pose : *poses) {
    pose(null_dim, 3) = 0.0;
    const double angle = EulerSxyz(pose.topLeftCorner<3, 3>())[null_dim];
    pose.topLeftCorner<3, 3>() = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
  }
}

std::vector<double> AccumulatedDistances(const PoseMatrices& poses) {
  std::vector<double> distances(poses.size(), 0.0);
  for (std::size_t i = 1; i < poses.size(); ++i) {
    distances[i] =
        distances[i - 1] + (poses[i].block<3, 1>(0, 3) - poses[i - 1].block<3, 1>(0, 3)).norm();
  }
  return distances;
}

}  // namespace planeloc
