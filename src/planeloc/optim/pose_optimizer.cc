#include "planeloc/optim/pose_optimizer.h"

#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "planeloc/optim/cost_functions.h"
#include "planeloc/util/error.h"

namespace planeloc {

void PoseOptimizerOptions::Check() const {
  if (rounds < 1) throw OptionsError("PoseOptimizerOptions.rounds must be >= 1");
  if (iterations_per_round < 1) {
    throw OptionsError("PoseOptimizerOptions.iterations_per_round must be >= 1");
  }
  if (!(chi2_mono > 0)) throw OptionsError("PoseOptimizerOptions.chi2_mono must be > 0");
  if (!(chi2_stereo > 0)) throw OptionsError("PoseOptimizerOptions.chi2_stereo must be > 0");
}

namespace {

// Fewer inliers than this cannot constrain 6 DoF robustly; ORB-SLAM2 stops at 10 edges.
constexpr int kMinObservationsToSolve = 10;

struct PoseBlocks {
  double q[4];  // x, y, z, w
  double t[3];
};

// Whitened squared error |r|^2 of one observation at the given pose, or +inf when the point is
// at/behind the camera (then it is an outlier).
double Chi2(const ceres::CostFunction& cost, const PoseBlocks& pose) {
  const double* params[2] = {pose.q, pose.t};
  double r[3] = {0, 0, 0};
  if (!cost.Evaluate(params, r, nullptr)) return std::numeric_limits<double>::infinity();
  return r[0] * r[0] + r[1] * r[1] + (cost.num_residuals() == 3 ? r[2] * r[2] : 0.0);
}

// Also sets stereo[i] (sized to the observations): whether observation i has a right-image
// coordinate.
std::vector<std::unique_ptr<ceres::CostFunction>> MakeCosts(
    const StereoCamera& camera, const std::vector<PoseObservation>& observations,
    std::vector<bool>& stereo) {
  const PinholeStereoIntrinsics k = PinholeStereoIntrinsics::From(camera);
  const int n = static_cast<int>(observations.size());
  std::vector<std::unique_ptr<ceres::CostFunction>> costs;
  costs.reserve(n);
  for (int i = 0; i < n; ++i) {
    const PoseObservation& o = observations[i];
    stereo[i] = o.u_right >= 0;
    if (stereo[i]) {
      costs.push_back(std::make_unique<StereoPoseOnlyError>(
          k, Eigen::Vector3d(o.u_left, o.v, o.u_right), o.point_in_world, o.information));
    } else {
      costs.push_back(std::make_unique<MonoPoseOnlyError>(k, Eigen::Vector2d(o.u_left, o.v),
                                                          o.point_in_world, o.information));
    }
  }
  return costs;
}

// The costs, losses and manifold outlive every round's problem.
ceres::Problem::Options NonOwningProblemOptions() {
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  return problem_options;
}

ceres::Solver::Options RoundSolverOptions(const PoseOptimizerOptions& options) {
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;  // 6x6 normal equations
  solver_options.max_num_iterations = options.iterations_per_round;
  solver_options.num_threads = 1;  // deterministic, and a 6-DoF problem gains nothing
  solver_options.logging_type = ceres::SILENT;
  solver_options.minimizer_progress_to_stdout = false;
  return solver_options;
}

}  // namespace

PoseOptimizerResult OptimizePose(const StereoCamera& camera, const Rigid3d& cam_from_world_initial,
                                 const std::vector<PoseObservation>& observations,
                                 const PoseOptimizerOptions& options) {
  options.Check();
  const int n = static_cast<int>(observations.size());

  // One analytic cost per observation, reused by every round's problem.
  std::vector<bool> stereo(n);
  const std::vector<std::unique_ptr<ceres::CostFunction>> costs =
      MakeCosts(camera, observations, stereo);

  PoseBlocks pose;
  Eigen::Map<Eigen::Quaterniond>(pose.q) = cam_from_world_initial.rotation.normalized();
  Eigen::Map<Eigen::Vector3d>(pose.t) = cam_from_world_initial.translation;

  // Initial classification: everything that projects in front of the camera is an inlier (the
  // first round decides with the robust kernel).
  std::vector<bool> inlier(n);
  for (int i = 0; i < n; ++i) inlier[i] = std::isfinite(Chi2(*costs[i], pose));

  ceres::HuberLoss huber_mono(std::sqrt(options.chi2_mono));
  ceres::HuberLoss huber_stereo(std::sqrt(options.chi2_stereo));
  ceres::EigenQuaternionManifold quaternion_manifold;

  const ceres::Problem::Options problem_options = NonOwningProblemOptions();
  const ceres::Solver::Options solver_options = RoundSolverOptions(options);

  const auto classify = [&] {
    for (int i = 0; i < n; ++i) {
      inlier[i] = Chi2(*costs[i], pose) <= (stereo[i] ? options.chi2_stereo : options.chi2_mono);
    }
  };

  for (int round = 0; round < options.rounds; ++round) {
    // ORB-SLAM2 drops the robust kernel in the last round: the inlier set is settled and the
    // plain least-squares estimate is the efficient one.
    const bool robust = round + 1 < options.rounds;
    ceres::Problem problem(problem_options);
    problem.AddParameterBlock(pose.q, 4, &quaternion_manifold);
    problem.AddParameterBlock(pose.t, 3);
    int num_blocks = 0;
    for (int i = 0; i < n; ++i) {
      if (!inlier[i]) continue;  // outliers are switched off for this round, may come back later
      ceres::LossFunction* loss = nullptr;
      if (robust) loss = stereo[i] ? &huber_stereo : &huber_mono;
      problem.AddResidualBlock(costs[i].get(), loss, pose.q, pose.t);
      ++num_blocks;
    }
    if (num_blocks < kMinObservationsToSolve) {
      classify();
      break;
    }
    const PoseBlocks before = pose;
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &problem, &summary);
    if (!summary.IsSolutionUsable()) pose = before;  // keep the last good pose, never a broken one
    // Re-classify every observation, also this round's outliers, at the (new) pose.
    classify();
    if (!summary.IsSolutionUsable()) break;
  }

  PoseOptimizerResult result;
  result.cam_from_world = Rigid3d(Eigen::Quaterniond(Eigen::Map<const Eigen::Quaterniond>(pose.q)),
                                  Eigen::Vector3d(Eigen::Map<const Eigen::Vector3d>(pose.t)));
  result.inlier = std::move(inlier);
  for (bool b : result.inlier) result.num_inliers += b ? 1 : 0;
  return result;
}

}  // namespace planeloc
