#include "planeloc/eval/alignment.h"

#include <fmt/format.h>

#include <Eigen/SVD>
#include <limits>
#include <stdexcept>

#include "planeloc/util/error.h"

namespace planeloc {

AlignmentType ParseAlignmentType(const std::string& name) {
  if (name == "none") return AlignmentType::kNone;
  if (name == "se3") return AlignmentType::kSe3;
  if (name == "sim3") return AlignmentType::kSim3;
  throw InputError("", fmt::format("unknown alignment '{}'", name), "use none, se3 or sim3");
}

std::string ToString(AlignmentType type) {
  switch (type) {
    case AlignmentType::kSe3:
      return "se3";
    case AlignmentType::kSim3:
      return "sim3";
    case AlignmentType::kNone:
      break;
  }
  return "none";
}

Sim3Alignment UmeyamaAlignment(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y,
                               bool with_scale) {
  if (x.cols() != y.cols()) {
    throw std::invalid_argument("UmeyamaAlignment: point sets of different sizes");
  }
  if (x.cols() < 2) {
    throw InputError("", fmt::format("cannot align {} pose(s)", x.cols()),
                     "alignment needs at least 3 poses that are not on one line; use --align none");
  }
  const double n = static_cast<double>(x.cols());
  const Eigen::Vector3d mean_x = x.rowwise().mean();
  const Eigen::Vector3d mean_y = y.rowwise().mean();
  const Eigen::Matrix3Xd x_centred = x.colwise() - mean_x;
  const Eigen::Matrix3Xd y_centred = y.colwise() - mean_y;
  const double sigma_x = x_centred.squaredNorm() / n;
  const Eigen::Matrix3d covariance = y_centred * x_centred.transpose() / n;

  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d d = svd.singularValues();
  int rank = 0;
  for (int i = 0; i < 3; ++i) rank += d[i] > std::numeric_limits<double>::epsilon() ? 1 : 0;
  if (rank < 2) {
    throw InputError("", "the trajectory is degenerate (a point or a straight line)",
                     "alignment needs poses spanning a plane; use --align none");
  }
  Eigen::Matrix3d s = Eigen::Matrix3d::Identity();
  // Kabsch: keep a proper rotation, never a reflection.
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) s(2, 2) = -1.0;

  Sim3Alignment alignment;
  alignment.type = with_scale ? AlignmentType::kSim3 : AlignmentType::kSe3;
  alignment.rotation = svd.matrixU() * s * svd.matrixV().transpose();
  alignment.scale = with_scale ? (d.asDiagonal() * s).trace() / sigma_x : 1.0;
  alignment.translation = mean_y - alignment.scale * alignment.rotation * mean_x;
  return alignment;
}

void ApplyAlignment(const Sim3Alignment& alignment, PoseMatrices* poses) {
  Eigen::Matrix4d transform = Eigen::Matrix4d::Identity();
  transform.topLeftCorner<3, 3>() = alignment.rotation;
  transform.block<3, 1>(0, 3) = alignment.translation;
  for (Eigen::Matrix4d& pose : *poses) {
    pose.block<3, 1>(0, 3) *= alignment.scale;
    pose = transform * pose;
  }
}

Sim3Alignment AlignTrajectory(const PoseMatrices& reference, AlignmentType type,
                              PoseMatrices* estimate) {
  if (type == AlignmentType::kNone) return Sim3Alignment{};
  if (reference.size() != estimate->size()) {
    throw std::invalid_argument("AlignTrajectory: trajectories of different lengths");
  }
  const Sim3Alignment alignment =
      UmeyamaAlignment(Positions(*estimate), Positions(reference), type == AlignmentType::kSim3);
  ApplyAlignment(alignment, estimate);
  return alignment;
}

}  // namespace planeloc
