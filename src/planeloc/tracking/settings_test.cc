#include "planeloc/tracking/settings.h"

#include <gtest/gtest.h>

#include <fstream>

#include "planeloc/sim/simulator.h"
#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc {
namespace {

// The simulator's camera: KITTI odometry sequences 04-12.
StereoCamera TestCamera() { return sim::Kitti07Camera(); }

std::filesystem::path WriteFile(const TempDir& dir, const std::string& text) {
  const auto path = dir.path() / "settings.yaml";
  std::ofstream(path) << text;
  return path;
}

// The head of ORB-SLAM2's Examples/Stereo/KITTI04-12.yaml, as users have it.
constexpr const char* kOrbSlamKitti = R"(%YAML:1.0

# Camera Parameters
Camera.fx: 707.0912
Camera.fy: 707.0912
Camera.cx: 601.8873
Camera.cy: 183.1104
Camera.k1: 0.0
Camera.k2: 0.0
Camera.width: 1241
Camera.height: 376
Camera.fps: 10.0
Camera.bf: 379.8145
Camera.RGB: 1
ThDepth: 35
ORBextractor.nFeatures: 2000
ORBextractor.scaleFactor: 1.2
ORBextractor.nLevels: 8
ORBextractor.iniThFAST: 12
ORBextractor.minThFAST: 7
Viewer.KeyFrameSize: 0.6
Viewer.ViewpointF: 2000
)";

TEST(SettingsTest, ReadsOrbSlam2KittiFile) {
  TempDir dir;
  const SettingsFile file =
      LoadTrackerSettings(WriteFile(dir, kOrbSlamKitti), TrackerOptions{}, TestCamera());
  EXPECT_DOUBLE_EQ(file.options.close_depth_baselines, 35.0);
  EXPECT_EQ(file.options.orb.initial_fast_threshold, 12);
  EXPECT_EQ(file.options.orb.num_features, 2000);
  EXPECT_DOUBLE_EQ(file.options.fps, 10.0);
  // Distortion, image size, RGB and viewer keys are known and silently ignored; the camera
  // matches the calibration.
  EXPECT_TRUE(file.warnings.empty()) << file.warnings.front();
}

TEST(SettingsTest, WarnsAboutUnknownKeysAndCameraMismatch) {
  TempDir dir;
  const SettingsFile file = LoadTrackerSettings(
      WriteFile(dir, "Camera.fx: 718.856\nTracking.bogus: 3\n"), TrackerOptions{}, TestCamera());
  ASSERT_EQ(file.warnings.size(), 2u);
  EXPECT_NE(file.warnings[0].find("Camera.fx"), std::string::npos);
  EXPECT_NE(file.warnings[1].find("Tracking.bogus"), std::string::npos);
}

TEST(SettingsTest, ReportsAllMistypedKeysTogether) {
  TempDir dir;
  const auto path =
      WriteFile(dir, "ORBextractor.nFeatures: many\nThDepth: [1, 2]\nORBextractor.nLevels: 2.5\n");
  try {
    LoadTrackerSettings(path, TrackerOptions{}, TestCamera());
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("ORBextractor.nFeatures must be an integer"), std::string::npos);
    EXPECT_NE(message.find("ThDepth must be a number"), std::string::npos);
    EXPECT_NE(message.find("ORBextractor.nLevels must be an integer"), std::string::npos);
    EXPECT_EQ(e.path(), path.string());
  }
}

TEST(SettingsTest, RejectsInvalidValues) {
  TempDir dir;
  EXPECT_THROW(
      LoadTrackerSettings(WriteFile(dir, "Camera.fps: -1\n"), TrackerOptions{}, TestCamera()),
      InputError);
  EXPECT_THROW(LoadTrackerSettings(dir.path() / "missing.yaml", TrackerOptions{}), InputError);
}

TEST(SettingsTest, EffectiveSettingsReadBack) {
  TempDir dir;
  TrackerOptions options;
  options.orb.num_features = 1234;
  options.ba_window_keyframes = 7;
  options.deterministic = true;
  options.min_found_ratio = 0.3;
  const auto path = dir.path() / "effective.yaml";
  WriteTrackerSettings(path, options, TestCamera());
  const SettingsFile file = LoadTrackerSettings(path, TrackerOptions{}, TestCamera());
  EXPECT_TRUE(file.warnings.empty());
  EXPECT_EQ(file.options.orb.num_features, 1234);
  EXPECT_EQ(file.options.ba_window_keyframes, 7);
  EXPECT_TRUE(file.options.deterministic);
  EXPECT_DOUBLE_EQ(file.options.min_found_ratio, 0.3);
}

TEST(SettingsTest, CheckNamesTheField) {
  TrackerOptions options;
  options.ba_window_keyframes = 0;
  try {
    options.Check();
    FAIL();
  } catch (const OptionsError& e) {
    EXPECT_NE(std::string(e.what()).find("ba_window_keyframes"), std::string::npos);
  }
}

}  // namespace
}  // namespace planeloc
