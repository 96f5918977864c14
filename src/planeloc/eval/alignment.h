// Umeyama alignment of an estimated trajectory to a reference, as evo does it
// (evo/core/geometry.py umeyama_alignment, PosePath3D.align): least squares on the positions only,
// rotation by SVD with the Kabsch sign fix, Sim(3) scale from eq. 42 of Umeyama (1991).
#pragma once

#include <Eigen/Core>
#include <string>

#include "planeloc/eval/pose_path.h"

namespace planeloc {

enum class AlignmentType { kNone, kSe3, kSim3 };
// "none" | "se3" | "sim3"; throws InputError otherwise.
AlignmentType ParseAlignmentType(const std::string& name);
std::string ToString(AlignmentType type);

// The similarity ref_from_est: p_ref ~= scale * rotation * p_est + translation.
struct Sim3Alignment {
  AlignmentType type = AlignmentType::kNone;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  double scale = 1.0;
};

// Finds c, R, t minimizing sum |y_i - (c R x_i + t)|^2 over the columns of the 3xN matrices
// (c = 1 unless `with_scale`). Throws InputError when the points are degenerate (fewer than two
// distinct directions, e.g. all on one line), as evo does.
Sim3Alignment UmeyamaAlignment(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y,
                               bool with_scale);

// Applies the alignment as evo: every translation is scaled first, then the pose is
// left-multiplied by [R t], so world_from_cam -> [R * R_cam, R * (scale * t_cam) + t].
void ApplyAlignment(const Sim3Alignment& alignment, PoseMatrices* poses);

// Aligns `estimate` (same length as `reference`) in place and returns the transform used;
// kNone leaves it untouched and returns the identity.
Sim3Alignment AlignTrajectory(const PoseMatrices& reference, AlignmentType type,
                              PoseMatrices* estimate);

}  // namespace planeloc
