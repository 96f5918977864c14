#include "planeloc/map/pose_refinement.h"

#include <open3d/geometry/KDTreeSearchParam.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/pipelines/registration/TransformationEstimation.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <numbers>
#include <string>

#include "planeloc/util/error.h"
#include "planeloc/util/progress.h"

namespace planeloc {

void PoseRefinementOptions::Check() const {
  const auto positive = [](double value, const char* name, const char* unit) {
    if (!(std::isfinite(value) && value > 0)) {
      throw OptionsError(std::string("PoseRefinementOptions.") + name + " must be > 0 (" + unit +
                         ")");
    }
  };
  positive(voxel_size, "voxel_size", "metres");
  positive(normal_radius, "normal_radius", "metres");
  positive(max_correspondence, "max_correspondence", "metres");
  positive(prior_sigma_translation, "prior_sigma_translation", "metres");
  positive(prior_sigma_rotation_deg, "prior_sigma_rotation_deg", "degrees");
  positive(edge_sigma_translation, "edge_sigma_translation", "metres");
  positive(edge_sigma_rotation_deg, "edge_sigma_rotation_deg", "degrees");
  positive(max_prior_sigmas, "max_prior_sigmas", "prior sigmas");
  if (icp_iterations < 1) throw OptionsError("PoseRefinementOptions.icp_iterations must be >= 1");
  if (!(min_fitness >= 0 && min_fitness <= 1)) {
    throw OptionsError("PoseRefinementOptions.min_fitness must be in [0, 1]");
  }
  for (const int k : neighbours) {
    if (k < 1) throw OptionsError("PoseRefinementOptions.neighbours must all be >= 1");
  }
  graph.Check();
}

namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

std::shared_ptr<open3d::geometry::PointCloud> IcpCloud(const std::vector<Eigen::Vector3d>& points,
                                                       const MapBuildOptions& build,
                                                       const PoseRefinementOptions& options) {
  auto cloud = std::make_shared<open3d::geometry::PointCloud>();
  for (const Eigen::Vector3d& p : points) {
    const double range = p.norm();
    if (range >= build.min_range && range <= build.max_range) cloud->points_.push_back(p);
  }
  cloud = cloud->VoxelDownSample(options.voxel_size);
  cloud->EstimateNormals(open3d::geometry::KDTreeSearchParamHybrid(options.normal_radius, 30));
  return cloud;
}

// Angle of a rotation, radians.
double Angle(const Eigen::Quaterniond& q) {
  return 2.0 * std::atan2(q.vec().norm(), std::abs(q.w()));
}

// The pose graph of the used scans: a prior per scan (its given pose), an edge per accepted ICP
// registration to a recent scan.
struct ScanGraph {
  std::vector<std::size_t> frames;  // frame index per graph node
  std::vector<PosePrior> priors;
  std::vector<RelativePose> edges;
  int rejected_edges = 0;
};

ScanGraph RegisterScans(const MapBuildOptions& build, const PoseRefinementOptions& options,
                        const KittiSequence& sequence, const Trajectory& poses,
                        const Rigid3d& cam_from_velo) {
  int farthest = 1;
  for (const int k : options.neighbours) farthest = std::max(farthest, k);
  ScanGraph graph;
  std::map<int, std::shared_ptr<open3d::geometry::PointCloud>> recent;  // node -> ICP cloud
  const double prior_rotation = options.prior_sigma_rotation_deg * kDegree;
  const double edge_rotation = options.edge_sigma_rotation_deg * kDegree;
  // A relative pose between two priors is off by sqrt(2) prior sigmas per axis (3 axes).
  const double max_translation_jump =
      options.max_prior_sigmas * std::sqrt(6.0) * options.prior_sigma_translation;
  const double max_rotation_jump = options.max_prior_sigmas * std::sqrt(6.0) * prior_rotation;
  const std::size_t total = (sequence.size() + build.every - 1) / build.every;
  ProgressBar progress("refine poses", total, "scans");
  if (!build.show_progress) progress.Finish();
  for (std::size_t i = 0, done = 0; i < sequence.size(); i += build.every, ++done) {
    const auto path = sequence.velodyne_path(i);
    if (!path || !std::filesystem::exists(*path)) continue;
    const int node = static_cast<int>(graph.priors.size());
    graph.frames.push_back(i);
    const Rigid3d world_from_velo = poses.world_from_cam[i] * cam_from_velo;
    graph.priors.push_back({world_from_velo, options.prior_sigma_translation, prior_rotation});
    auto cloud = IcpCloud(ReadVelodyneScan(*path).points, build, options);
    for (const int k : options.neighbours) {
      const auto target = recent.find(node - k);
      if (target == recent.end() || cloud->points_.empty() || target->second->points_.empty()) {
        continue;
      }
      const Rigid3d initial = graph.priors[node - k].world_from_node.Inverse() * world_from_velo;
      const auto icp = open3d::pipelines::registration::RegistrationICP(
          *cloud, *target->second, options.max_correspondence, initial.Matrix4d(),
          open3d::pipelines::registration::TransformationEstimationPointToPlane(),
          open3d::pipelines::registration::ICPConvergenceCriteria(1e-6, 1e-6,
                                                                  options.icp_iterations));
      const Rigid3d measured = Rigid3d::FromMatrix4d(icp.transformation_);
      const Rigid3d jump = initial.Inverse() * measured;
      if (icp.fitness_ < options.min_fitness || jump.translation.norm() > max_translation_jump ||
          Angle(jump.rotation) > max_rotation_jump) {
        ++graph.rejected_edges;
        continue;
      }
      graph.edges.push_back(
          {node - k, node, measured, options.edge_sigma_translation, edge_rotation});
    }
    recent[node] = std::move(cloud);
    recent.erase(node - farthest);
    if (build.show_progress) progress.Update(done + 1);
  }
  progress.Finish();
  return graph;
}

// Throws when the graph cannot refine anything; warns when most registrations were rejected.
void CheckScanGraph(const ScanGraph& graph, const PoseRefinementOptions& options,
                    const std::string& folder) {
  CheckInput(!graph.priors.empty(), folder, 0, "no Velodyne scan found in the sequence",
             "use a sequence with velodyne/*.bin scans");
  // Without a registration the graph holds only the priors and would return the given poses as
  // "refined": that is no result.
  CheckInput(graph.priors.size() < 2 || !graph.edges.empty(), folder, 0,
             fmt::format("none of the {} scan registrations passed (ICP fitness below {} or a "
                         "correction beyond {} prior sigmas): nothing to refine the poses with",
                         graph.rejected_edges, options.min_fitness, options.max_prior_sigmas),
             "check that --poses are this sequence's poses in its frame, that --prior-sigma is "
             "not smaller than their error, and --min-range/--max-range");
  if (graph.rejected_edges > static_cast<int>(graph.edges.size())) {
    spdlog::warn(
        "map refine-poses: {} of {} scan registrations of {} rejected; the poses are refined from "
        "the {} that passed (check --poses and --prior-sigma)",
        graph.rejected_edges, graph.rejected_edges + static_cast<int>(graph.edges.size()), folder,
        graph.edges.size());
  }
}

// Every frame takes the correction (refined * given^-1) of the nearest node.
Trajectory CorrectPoses(const Trajectory& poses, const ScanGraph& graph,
                        const PoseGraphResult& solved) {
  const std::vector<std::size_t>& frames = graph.frames;
  Trajectory corrected = poses;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const auto after = std::lower_bound(frames.begin(), frames.end(), i);
    std::size_t nearest = static_cast<std::size_t>(after - frames.begin());
    if (after == frames.end() || (after != frames.begin() && *after - i > i - *(after - 1))) {
      --nearest;
    }
    const Rigid3d correction =
        solved.world_from_node[nearest] * graph.priors[nearest].world_from_node.Inverse();
    corrected.world_from_cam[i] = correction * poses.world_from_cam[i];
  }
  return corrected;
}

}  // namespace

