// Pose sequences as the evaluator sees them: 4x4 world_from_cam matrices exactly as read.
//
// evo keeps the numbers of a KITTI file as they are (the rotation blocks are only orthonormal to
// ~1e-6, the precision of the file) and inverts a pose with the transpose of its rotation block.
// To reproduce evo's statistics to 1e-6 the evaluator does the same, instead of going through
// Rigid3d (which re-orthonormalizes).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "planeloc/io/trajectory.h"

namespace planeloc {

using PoseMatrices = std::vector<Eigen::Matrix4d>;  // world_from_cam, one per pose

PoseMatrices ToPoseMatrices(const Trajectory& trajectory);
PoseMatrices ToPoseMatrices(const std::vector<Eigen::Matrix<double, 3, 4>>& rows);

// Positions (translation columns) as a 3xN matrix.
Eigen::Matrix3Xd Positions(const PoseMatrices& poses);

// [R t]^-1 computed as [R^T, -R^T t], as evo's lie.se3_inverse.
Eigen::Matrix4d InverseRigid(const Eigen::Matrix4d& pose);
// a^-1 * b with InverseRigid, as evo's lie.relative_se3.
Eigen::Matrix4d RelativePose(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b);

// Rotation angle of the rotation block, radians in [0, pi] (via a normalized quaternion).
double RotationAngleOf(const Eigen::Matrix3d& rotation);

// The plane that `--plane` keeps. KITTI camera frames (y down) have the ground in x-z.
enum class ProjectionPlane { kNone, kXy, kXz, kYz };
// "xy" | "xz" | "yz" | "" (none); throws InputError otherwise.
ProjectionPlane ParseProjectionPlane(const std::string& name);
std::string ToString(ProjectionPlane plane);

// evo's PosePath3D.project: the dropped coordinate of every position is set to 0 and every
// rotation is replaced by the rotation about the plane normal by the matching 'sxyz' Euler angle.
void ProjectToPlane(ProjectionPlane plane, PoseMatrices* poses);

// Cumulative path length at each pose (0 at the first), metres.
std::vector<double> AccumulatedDistances(const PoseMatrices& poses);

}  // namespace planeloc
