// Issue 4's accuracy acceptance on the simulator's town: map from the simulated scans with the GT
// poses, planes extracted, compared with world/planes_gt.json.
#include <gtest/gtest.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <numbers>

#include "planeloc/io/kitti_sequence.h"
#include "planeloc/io/plane_map.h"
#include "planeloc/io/trajectory.h"
#include "planeloc/map/map_builder.h"
#include "planeloc/map/plane_extraction.h"
#include "planeloc/map/tensor_voting.h"
#include "planeloc/sim/simulator.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc {
namespace {

// In-plane basis of a GT plane.
std::pair<Eigen::Vector3d, Eigen::Vector3d> Basis(const Eigen::Vector3d& n) {
  const Eigen::Vector3d helper =
      std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d u = n.cross(helper).normalized();
  return {u, n.cross(u)};
}

// Crossing-number test of p (on the plane) against the GT polygon.
bool InsidePolygon(const MapPlane& gt, const Eigen::Vector3d& p) {
  if (gt.polygon.size() < 3) return true;  // no outline given: the whole plane
  const auto [u, v] = Basis(gt.plane_in_map.normal);
  const Eigen::Vector2d q(p.dot(u), p.dot(v));
  bool inside = false;
  for (std::size_t i = 0, j = gt.polygon.size() - 1; i < gt.polygon.size(); j = i++) {
    const Eigen::Vector2d a(gt.polygon[i].dot(u), gt.polygon[i].dot(v));
    const Eigen::Vector2d b(gt.polygon[j].dot(u), gt.polygon[j].dot(v));
    if ((a.y() > q.y()) != (b.y() > q.y()) &&
        q.x() < (b.x() - a.x()) * (q.y() - a.y()) / (b.y() - a.y()) + a.x()) {
      inside = !inside;
    }
  }
  return inside;
}

// Fraction of `points` within 10 cm of some GT plane.
double FractionOnGt(const std::vector<Eigen::Vector3d>& points, const PlaneMap& gt) {
  std::size_t near = 0;
  for (const auto& p : points) {
    for (const MapPlane& g : gt.planes) {
      if (std::abs(g.plane_in_map.SignedDistance(p)) < 0.10) {
        ++near;
        break;
      }
    }
  }
  return points.empty() ? 0.0 : static_cast<double>(near) / static_cast<double>(points.size());
}

TEST(MapSimTest, TinyTownPlanesMatchGroundTruth) {
  TempDir dir("planeloc-map-sim");
  sim::SimOptions sim_options = sim::SimOptions::FromPreset("tiny");
  sim_options.frames = 4;  // the first 0.4 s of the tiny drive keep the test fast
  sim_options.show_progress = false;
  const char* keep = std::getenv("PLANELOC_MAP_SIM_DEBUG");
  const sim::SimResult sim =
      sim::GenerateSequence(sim_options, keep ? std::filesystem::path(keep) : dir.path(), true);
  const PlaneMap gt = ReadPlaneMap(sim.planes_path);
  const KittiSequence sequence = KittiSequence::Open(sim.sequence_dir);
  const Trajectory poses = ReadKittiTrajectory(sim.poses_path);
  MapBuildOptions build;
  build.show_progress = false;
  build.max_range = 25.0;  // a small map: the test checks accuracy, the benchmark speed
  const PointCloud map = BuildMap(build, sequence, poses);
  // Scans, Tr and poses must agree with the GT (the simulator once scanned with the inverse of
  // its own Tr; this catches that before the plane checks).
  ASSERT_GT(FractionOnGt(map.points, gt), 0.5) << "simulated scans disagree with planes_gt.json";
  const TensorVotingResult voting = RunTensorVoting(map.points, TensorVotingOptions());
  const PlaneExtractionResult result = ExtractPlanes(map.points, voting, PlaneExtractionOptions());
  if (keep) {
    for (const auto& g : gt.planes) {
      spdlog::info("gt {} {} n {} {} {} d {} area {}", g.id, g.kind, g.plane_in_map.normal.x(),
                   g.plane_in_map.normal.y(), g.plane_in_map.normal.z(), g.plane_in_map.d, g.area);
    }
    for (const auto& g : result.plane_map.planes) {
      spdlog::info("est {} {} n {} {} {} d {} area {} inl {}", g.id, g.kind,
                   g.plane_in_map.normal.x(), g.plane_in_map.normal.y(), g.plane_in_map.normal.z(),
                   g.plane_in_map.d, g.area, g.inliers);
    }
  }
  int checked = 0;
  for (const MapPlane& g : gt.planes) {
    if (g.kind != "ground" && g.kind != "facade") continue;
    // Visible area: map points on the GT rectangle, each standing for one voxel face.
    int on_plane = 0;
    for (const auto& p : map.points) {
      on_plane += std::abs(g.plane_in_map.SignedDistance(p)) < 0.05 && InsidePolygon(g, p);
    }
    if (on_plane * build.voxel_size * build.voxel_size < 20.0) continue;
    ++checked;
    double best_angle = 180.0, best_offset = 1e9;
    for (const MapPlane& p : result.plane_map.planes) {
      const double angle = p.plane_in_map.AngleTo(g.plane_in_map) * 180.0 / std::numbers::pi;
      const double offset = std::abs(g.plane_in_map.SignedDistance(p.centroid));
      if (angle < 1.0 && offset < best_offset) {
        best_angle = angle;
        best_offset = offset;
      }
    }
    EXPECT_LT(best_angle, 1.0) << "GT plane " << g.id << " (" << g.kind << ") unmatched";
    EXPECT_LT(best_offset, 0.05) << "GT plane " << g.id << " (" << g.kind << ")";
  }
  EXPECT_GE(checked, 2);  // road and the near facade in the first frames
  std::vector<Eigen::Vector3d> labelled;
  for (std::size_t i = 0; i < map.size(); ++i) {
    if (result.point_plane[i] >= 0) labelled.push_back(map.points[i]);
  }
  ASSERT_FALSE(labelled.empty());
  EXPECT_GE(FractionOnGt(labelled, gt), 0.95);
}

}  // namespace
}  // namespace planeloc