PoseRefinementResult RefinePoses(const MapBuildOptions& build, const PoseRefinementOptions& options,
                                 const KittiSequence& sequence, const Trajectory& poses) {
  build.Check();
  options.Check();
  const std::string folder = sequence.folder().string();
  const Rigid3d cam_from_velo = CheckScanSequence(sequence, poses);
  const ScanGraph scans = RegisterScans(build, options, sequence, poses, cam_from_velo);
  CheckScanGraph(scans, options, folder);
  const PoseGraphResult graph = SolvePoseGraph(scans.priors, scans.edges, options.graph);
  CheckInput(graph.usable, folder, 0, "the pose graph of the scans did not converge",
             "check the poses and their sigmas (--prior-sigma)");

  PoseRefinementResult result;
  result.rejected_edges = scans.rejected_edges;
  result.poses = CorrectPoses(poses, scans, graph);
  const std::vector<std::size_t>& frames = scans.frames;
  for (std::size_t n = 0; n < frames.size(); ++n) {
    const Rigid3d& refined = result.poses.world_from_cam[frames[n]];
    const Rigid3d& given = poses.world_from_cam[frames[n]];
    const double moved = (refined.translation - given.translation).norm();
    result.mean_correction += moved / frames.size();
    result.max_correction = std::max(result.max_correction, moved);
    result.mean_correction_deg +=
        Angle(refined.rotation.conjugate() * given.rotation) / kDegree / frames.size();
  }
  result.scans = static_cast<int>(frames.size());
  result.edges = static_cast<int>(scans.edges.size());
  return result;
}

}  // namespace planeloc
