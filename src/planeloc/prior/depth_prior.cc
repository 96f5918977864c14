#include "planeloc/prior/depth_prior.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <algorithm>
#include <limits>
#include <memory>

#include "planeloc/geometry/lie.h"

namespace planeloc {

ceres::CostFunction* DisparityToMapError::Create(const DenseDisparity& disparity,
                                                 const PinholeStereoIntrinsics& k,
                                                 const Eigen::Vector3d& point_in_world,
                                                 double sigma_px) {
  return new ceres::AutoDiffCostFunction<DisparityToMapError, 1, 4, 3>(
      new DisparityToMapError(disparity, k, point_in_world, sigma_px));
}

namespace {

struct Projected {
  int index;
  double u, v, z;
};

// A pixel grid of `cell` pixels over the image.
struct CellGrid {
  int cell, cols, rows;
  CellGrid(const StereoCamera& camera, int cell_px)
      : cell(cell_px),
        cols((camera.width + cell_px - 1) / cell_px),
        rows((camera.height + cell_px - 1) / cell_px) {}
  int size() const { return cols * rows; }
  int Of(double u, double v) const {
    const int c = std::clamp(static_cast<int>(u / cell), 0, cols - 1);
    const int r = std::clamp(static_cast<int>(v / cell), 0, rows - 1);
    return r * cols + c;
  }
  double CenterDistance2(double u, double v) const {
    const double du = u - (std::floor(u / cell) + 0.5) * cell;
    const double dv = v - (std::floor(v / cell) + 0.5) * cell;
    return du * du + dv * dv;
  }
};

}  // namespace

std::vector<Eigen::Vector3d> SelectDepthPoints(const MapCloudIndex& map, const StereoCamera& camera,
                                               const Rigid3d& cam_from_world,
                                               const DenseDisparity& disparity,
                                               const DepthPriorOptions& options,
                                               DepthSelectionStats* stats) {
  DepthSelectionStats s;
  const Eigen::Vector3d center = cam_from_world.Inverse().translation;
  const std::vector<int> near = map.Near(center, options.max_range);
  s.candidates = static_cast<int>(near.size());

  std::vector<Projected> projected;
  for (int i : near) {
    const Eigen::Vector3d p = cam_from_world * map.point(i);
    if (p.z() < options.min_depth || p.z() > options.max_range) continue;
    const double u = camera.fx * p.x() / p.z() + camera.cx;
    const double v = camera.fy * p.y() / p.z() + camera.cy;
    if (!camera.InImage(Eigen::Vector2d(u, v), 1.0)) continue;
    projected.push_back({i, u, v, p.z()});
  }
  // Splats on a grid of 2-pixel cells: a disc of the voxel's size at the point's depth.
  const CellGrid zgrid(camera, 2);
  std::vector<double> nearest(zgrid.size(), std::numeric_limits<double>::infinity());
  for (const Projected& p : projected) {
    const int radius =
        std::max(0, static_cast<int>(0.5 * camera.fx * options.voxel_size / p.z / zgrid.cell));
    const int c0 = static_cast<int>(p.u / zgrid.cell), r0 = static_cast<int>(p.v / zgrid.cell);
    for (int r = std::max(0, r0 - radius); r <= std::min(zgrid.rows - 1, r0 + radius); ++r) {
      for (int c = std::max(0, c0 - radius); c <= std::min(zgrid.cols - 1, c0 + radius); ++c) {
        double& z_min = nearest[r * zgrid.cols + c];
        z_min = std::min(z_min, p.z);
      }
    }
  }
  s.in_view = static_cast<int>(projected.size());

  // One point per sampling cell: the one nearest its centre, so that the evidence covers the
  // image instead of the densest facade.
  const CellGrid sample_grid(camera, options.sample_cell);
  std::vector<int> chosen(sample_grid.size(), -1);
  const double bf = camera.BaselineTimesFx();
  for (int k = 0; k < static_cast<int>(projected.size()); ++k) {
    const Projected& p = projected[k];
    const double nearest_z = nearest[zgrid.Of(p.u, p.v)];
    if (p.z > nearest_z + 1.5 * options.voxel_size + options.zbuffer_relative * p.z) {
      ++s.hidden_by_map;
      continue;
    }
    const double d = disparity.At(p.u, p.v);
    if (d <= 0) {
      ++s.no_disparity;
      continue;
    }
    if (!disparity.SmoothAt(p.u, p.v, options.edge_tolerance)) {
      ++s.on_edge;
      continue;
    }
    const double z_stereo = bf / d;
    const double sigma_z = p.z * p.z * options.disparity_sigma / bf;
    if (p.z - z_stereo > std::max(options.occlusion_margin, 3 * sigma_z)) {
      ++s.occluded;
      continue;
    }
    int& best = chosen[sample_grid.Of(p.u, p.v)];
    if (best < 0 || sample_grid.CenterDistance2(p.u, p.v) <
                        sample_grid.CenterDistance2(projected[best].u, projected[best].v)) {
      best = k;
    }
  }
  std::vector<int> cells;
  for (int c = 0; c < sample_grid.size(); ++c) {
    if (chosen[c] >= 0) cells.push_back(chosen[c]);
  }
  // Over the budget: an even stride over the cells keeps the spread.
  const std::size_t budget = static_cast<std::size_t>(options.max_points);
  std::vector<Eigen::Vector3d> points;
  const double step = cells.size() > budget ? double(cells.size()) / budget : 1.0;
  for (double x = 0; x < cells.size() && points.size() < budget; x += step) {
    points.push_back(map.point(projected[cells[static_cast<std::size_t>(x)]].index));
  }
  s.used = static_cast<int>(points.size());
  if (stats) *stats = s;
  return points;
}

namespace {

struct PoseBlocks {
  double q[4];  // x, y, z, w
  double t[3];
  explicit PoseBlocks(const Rigid3d& cam_from_world) {
    const Eigen::Quaterniond r = cam_from_world.rotation.normalized();
    q[0] = r.x(), q[1] = r.y(), q[2] = r.z(), q[3] = r.w();
    for (int i = 0; i < 3; ++i) t[i] = cam_from_world.translation[i];
  }
  Rigid3d ToRigid() const {
    return Rigid3d(Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized(),
                   Eigen::Vector3d(t[0], t[1], t[2]));
  }
};

}  // namespace

DepthRefinement RefinePoseWithMapDepth(const StereoCamera& camera,
                                       const Rigid3d& cam_from_world_initial,
                                       const std::vector<PoseObservation>& visual,
                                       const MapCloudIndex& map, const DenseDisparity& disparity,
                                       const DepthPriorOptions& options) {
  options.Check();
  DepthRefinement result;
  result.cam_from_world = cam_from_world_initial;
  if (disparity.empty()) return result;
  const PinholeStereoIntrinsics k = PinholeStereoIntrinsics::From(camera);
  // Whitened by sigma_d, the robust kernel at `huber` sigma_d, then scaled by the weight (the
  // kernel stays where the disparity's noise puts it whatever the weight).
  const double sigma = options.disparity_sigma;

  PoseBlocks pose(cam_from_world_initial);
  ceres::HuberLoss huber_mono(std::sqrt(5.991)), huber_stereo(std::sqrt(7.815));
  ceres::ScaledLoss huber_depth(new ceres::HuberLoss(options.huber), options.weight,
                                ceres::TAKE_OWNERSHIP);
  std::vector<Eigen::Vector3d> points;
  for (int round = 0; round < 2; ++round) {
    points = SelectDepthPoints(map, camera, pose.ToRigid(), disparity, options,
                               round == 0 ? &result.selection : nullptr);
    if (static_cast<int>(points.size()) < options.min_points) {
      if (round == 0) return result;
      break;
    }
    ceres::Problem::Options problem_options;
    problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::EigenQuaternionManifold quaternion_manifold;
    ceres::Problem problem(problem_options);
    problem.AddParameterBlock(pose.q, 4, &quaternion_manifold);
    problem.AddParameterBlock(pose.t, 3);
    for (const PoseObservation& o : visual) {
      if (o.u_right >= 0) {
        problem.AddResidualBlock(
            new StereoPoseOnlyError(k, Eigen::Vector3d(o.u_left, o.v, o.u_right), o.point_in_world,
                                    o.information),
            &huber_stereo, pose.q, pose.t);
      } else {
        problem.AddResidualBlock(new MonoPoseOnlyError(k, Eigen::Vector2d(o.u_left, o.v),
                                                       o.point_in_world, o.information),
                                 &huber_mono, pose.q, pose.t);
      }
    }
    for (const Eigen::Vector3d& x : points) {
      problem.AddResidualBlock(DisparityToMapError::Create(disparity, k, x, sigma), &huber_depth,
                               pose.q, pose.t);
    }
    ceres::Solver::Options solver_options;
    solver_options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
    solver_options.max_num_iterations = 10;
    solver_options.num_threads = 1;
    solver_options.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    const PoseBlocks before = pose;
    ceres::Solve(solver_options, &problem, &summary);
    if (!summary.IsSolutionUsable()) {
      pose = before;
      break;
    }
    result.applied = true;
  }
  result.cam_from_world = pose.ToRigid();
  if (result.applied) {
    const Rigid3d step = result.cam_from_world * cam_from_world_initial.Inverse();
    const double moved =
        (result.cam_from_world.Inverse().translation - cam_from_world_initial.Inverse().translation)
            .norm();
    const double turned = LogSO3(step.RotationMatrix()).norm() * 180.0 / M_PI;
    if (moved > options.max_correction || turned > options.max_correction_deg) {
      result.cam_from_world = cam_from_world_initial;
      result.applied = false;
      result.refused = true;
      return result;
    }
  }
  if (result.applied) {
    std::vector<double> residuals;
    for (const Eigen::Vector3d& x : points) {
      const Eigen::Vector3d p = result.cam_from_world * x;
      if (p.z() < kMinDepth) continue;
      const double d = disparity.At(camera.fx * p.x() / p.z() + camera.cx,
                                    camera.fy * p.y() / p.z() + camera.cy);
      if (d > 0) residuals.push_back(std::abs(d - camera.BaselineTimesFx() / p.z()));
    }
    if (!residuals.empty()) {
      std::nth_element(residuals.begin(), residuals.begin() + residuals.size() / 2,
                       residuals.end());
      result.median_abs_residual_px = residuals[residuals.size() / 2];
    }
  }
  return result;
}

}  // namespace planeloc
