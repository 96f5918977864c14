#include "planeloc/pipeline/run_checks.h"

#include <gtest/gtest.h>

#include <vector>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

// Frames at 10 Hz; no images (the checks only read timestamps).
class TimestampsOnly : public StereoSource {
 public:
  std::string name() const override { return "frames"; }
  std::size_t size() const override { return 100; }
  const StereoCamera& camera() const override { return camera_; }
  double timestamp(std::size_t index) const override { return 0.1 * static_cast<double>(index); }
  StereoPair LoadStereoPair(std::size_t) const override { return {}; }

 private:
  StereoCamera camera_;
};

Rigid3d AtForward(double metres) {
  return Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, metres));
}

// Feeds frames 0..n at `speed` m/s; returns the frame whose Add threw (or -1).
int FirstThrowingFrame(CalibrationSpeedCheck& check, double speed, int n) {
  const TimestampsOnly frames;
  for (int i = 0; i <= n; ++i) {
    try {
      check.Add(frames, i, AtForward(speed * frames.timestamp(i)));
    } catch (const InputError& error) {
      EXPECT_EQ(error.path(), "calib.txt");
      EXPECT_NE(error.problem().find("baseline"), std::string::npos) << error.problem();
      return i;
    }
  }
  return -1;
}

TEST(CalibrationSpeedCheckTest, ACarAt300KmPerHourPasses) {
  CalibrationSpeedCheck check("calib.txt");
  EXPECT_EQ(FirstThrowingFrame(check, 83.0, 40), -1);
}

TEST(CalibrationSpeedCheckTest, ABaselineTooLargeIsNamedAfterHalfASecond) {
  // 10 m/s with bf x 100: 1 km/s. Frame 5 is 0.5 s after frame 0: the first frame judged.
  CalibrationSpeedCheck check("calib.txt");
  EXPECT_EQ(FirstThrowingFrame(check, 1000.0, 40), 5);
}

TEST(CalibrationSpeedCheckTest, JudgesOnlyTheFirstHalfSecond) {
  // A jump after the window (a relocalization, say) is not the calibration's doing.
  const TimestampsOnly frames;
  CalibrationSpeedCheck check("calib.txt");
  for (int i = 0; i <= 5; ++i) check.Add(frames, i, AtForward(1.0 * frames.timestamp(i)));
  EXPECT_NO_THROW(check.Add(frames, 6, AtForward(500.0)));
}

FrameStats Tracked(int frame, bool refined) {
  FrameStats stats;
  stats.frame = frame;
  if (refined) stats.depth_points = 200;
  return stats;
}

TEST(MapCloudCoverageCheckTest, WarnsWhenFewerThanHalfTheFramesWereRefined) {
  MapCloudCoverageCheck check("map.pcd", /*by_windows=*/false);
  // Frame 0 is the start (never refined) and lost frames do not count: 20 tracked frames, 9
  // refined.
  check.Add(Tracked(0, false));
  FrameStats lost = Tracked(1, false);
  lost.state = TrackingState::kLost;
  check.Add(lost);
  for (int i = 2; i < 2 + MapCloudCoverageCheck::kFrames - 1; ++i) check.Add(Tracked(i, i < 11));
  EXPECT_FALSE(check.warned());  // 19 tracked frames: not judged yet
  check.Add(Tracked(21, false));
  EXPECT_TRUE(check.warned());
}

TEST(MapCloudCoverageCheckTest, HalfTheFramesRefinedIsEnough) {
  MapCloudCoverageCheck check("map.pcd", /*by_windows=*/false);
  for (int i = 1; i <= MapCloudCoverageCheck::kFrames; ++i) check.Add(Tracked(i, i % 2 == 0));
  EXPECT_FALSE(check.warned());
}

TEST(MapCloudCoverageCheckTest, WithoutFrameRefinementCountsTheWindowsWithPatches) {
  // Frames are never refined then: only the BA windows with patch residuals are evidence.
  MapCloudCoverageCheck used("map.pcd", /*by_windows=*/true);
  MapCloudCoverageCheck unused("map.pcd", /*by_windows=*/true);
  for (int i = 1; i <= MapCloudCoverageCheck::kFrames; ++i) {
    FrameStats stats = Tracked(i, false);
    if (i % 4 == 0) stats.ba_keyframe = i;
    FrameStats with_patches = stats;
    if (stats.ba_keyframe) with_patches.ba_plane_residuals = 150;
    used.Add(with_patches);
    unused.Add(stats);
  }
  EXPECT_FALSE(used.warned());
  EXPECT_TRUE(unused.warned());
}

}  // namespace
}  // namespace planeloc
