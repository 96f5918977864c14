// Issue 10, "a map that can be wrong", end to end on the simulator's `tiny` preset: the drive
// localized in its own LiDAR plane map with its main road plane and main facade moved by 0.2 m
// along their normal. The moved planes' points sit off them, so they get disabled, and the ATE
// stays near the clean map's and below visual odometry's.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>

#include "planeloc/io/kitti_sequence.h"
#include "planeloc/io/map_updates.h"
#include "planeloc/io/plane_map.h"
#include "planeloc/io/trajectory.h"
#include "planeloc/map/map_builder.h"
#include "planeloc/map/map_planes.h"
#include "planeloc/pipeline/run_sequence.h"
#include "planeloc/pipeline/tiny_drive_for_test.h"
#include "planeloc/sim/simulator.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc {
namespace {

// Moves the ground plane and the facade with the most LiDAR inliers (the planes the drive leans
// on most: the worst case of a wrong map) by `offset` metres along their normal, outline and
// centroid with them. Returns the moved ids.
std::vector<int> MoveLargestPlanes(PlaneMap& map, double offset) {
  std::vector<int> moved;
  for (const char* kind : {"ground", "facade"}) {
    MapPlane* largest = nullptr;
    for (MapPlane& plane : map.planes) {
      if (plane.kind == kind && (!largest || plane.inliers > largest->inliers)) largest = &plane;
    }
    if (!largest) continue;
    const Eigen::Vector3d move = offset * largest->plane_in_map.normal;
    largest->plane_in_map.d -= offset;
    largest->centroid += move;
    for (Eigen::Vector3d& p : largest->polygon) p += move;
    moved.push_back(largest->id);
  }
  return moved;
}

double Ate(const RunSummary& summary, const std::vector<Rigid3d>& gt) {
  double sum2 = 0;
  for (int i = 0; i < summary.frames; ++i) {
    sum2 += (summary.world_from_cam[i].translation - gt[i].translation).squaredNorm();
  }
  return std::sqrt(sum2 / summary.frames);
}

TEST(WrongMapSimTest, MovedPlanesAreDisabledAndTheAteStaysNearTheCleanMaps) {
  TempDir dir("planeloc-wrong-map-sim");
  const sim::SimResult& sim = testing::SharedTinySim();
  const PlaneMap& clean = testing::SharedTinyPlanes();
  PlaneMap moved_map = clean;
  const std::vector<int> moved = MoveLargestPlanes(moved_map, 0.2);
  ASSERT_EQ(moved.size(), 2u);
  WritePlaneMap(dir.path() / "clean.json", clean);
  WritePlaneMap(dir.path() / "moved.json", moved_map);

  auto run = [&](const std::string& name, std::optional<std::filesystem::path> planes) {
    RunOptions options;
    options.sequence = sim.sequence_dir;
    options.trajectory_path = dir.path() / (name + ".txt");
    options.deterministic = true;
    options.show_progress = false;
    options.world_from_cam_initial = sim.world_from_cam.front();
    options.planes_path = planes;
    if (planes) options.map_update_path = dir.path() / (name + "_updates.json");
    return RunSequence(options);
  };
  const RunSummary visual = run("visual", std::nullopt);
  const RunSummary with_clean = run("clean", dir.path() / "clean.json");
  const RunSummary with_moved = run("moved", dir.path() / "moved.json");
  const double ate_visual = Ate(visual, sim.world_from_cam);
  const double ate_clean = Ate(with_clean, sim.world_from_cam);
  const double ate_moved = Ate(with_moved, sim.world_from_cam);
  std::cout << "ATE RMSE visual " << ate_visual << " m, clean map " << ate_clean
            << " m, moved planes " << ate_moved << " m; planes disabled: clean "
            << with_clean.planes_disabled << ", moved " << with_moved.planes_disabled << " of "
            << moved.size() << " moved\n";
  EXPECT_EQ(with_moved.tracked, with_moved.frames);
  // Measured at 732d692's defaults (same numbers from `planeloc run --deterministic` on
  // `planeloc sim --preset tiny --seed 1`, map build --voxel 0.10, map planes): ATE visual
  // 0.0842 m, clean map 0.0454 m, moved planes 0.0646 m; the two moved planes disabled (plane 0
  // at -0.180 m, plane 1 at -0.154 m), one plane (+0.106 m) with the clean map. At 3499e9c
  // (Planes.trajectoryConsensus on, `planeloc_tracking_test --gtest_filter=WrongMap*`): visual
  // 0.0842 m, clean 0.0443 m, moved 0.0480 m; 2 planes disabled with the moved map, 1 with the
  // clean one. At 88c0d72 (fixed 15 cm band, no bias statistics) the same moved map gave
  // 0.234 m, the clean 0.0416 m.
  EXPECT_GE(with_moved.planes_disabled, 2);
  EXPECT_LT(ate_moved, ate_visual);
  EXPECT_LT(ate_moved, 0.09);
  // The clean map is the reference the moved one is judged against: it must itself work.
  // Measured 2026-12-04 (this test): clean 0.0443 m against visual 0.0842 m, all frames tracked.
  EXPECT_EQ(with_clean.tracked, with_clean.frames);
  EXPECT_LT(ate_clean, 0.07);
  EXPECT_LT(ate_clean, 0.7 * ate_visual);
  EXPECT_LT(ate_moved, 1.6 * ate_clean);  // 0.0480 / 0.0443 = 1.08 measured

  // What the runs report about the planes (run --map-update, issue 32): the moved planes' points
  // sit 0.2 m behind them (the map moved them by +0.2 m along n), measured although the run
  // disabled them. Measured 2026-12-05 (`planeloc_pipeline_test --gtest_filter=WrongMap*`): moved
  // planes corrected by -0.199 +- 0.030 m (2507 points) and -0.161 +- 0.034 m (253 points); on
  // the clean map 5 planes confirmed, 2 corrected. Measured 2026-12-07 after the map update took
  // the bias statistics' witness rule (a facade's foot measures no road): moved planes -0.195 m
  // (2163 points) and -0.169 m (261 points), no other plane corrected (before: one more); clean
  // map 7 confirmed, 0 corrected (before: 6 and 1).
  const MapUpdates moved_updates = ReadMapUpdates(dir.path() / "moved_updates.json");
  EXPECT_EQ(moved_updates.planes_hash, FileHash(dir.path() / "moved.json"));
  ASSERT_EQ(moved_updates.planes.size(), moved_map.planes.size());
  int unmoved_corrected = 0;
  for (const PlaneUpdate& update : moved_updates.planes) {
    if (std::find(moved.begin(), moved.end(), update.id) == moved.end()) {
      unmoved_corrected += update.status == PlaneUpdateStatus::kCorrected;
      continue;
    }
    std::cout << "moved plane " << update.id << ": " << ToString(update.status) << " offset "
              << update.offset << " +- " << update.offset_sigma << " m, " << update.points
              << " points, " << update.frames.size() << " keyframes\n";
    EXPECT_EQ(update.status, PlaneUpdateStatus::kCorrected) << update.id;
    EXPECT_NEAR(update.offset, -0.2, 0.06) << update.id;
    EXPECT_TRUE(update.disabled_at_frame.has_value()) << update.id;
  }
  EXPECT_LE(unmoved_corrected, 1);
  const MapUpdates clean_updates = ReadMapUpdates(dir.path() / "clean_updates.json");
  int clean_corrected = 0, clean_confirmed = 0;
  for (const PlaneUpdate& update : clean_updates.planes) {
    clean_corrected += update.status == PlaneUpdateStatus::kCorrected;
    clean_confirmed += update.status == PlaneUpdateStatus::kConfirmed;
  }
  std::cout << "clean map: " << clean_confirmed << " confirmed, " << clean_corrected
            << " corrected\n";
  EXPECT_LE(clean_corrected, 1);
  EXPECT_GE(clean_confirmed, 4);
}

}  // namespace
}  // namespace planeloc
