#include "planeloc/optim/window_ba.h"

#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <ceres/ordered_groups.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "planeloc/optim/cost_functions.h"
#include "planeloc/util/error.h"

namespace planeloc {

void WindowBaOptions::Check() const {
  if (!(lambda > 0.0 && lambda <= 1.0)) {
    throw OptionsError(
        "WindowBaOptions.lambda must be in (0, 1]: lambda = 0 leaves the poses "
        "without any visual constraint");
  }
  if (!(plane_sigma > 0)) throw OptionsError("WindowBaOptions.plane_sigma must be > 0 metres");
  if (!(plane_huber > 0)) throw OptionsError("WindowBaOptions.plane_huber must be > 0 metres");
  if (!(plane_outlier_distance > 0)) {
    throw OptionsError("WindowBaOptions.plane_outlier_distance must be > 0 metres");
  }
  if (!(chi2_mono > 0)) throw OptionsError("WindowBaOptions.chi2_mono must be > 0");
  if (!(chi2_stereo > 0)) throw OptionsError("WindowBaOptions.chi2_stereo must be > 0");
  if (iterations < 1) throw OptionsError("WindowBaOptions.iterations must be >= 1");
  if (num_threads < 1) throw OptionsError("WindowBaOptions.num_threads must be >= 1");
  if (dense_schur_max_keyframes < 0) {
    throw OptionsError("WindowBaOptions.dense_schur_max_keyframes must be >= 0");
  }
}

namespace {

using PoseParams = std::array<double, 7>;  // q (x, y, z, w), then t; cam_from_world
using PointParams = std::array<double, 3>;

// The problem flattened to indices, the parameter storage and one cost per residual. Costs are
// created once and reused by both rounds (the problems do not own them).
struct WindowState {
  std::vector<PoseParams> poses;          // aligned with problem.keyframes
  std::vector<PointParams> points;        // aligned with problem.points
  std::vector<int> obs_keyframe;          // per observation: keyframe index
  std::vector<int> obs_point;             // per observation: point index
  std::vector<bool> obs_stereo;           // per observation
  std::vector<const Plane*> point_plane;  // per point, nullptr when not on a plane
  std::vector<int> point_correction;      // per point: index into corrections, -1 for none
  std::vector<std::unique_ptr<ceres::CostFunction>> reprojection_costs;  // per observation
  std::vector<std::unique_ptr<ceres::CostFunction>> plane_costs;         // per point or null
  // Per corrected plane (WindowPlane::offset_sigma > 0): its parameters, prior and plane id.
  std::vector<PointParams> corrections;
  std::vector<std::unique_ptr<ceres::CostFunction>> correction_priors;
  std::vector<int> correction_plane_id;
  std::vector<bool> correction_holds_tilt;
  std::vector<bool> correction_used;  // reached by a plane residual in some round
};

template <typename Id>
std::unordered_map<int, int> IndexById(const std::vector<Id>& items, const char* what) {
  std::unordered_map<int, int> index;
  for (int i = 0; i < static_cast<int>(items.size()); ++i) {
    if (!index.emplace(items[i].id, i).second) {
      throw std::invalid_argument(std::string("SolveWindowBa: duplicate ") + what + " id " +
                                  std::to_string(items[i].id));
    }
  }
  return index;
}

int Lookup(const std::unordered_map<int, int>& index, int id, const char* what) {
  const auto it = index.find(id);
  if (it == index.end()) {
    throw std::invalid_argument(std::string("SolveWindowBa: unknown ") + what + " id " +
                                std::to_string(id));
  }
  return it->second;
}

WindowState BuildState(const StereoCamera& camera, const WindowProblem& problem,
                       const WindowBaOptions& options) {
  WindowState s;
  const auto keyframe_index = IndexById(problem.keyframes, "keyframe");
  const auto point_index = IndexById(problem.points, "point");
  const auto plane_index = IndexById(problem.planes, "plane");
  for (const WindowKeyframe& kf : problem.keyframes) {
    const Eigen::Quaterniond q = kf.cam_from_world.rotation.normalized();
    s.poses.push_back({q.x(), q.y(), q.z(), q.w(), kf.cam_from_world.translation.x(),
                       kf.cam_from_world.translation.y(), kf.cam_from_world.translation.z()});
  }
  const bool use_planes = options.lambda < 1.0;
  std::vector<int> plane_correction(problem.planes.size(), -1);
  for (std::size_t i = 0; use_planes && i < problem.planes.size(); ++i) {
    const WindowPlane& plane = problem.planes[i];
    if (!(std::isfinite(plane.offset_sigma) && plane.offset_sigma >= 0 &&
          std::isfinite(plane.tilt_sigma) && plane.tilt_sigma >= 0 && plane.anchor.allFinite())) {
      throw std::invalid_argument("SolveWindowBa: plane " + std::to_string(plane.id) +
                                  " has a negative or non-finite correction sigma or anchor");
    }
    if (!(plane.offset_sigma > 0)) continue;
    plane_correction[i] = static_cast<int>(s.corrections.size());
    s.corrections.push_back({0, 0, 0});
    s.correction_priors.emplace_back(
        PlaneCorrectionPrior::Create(plane.offset_sigma, plane.tilt_sigma));
    s.correction_plane_id.push_back(plane.id);
    s.correction_holds_tilt.push_back(!(plane.tilt_sigma > 0));
    s.correction_used.push_back(false);
  }
  for (const WindowPoint& p : problem.points) {
    s.points.push_back({p.point_in_world.x(), p.point_in_world.y(), p.point_in_world.z()});
    const WindowPlane* plane = nullptr;
    int correction = -1;
    if (p.plane_id) {
      const int index = Lookup(plane_index, *p.plane_id, "plane");
      plane = &problem.planes[index];
      correction = plane_correction[index];
    }
    s.point_plane.push_back(plane != nullptr ? &plane->plane_in_world : nullptr);
    s.point_correction.push_back(correction);
    const double sigma = p.plane_sigma > 0 ? p.plane_sigma : options.plane_sigma;
    if (!use_planes || plane == nullptr) {
      s.plane_costs.emplace_back(nullptr);
    } else if (correction >= 0) {
      s.plane_costs.emplace_back(
          PointToCorrectedPlanePadded::Create(plane->plane_in_world, plane->anchor, sigma));
    } else {
      s.plane_costs.emplace_back(new PointToPlanePadded(plane->plane_in_world, sigma));
    }
  }
  const PinholeStereoIntrinsics k = PinholeStereoIntrinsics::From(camera);
  for (const WindowObservation& o : problem.observations) {
    s.obs_keyframe.push_back(Lookup(keyframe_index, o.keyframe_id, "keyframe"));
    s.obs_point.push_back(Lookup(point_index, o.point_id, "point"));
    s.obs_stereo.push_back(o.u_right >= 0);
    // Analytic Jacobians; mono padded to 3 rows so Ceres uses its <3, 3, 3> Schur eliminator.
    if (o.u_right >= 0) {
      s.reprojection_costs.push_back(std::make_unique<StereoReprojectionAnalytic>(
          k, Eigen::Vector3d(o.u_left, o.v, o.u_right), o.information));
    } else {
      s.reprojection_costs.push_back(std::make_unique<MonoReprojectionPadded>(
          k, Eigen::Vector2d(o.u_left, o.v), o.information));
    }
  }
  return s;
}

// Whitened squared reprojection error of observation i, +inf at/behind the camera.
double Chi2(const WindowState& s, int i) {
  const PoseParams& pose = s.poses[s.obs_keyframe[i]];
  const double* params[3] = {pose.data(), pose.data() + 4, s.points[s.obs_point[i]].data()};
  double r[3] = {0, 0, 0};
  if (!s.reprojection_costs[i]->Evaluate(params, r, nullptr)) {
    return std::numeric_limits<double>::infinity();
  }
  return r[0] * r[0] + r[1] * r[1] + r[2] * r[2];  // r[2] is 0 for (padded) mono
}

std::vector<bool> ClassifyObservations(const WindowState& s, const WindowBaOptions& options) {
  std::vector<bool> inlier(s.obs_keyframe.size());
  for (size_t i = 0; i < inlier.size(); ++i) {
    const int ii = static_cast<int>(i);
    inlier[i] = Chi2(s, ii) <= (s.obs_stereo[i] ? options.chi2_stereo : options.chi2_mono);
  }
  return inlier;
}

// The loss functions of one round. The paper's lambda * E_reproj + (1 - lambda) * E_plane enters
// here only, as ceres::ScaledLoss around the (robust or plain) kernel of each term.
struct RoundLosses {
  RoundLosses(const WindowBaOptions& options, bool robust_reprojection) {
    const auto scaled = [](ceres::LossFunction* inner, double weight) -> ceres::LossFunction* {
      return new ceres::ScaledLoss(inner, weight, ceres::DO_NOT_TAKE_OWNERSHIP);
    };
    if (robust_reprojection) {
      huber_mono = std::make_unique<ceres::HuberLoss>(std::sqrt(options.chi2_mono));
      huber_stereo = std::make_unique<ceres::HuberLoss>(std::sqrt(options.chi2_stereo));
    }
    if (options.lambda < 1.0) {
      mono.reset(scaled(huber_mono.get(), options.lambda));
      stereo.reset(scaled(huber_stereo.get(), options.lambda));
      // Huber threshold in whitened units: plane_huber metres / plane_sigma metres.
      huber_plane = std::make_unique<ceres::HuberLoss>(options.plane_huber / options.plane_sigma);
      plane.reset(scaled(huber_plane.get(), 1.0 - options.lambda));
      plane_prior.reset(scaled(nullptr, 1.0 - options.lambda));
    }
  }
  ceres::LossFunction* Mono() const { return mono ? mono.get() : huber_mono.get(); }
  ceres::LossFunction* Stereo() const { return stereo ? stereo.get() : huber_stereo.get(); }

