// Issue 4's accuracy acceptance on the simulator's town: map from the simulated scans with the GT
// poses, planes extracted, compared with world/planes_gt.json.
#include <gtest/gtest.h>
#include <spdlog/spdlog.h>

#include <cmath>

#include "planeloc/io/kitti_sequence.h"
#include "planeloc/io/plane_map.h"
#include "planeloc/io/trajectory.h"
#include "planeloc/map/map_builder.h"
#include "planeloc/map/plane_extraction.h"
#include "planeloc/map/plane_map_eval.h"
#include "planeloc/map/tensor_voting.h"
#include "planeloc/sim/simulator.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc {
namespace {

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
  // The map's header says what the build read (issue 37): 4 scans, none empty or damaged.
  const auto counts = MapBuildCountsFromComments(map.comments);
  ASSERT_TRUE(counts.has_value());
  EXPECT_EQ((*counts)["frames"], 4);
  EXPECT_EQ((*counts)["scans"], 4);
  EXPECT_EQ((*counts)["missing_scans"], 0);
  EXPECT_EQ((*counts)["empty_scans"], 0);
  EXPECT_EQ((*counts)["non_finite_points"], 0);
  EXPECT_EQ((*counts)["map_points"], map.size());
  EXPECT_GT((*counts)["scan_points"].get<std::size_t>(),
            (*counts)["out_of_range_points"].get<std::size_t>() + map.size());
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
  PlaneMapEvalOptions eval_options;
  eval_options.point_area = build.voxel_size * build.voxel_size;
  const PlaneMapEvaluation evaluation =
      EvaluatePlaneMap(map.points, result.point_plane, result.plane_map, gt, eval_options);
  for (const GtPlaneMatch& m : evaluation.checked) {
    EXPECT_TRUE(m.good) << "GT plane " << m.gt_id << " (" << m.kind << ", " << m.visible_area
                        << " m^2): extracted " << m.extracted_id << ", angle " << m.angle_deg
                        << " deg, offset " << m.offset << " m";
    EXPECT_GT(m.support, 0.5) << "GT plane " << m.gt_id;
  }
  EXPECT_GE(evaluation.checked.size(), 2u);  // road and the near facade in the first frames
  ASSERT_GT(evaluation.labelled_points, 1000u);
  EXPECT_GE(evaluation.labelled_on_gt, 0.95);
}

}  // namespace
}  // namespace planeloc
