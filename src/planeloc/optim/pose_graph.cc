#include "planeloc/optim/pose_graph.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include "planeloc/util/error.h"

namespace planeloc {

void PoseGraphOptions::Check() const {
  if (!(huber > 0)) throw OptionsError("PoseGraphOptions.huber must be > 0 (whitened units)");
  if (iterations < 1) throw OptionsError("PoseGraphOptions.iterations must be >= 1");
  if (num_threads < 1) throw OptionsError("PoseGraphOptions.num_threads must be >= 1");
}

namespace {

// A measured pose M with its sigmas; Residual writes the whitened error of M^-1 * T for a pose T
// (see the header). Shared by the prior and the relative-pose functors.
class WhitenedPoseError {
 public:
  WhitenedPoseError(const Rigid3d& measured, double sigma_translation, double sigma_rotation)
      : inverse_(measured.Inverse()),
        inv_sigma_rotation_(1.0 / sigma_rotation),
        inv_sigma_translation_(1.0 / sigma_translation) {}

  template <typename T>
  void Residual(const Eigen::Quaternion<T>& rotation, const Eigen::Matrix<T, 3, 1>& translation,
                T* residual) const {
    const Eigen::Quaternion<T> r_inverse = inverse_.rotation.cast<T>();
    const Eigen::Quaternion<T> q_error = r_inverse * rotation;
    const Eigen::Matrix<T, 3, 1> t_error = r_inverse * translation + inverse_.translation.cast<T>();
    // q and -q are the same rotation: take the one with w >= 0 so that vec(q) is the small one.
    const T sign = q_error.w() < T(0) ? T(-1) : T(1);
    for (int i = 0; i < 3; ++i) {
      residual[i] = T(2.0 * inv_sigma_rotation_) * sign * q_error.vec()[i];
      residual[3 + i] = T(inv_sigma_translation_) * t_error[i];
    }
  }

 private:
  Rigid3d inverse_;
  double inv_sigma_rotation_, inv_sigma_translation_;
};

class PriorError {
 public:
  explicit PriorError(const PosePrior& prior)
      : error_(prior.world_from_node, prior.sigma_translation, prior.sigma_rotation) {}

  template <typename T>
  bool operator()(const T* const q, const T* const t, T* residual) const {
    error_.Residual(Eigen::Quaternion<T>(q[3], q[0], q[1], q[2]),
                    Eigen::Matrix<T, 3, 1>(t[0], t[1], t[2]), residual);
    return true;
  }

 private:
  WhitenedPoseError error_;
};

class RelativeError {
 public:
  explicit RelativeError(const RelativePose& edge)
      : error_(edge.from_from_to, edge.sigma_translation, edge.sigma_rotation) {}

  template <typename T>
  bool operator()(const T* const q_from, const T* const t_from, const T* const q_to,
                  const T* const t_to, T* residual) const {
    // from_from_to = world_from_from^-1 * world_from_to.
    const Eigen::Quaternion<T> from_inverse =
        Eigen::Quaternion<T>(q_from[3], q_from[0], q_from[1], q_from[2]).conjugate();
    const Eigen::Quaternion<T> world_from_to(q_to[3], q_to[0], q_to[1], q_to[2]);
    const Eigen::Matrix<T, 3, 1> offset(t_to[0] - t_from[0], t_to[1] - t_from[1],
                                        t_to[2] - t_from[2]);
    error_.Residual(from_inverse * world_from_to, from_inverse * offset, residual);
    return true;
  }

 private:
  WhitenedPoseError error_;
};

bool PositiveSigmas(double sigma_translation, double sigma_rotation) {
  return std::isfinite(sigma_translation) && sigma_translation > 0 &&
         std::isfinite(sigma_rotation) && sigma_rotation > 0;
}

}  // namespace

PoseGraphResult SolvePoseGraph(const std::vector<PosePrior>& priors,
                               const std::vector<RelativePose>& edges,
                               const PoseGraphOptions& options) {
  options.Check();
  const int n = static_cast<int>(priors.size());
  std::vector<std::array<double, 4>> q(n);
  std::vector<std::array<double, 3>> t(n);
  ceres::EigenQuaternionManifold quaternion_manifold;
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  for (int i = 0; i < n; ++i) {
    const PosePrior& prior = priors[i];
    if (!PositiveSigmas(prior.sigma_translation, prior.sigma_rotation)) {
      throw std::invalid_argument("SolvePoseGraph: prior " + std::to_string(i) +
                                  " needs positive, finite sigmas");
    }
    const Eigen::Quaterniond r = prior.world_from_node.rotation.normalized();
    q[i] = {r.x(), r.y(), r.z(), r.w()};
    const Eigen::Vector3d& p = prior.world_from_node.translation;
    t[i] = {p.x(), p.y(), p.z()};
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<PriorError, 6, 4, 3>(new PriorError(prior)), nullptr,
        q[i].data(), t[i].data());
    problem.SetManifold(q[i].data(), &quaternion_manifold);
  }
  for (const RelativePose& edge : edges) {
    if (edge.from < 0 || edge.from >= n || edge.to < 0 || edge.to >= n || edge.from == edge.to) {
      throw std::invalid_argument("SolvePoseGraph: edge " + std::to_string(edge.from) + " -> " +
                                  std::to_string(edge.to) + " names an unknown node");
    }
    if (!PositiveSigmas(edge.sigma_translation, edge.sigma_rotation)) {
      throw std::invalid_argument("SolvePoseGraph: edge " + std::to_string(edge.from) + " -> " +
                                  std::to_string(edge.to) + " needs positive, finite sigmas");
    }
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<RelativeError, 6, 4, 3, 4, 3>(new RelativeError(edge)),
        new ceres::HuberLoss(options.huber), q[edge.from].data(), t[edge.from].data(),
        q[edge.to].data(), t[edge.to].data());
  }
  PoseGraphResult result;
  if (n == 0) return result;
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver_options.max_num_iterations = options.iterations;
  solver_options.num_threads = options.num_threads;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  result.usable = summary.IsSolutionUsable();
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.iterations = static_cast<int>(summary.iterations.size());
  for (int i = 0; i < n; ++i) {
    result.world_from_node.push_back(
        result.usable ? Rigid3d(Eigen::Quaterniond(q[i][3], q[i][0], q[i][1], q[i][2]).normalized(),
                                Eigen::Vector3d(t[i][0], t[i][1], t[i][2]))
                      : priors[i].world_from_node);
  }
  return result;
}

}  // namespace planeloc