  std::unique_ptr<ceres::LossFunction> huber_mono, huber_stereo, huber_plane;
  std::unique_ptr<ceres::LossFunction> mono, stereo, plane;  // scaled; null when lambda = 1
  std::unique_ptr<ceres::LossFunction> plane_prior;          // (1 - lambda), no kernel
};

struct RoundOutcome {
  ceres::Solver::Summary summary;
  int num_plane_residuals = 0;
};

// The active observations' reprojection residuals; points go to elimination group 0, poses to
// group 1. Marks the points it adds in `point_added`; returns the number of free keyframes.
int AddReprojectionResiduals(const WindowProblem& problem, const std::vector<bool>& active_obs,
                             const RoundLosses& losses, ceres::Manifold* quaternion_manifold,
                             WindowState& s, ceres::Problem& ceres_problem,
                             ceres::ParameterBlockOrdering& ordering,
                             std::vector<bool>& point_added) {
  std::vector<bool> pose_added(s.poses.size());
  int num_free_keyframes = 0;
  for (size_t i = 0; i < active_obs.size(); ++i) {
    if (!active_obs[i]) continue;
    const int kf = s.obs_keyframe[i], pt = s.obs_point[i];
    double* q = s.poses[kf].data();
    double* t = q + 4;
    double* x = s.points[pt].data();
    ceres_problem.AddResidualBlock(s.reprojection_costs[i].get(),
                                   s.obs_stereo[i] ? losses.Stereo() : losses.Mono(), q, t, x);
    if (!pose_added[kf]) {
      pose_added[kf] = true;
      if (!problem.keyframes[kf].fixed) ++num_free_keyframes;
      ceres_problem.SetManifold(q, quaternion_manifold);
      ordering.AddElementToGroup(q, 1);
      ordering.AddElementToGroup(t, 1);
      // Fixed keyframes are anchors; at least one of them also fixes the gauge (6 DoF for
      // stereo, 7 for monocular-only windows) that the reprojection error cannot observe.
      if (problem.keyframes[kf].fixed) {
        ceres_problem.SetParameterBlockConstant(q);
        ceres_problem.SetParameterBlockConstant(t);
      }
    }
    if (!point_added[pt]) {
      point_added[pt] = true;
      ordering.AddElementToGroup(x, 0);
    }
  }
  return num_free_keyframes;
}

// The active plane residuals of points that are also seen (alone a plane residual would fix 1 of
// 3 DoF), with the prior of each plane correction they reach. Returns their count.
int AddPlaneResiduals(const std::vector<bool>& point_added, const std::vector<bool>& active_plane,
                      const RoundLosses& losses, ceres::Manifold* hold_tilt, WindowState& s,
                      ceres::Problem& ceres_problem, ceres::ParameterBlockOrdering& ordering) {
  int num_plane_residuals = 0;
  std::vector<bool> correction_added(s.corrections.size(), false);
  for (size_t p = 0; p < s.points.size(); ++p) {
    if (!point_added[p] || !s.plane_costs[p] || !active_plane[p]) continue;
    const int c = s.point_correction[p];
    if (c < 0) {
      ceres_problem.AddResidualBlock(s.plane_costs[p].get(), losses.plane.get(),
                                     s.points[p].data());
    } else {
      double* correction = s.corrections[c].data();
      ceres_problem.AddResidualBlock(s.plane_costs[p].get(), losses.plane.get(), s.points[p].data(),
                                     correction);
      if (!correction_added[c]) {
        correction_added[c] = true;
        s.correction_used[c] = true;
        // The prior is part of the plane term: the same (1 - lambda) weight, no robust kernel
        // (it is not a measurement that can be an outlier).
        ceres_problem.AddResidualBlock(s.correction_priors[c].get(), losses.plane_prior.get(),
                                       correction);
        if (s.correction_holds_tilt[c]) ceres_problem.SetManifold(correction, hold_tilt);
        // Not eliminated with the points: it links many of them, like a pose.
        ordering.AddElementToGroup(correction, 1);
      }
    }
    ++num_plane_residuals;
  }
  return num_plane_residuals;
}

// One Levenberg-Marquardt run over the active residuals. Points form the first elimination
// group of the Schur complement, poses the second, so each solve factors only the small reduced
// camera system.
RoundOutcome SolveRound(const WindowProblem& problem, const WindowBaOptions& options,
                        const std::vector<bool>& active_obs, const std::vector<bool>& active_plane,
                        bool robust_reprojection, WindowState& s) {
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem ceres_problem(problem_options);
  ceres::EigenQuaternionManifold quaternion_manifold;
  const RoundLosses losses(options, robust_reprojection);
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();

  std::vector<bool> point_added(s.points.size());
  const int num_free_keyframes = AddReprojectionResiduals(
      problem, active_obs, losses, &quaternion_manifold, s, ceres_problem, *ordering, point_added);
  RoundOutcome outcome;
  ceres::SubsetManifold hold_tilt(3, {1, 2});
  outcome.num_plane_residuals =
      AddPlaneResiduals(point_added, active_plane, losses, &hold_tilt, s, ceres_problem, *ordering);
  if (ceres_problem.NumResidualBlocks() == 0) return outcome;  // summary stays unusable

  ceres::Solver::Options solver_options;
  // Both eliminate the points first; they differ in how the small reduced camera system is
  // factored. Dense is ~1.5x faster for window-sized problems (docs/bench-optim.md).
  solver_options.linear_solver_type = num_free_keyframes <= options.dense_schur_max_keyframes
                                          ? ceres::DENSE_SCHUR
                                          : ceres::SPARSE_SCHUR;
  solver_options.linear_solver_ordering = ordering;
  solver_options.max_num_iterations = options.iterations;
  solver_options.num_threads = options.num_threads;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solve(solver_options, &ceres_problem, &outcome.summary);
  return outcome;
}

std::vector<bool> PlaneInliers(const WindowState& s, const WindowBaOptions& options) {
  std::vector<bool> inlier(s.points.size(), false);
  for (size_t p = 0; p < s.points.size(); ++p) {
    if (s.point_plane[p] == nullptr) continue;
    const Eigen::Vector3d x(s.points[p][0], s.points[p][1], s.points[p][2]);
    inlier[p] = std::abs(s.point_plane[p]->SignedDistance(x)) <= options.plane_outlier_distance;
  }
  return inlier;
}

}  // namespace

WindowBaResult SolveWindowBa(const StereoCamera& camera, const WindowProblem& problem,
                             const WindowBaOptions& options) {
  options.Check();
  WindowState s = BuildState(camera, problem, options);

  // As ORB-SLAM2's LocalBundleAdjustment: round 1 with the Huber kernel over every observation
  // in front of its camera and every plane association; round 2 without the kernel on the
  // reprojection term (the plane term keeps its own) over the chi2 inliers of round 1 and the
  // points still near their plane.
  std::vector<bool> active(s.obs_keyframe.size());
  for (size_t i = 0; i < active.size(); ++i) {
    active[i] = std::isfinite(Chi2(s, static_cast<int>(i)));
  }
  std::vector<bool> active_plane(s.points.size(), true);
  WindowBaResult result;
  const std::vector<PoseParams> poses0 = s.poses;
  const std::vector<PointParams> points0 = s.points;
  const std::vector<PointParams> corrections0 = s.corrections;

  RoundOutcome round1 = SolveRound(problem, options, active, active_plane, true, s);
  result.initial_cost = round1.summary.initial_cost;
  result.usable = round1.summary.IsSolutionUsable();
  if (result.usable) {
    active = ClassifyObservations(s, options);
    active_plane = PlaneInliers(s, options);
    RoundOutcome round2 = SolveRound(problem, options, active, active_plane, false, s);
    result.usable = round2.summary.IsSolutionUsable();
    result.final_cost = round2.summary.final_cost;
    result.num_plane_residuals = round2.num_plane_residuals;
  }
  if (!result.usable) {  // numerical failure: hand back the input rather than a broken state
    s.poses = poses0;
    s.points = points0;
    s.corrections = corrections0;
    result.final_cost = result.initial_cost;
  }
  result.observation_inlier = ClassifyObservations(s, options);

  for (size_t i = 0; i < problem.keyframes.size(); ++i) {
    if (problem.keyframes[i].fixed) continue;
    const PoseParams& p = s.poses[i];
    result.cam_from_world[problem.keyframes[i].id] =
        Rigid3d(Eigen::Quaterniond(p[3], p[0], p[1], p[2]), Eigen::Vector3d(p[4], p[5], p[6]));
  }
  for (size_t i = 0; i < problem.points.size(); ++i) {
    result.point_in_world[problem.points[i].id] =
        Eigen::Vector3d(s.points[i][0], s.points[i][1], s.points[i][2]);
  }
  for (size_t c = 0; c < s.corrections.size(); ++c) {
    if (!s.correction_used[c]) continue;
    const PointParams& x = s.corrections[c];
    result.plane_correction[s.correction_plane_id[c]] = Eigen::Vector3d(x[0], x[1], x[2]);
  }
  return result;
}

}  // namespace planeloc
