// The tracker on real KITTI frames (issue 5 acceptance): raw drive 0001 (108 grey frames, no GT)
// for tracking health, and 7 colour frames of drive 0023 with OXTS ground truth for accuracy.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "planeloc/io/trajectory.h"
#include "planeloc/tracking/run_sequence.h"
#include "planeloc/util/temp_dir.h"
#include "planeloc/util/test_data.h"

namespace planeloc {
namespace {

RunOptions QuietRun(const std::filesystem::path& sequence, const TempDir& dir) {
  RunOptions run;
  run.sequence = sequence;
  run.trajectory_path = dir.path() / "traj.txt";
  run.stats_path = dir.path() / "stats.jsonl";
  run.deterministic = true;
  run.show_progress = false;
  return run;
}

TEST(TrackerRealTest, Drive0001TracksEveryFrameWithAPlausiblePath) {
  PLANELOC_SHARED_DATA_OR_SKIP(drive, "kitti-raw-2011_09_26_drive_0001");
  TempDir dir;
  const RunSummary summary = RunSequence(QuietRun(drive, dir));
  ASSERT_EQ(summary.frames, 108);
  EXPECT_EQ(summary.lost, 0);
  EXPECT_EQ(summary.tracked, 108);
  EXPECT_GE(summary.mean_tracked_points, 300.0);
  EXPECT_GT(summary.keyframes, 3);
  EXPECT_GT(summary.median_ba_reprojection_px, 0.0);
  EXPECT_LT(summary.median_ba_reprojection_px, 1.0);

  // Plausible path: speed below 20 m/s, no jump (frame-to-frame speed change < 1 m/s per 0.1 s).
  const Trajectory written = ReadKittiTrajectory(dir.path() / "traj.txt");
  ASSERT_EQ(written.size(), 108u);
  double previous_step = -1, length = 0;
  for (std::size_t i = 1; i < written.size(); ++i) {
    const double step =
        (written.world_from_cam[i].translation - written.world_from_cam[i - 1].translation).norm();
    length += step;
    EXPECT_LT(step / 0.1, 20.0) << "frame " << i;
    if (previous_step >= 0) {
      EXPECT_LT(std::abs(step - previous_step), 0.1) << "frame " << i;
    }
    previous_step = step;
  }
  EXPECT_GT(length, 5.0);  // the car drives (about 1 m/frame... well above a static estimate)

  // One stats line per frame, and the effective settings next to the trajectory.
  std::ifstream stats(dir.path() / "stats.jsonl");
  int lines = 0;
  for (std::string line; std::getline(stats, line);) {
    EXPECT_NE(line.find("\"state\":\"tracking\""), std::string::npos) << line;
    ++lines;
  }
  EXPECT_EQ(lines, 108);
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "traj.txt.config.yaml"));
}

TEST(TrackerRealTest, Drive0023ColourRelativeTranslationErrorBelowTwoPercent) {
  PLANELOC_SHARED_DATA_OR_SKIP(drive, "kitti-raw-2011_09_26_drive_0023-7frames");
  TempDir dir;
  RunOptions run = QuietRun(drive, dir);
  run.cameras = CameraChoice::kColor;
  const Trajectory gt = ReadKittiTrajectory(drive / "poses_cam02.txt");
  ASSERT_EQ(gt.size(), 7u);
  run.world_from_cam_initial = gt.world_from_cam[0];  // estimate in the GT frame
  const RunSummary summary = RunSequence(run);
  ASSERT_EQ(summary.frames, 7);
  EXPECT_EQ(summary.lost, 0);
  const double distance = gt.PathLength();
  ASSERT_GT(distance, 5.0);
  const Rigid3d gt_rel = gt.world_from_cam[0].Inverse() * gt.world_from_cam[6];
  const Rigid3d est_rel = summary.world_from_cam[0].Inverse() * summary.world_from_cam[6];
  const double error = (gt_rel.translation - est_rel.translation).norm();
  EXPECT_LT(error / distance, 0.02) << "error " << error << " m over " << distance << " m";
}

}  // namespace
}  // namespace planeloc
