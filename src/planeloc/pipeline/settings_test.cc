#include "planeloc/pipeline/settings.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "planeloc/pipeline/settings_fixtures_for_test.h"
#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc::settings_test {
namespace {

TEST(SettingsTest, ReadsOrbSlam2Layout) {
  TempDir dir;
  const SettingsFile file =
      LoadTrackerSettings(WriteFile(dir, kOrbSlam2), TrackerOptions{}, TestCamera());
  ExpectFixtureOptions(file);
  ASSERT_TRUE(file.camera.has_value());
  EXPECT_EQ(file.camera->layout, "ORB-SLAM2");
  EXPECT_DOUBLE_EQ(file.camera->fx, 707.0912);
  EXPECT_DOUBLE_EQ(file.camera->cy, 183.1104);
  EXPECT_DOUBLE_EQ(file.camera->baseline, 379.708 / 707.0912);
  EXPECT_EQ(file.camera->baseline_key, "Camera.bf");
  EXPECT_EQ(file.camera->width, 1226);
  EXPECT_EQ(file.camera->line, 7);
  EXPECT_TRUE(file.warnings.empty()) << file.warnings.front();
  EXPECT_EQ(file.ignored,
            (std::vector<std::string>{"Camera.k1", "Camera.k2", "Camera.p1", "Camera.p2",
                                      "Camera.bFishEye", "Camera.RGB", "Viewer.KeyFrameSize",
                                      "Viewer.PointSize", "Viewer.ViewpointY"}));
}

TEST(SettingsTest, ReadsOrbSlam3RectifiedLayout) {
  TempDir dir;
  const SettingsFile file =
      LoadTrackerSettings(WriteFile(dir, kOrbSlam3Rectified), TrackerOptions{}, TestCamera());
  ExpectFixtureOptions(file);
  ASSERT_TRUE(file.camera.has_value());
  EXPECT_EQ(file.camera->layout, "ORB-SLAM3");
  EXPECT_EQ(file.camera->fx_key, "Camera1.fx");
  EXPECT_DOUBLE_EQ(file.camera->cx, 601.8873);
  EXPECT_EQ(file.camera->baseline, 0.537);
  EXPECT_EQ(file.camera->baseline_key, "Stereo.b");
  EXPECT_TRUE(file.warnings.empty()) << file.warnings.front();
  EXPECT_EQ(file.ignored,
            (std::vector<std::string>{"Camera.RGB", "Viewer.KeyFrameSize", "Viewer.PointSize",
                                      "Viewer.imageViewScale", "System.thFarPoints"}));
}

TEST(SettingsTest, ReadsOrbSlam3PinHolePairThatIsRectified) {
  TempDir dir;
  const SettingsFile file =
      LoadTrackerSettings(WriteFile(dir, kOrbSlam3PinHole), TrackerOptions{}, TestCamera());
  ExpectFixtureOptions(file);
  ASSERT_TRUE(file.camera.has_value());
  EXPECT_EQ(file.camera->baseline, 0.537);
  EXPECT_EQ(file.camera->baseline_key, "Stereo.T_c1_c2");
  EXPECT_TRUE(file.warnings.empty()) << file.warnings.front();
}

TEST(SettingsTest, ReadsPlanelocKeysWithoutHeaderNestedMapsAndFlags) {
  TempDir dir;
  const SettingsFile plain =
      LoadTrackerSettings(WriteFile(dir, kPlanelocKeys), TrackerOptions{}, TestCamera());
  ExpectFixtureOptions(plain);
  EXPECT_FALSE(plain.camera.has_value());
  EXPECT_TRUE(plain.warnings.empty());

  const SettingsFile nested = LoadTrackerSettings(
      WriteFile(dir,
                "# planeloc keys as nested maps\nTracking:\n  minMotionMatches: 25\n"
                "System:\n  deterministic: true\n  threads: 3\n"
                "Mapping.triangulateWithNeighbours: 1\n"),
      TrackerOptions{});
  EXPECT_EQ(nested.options.min_motion_matches, 25);
  EXPECT_TRUE(nested.options.deterministic);
  EXPECT_EQ(nested.options.num_threads, 3);
  EXPECT_TRUE(nested.options.triangulate_with_neighbours);

  // Map-lock keys reach the locker's options (nested registration thresholds included).
  const SettingsFile lock = LoadTrackerSettings(
      WriteFile(dir,
                "%YAML:1.0\nMapLock.settleKeyframes: 12\nMapLock.maxTiltSigmaDeg: 0.8\n"
                "MapLock.mapSigma: 0.01\nMapLock.outlineMargin: 0.1\n"),
      TrackerOptions{});
  EXPECT_EQ(lock.options.map_lock.settle_keyframes, 12);
  EXPECT_DOUBLE_EQ(lock.options.map_lock.registration.max_tilt_sigma_deg, 0.8);
  EXPECT_DOUBLE_EQ(lock.options.map_lock.registration.map_sigma, 0.01);
  EXPECT_DOUBLE_EQ(lock.options.map_lock.registration.outline_margin, 0.1);
  EXPECT_THROW(LoadTrackerSettings(WriteFile(dir, "%YAML:1.0\nMapLock.settleKeyframes: -1\n"),
                                   TrackerOptions{}),
               InputError);
  EXPECT_THROW(LoadTrackerSettings(WriteFile(dir, "%YAML:1.0\nMapLock.outlineMargin: 0\n"),
                                   TrackerOptions{}),
               InputError);

  const SettingsFile empty = LoadTrackerSettings(WriteFile(dir, "%YAML:1.0\n# nothing\n"), {});
  EXPECT_EQ(empty.options.orb.num_features, TrackerOptions{}.orb.num_features);
}

TEST(SettingsTest, ReadsWindowsLineEndingsAndAHeaderAfterComments) {
  TempDir dir;
  std::string crlf;
  for (const char* c = kOrbSlam2; *c; ++c)
    crlf += *c == '\n' ? std::string("\r\n") : std::string(1, *c);
  const SettingsFile windows = LoadTrackerSettings(WriteFile(dir, crlf), TrackerOptions{});
  ExpectFixtureOptions(windows);
  ASSERT_TRUE(windows.camera.has_value());
  EXPECT_EQ(windows.camera->line, 7);

  const SettingsFile late = LoadTrackerSettings(
      WriteFile(dir, "\n# settings\n%YAML:1.0\nThDepth: 35\nbogus: 1\n"), TrackerOptions{});
  EXPECT_DOUBLE_EQ(late.options.close_depth_baselines, 35.0);
  ASSERT_EQ(late.warnings.size(), 1u);
  EXPECT_NE(late.warnings[0].find("line 5: unknown key bogus"), std::string::npos);
}

TEST(SettingsTest, WarnsAboutUnknownKeysWithTheirLine) {
  TempDir dir;
  const SettingsFile file = LoadTrackerSettings(
      WriteFile(dir, "%YAML:1.0\nThDepth: 35\n\nTracking.bogus: 3\nfoo:\n  bar: 1\n"),
      TrackerOptions{});
  ASSERT_EQ(file.warnings.size(), 2u);
  EXPECT_NE(file.warnings[0].find("line 4: unknown key Tracking.bogus"), std::string::npos)
      << file.warnings[0];
  EXPECT_NE(file.warnings[1].find("line 6: unknown key foo.bar"), std::string::npos)
      << file.warnings[1];
}

TEST(SettingsTest, WarnsAboutRepeatedKeysAndAliases) {
  TempDir dir;
  const SettingsFile file = LoadTrackerSettings(
      WriteFile(dir, "ThDepth: 30\nStereo.ThDepth: 36\nCamera.fps: 5\nCamera.fps: 12\n"),
      TrackerOptions{});
  EXPECT_DOUBLE_EQ(file.options.close_depth_baselines, 36.0);
  EXPECT_DOUBLE_EQ(file.options.fps, 12.0);
  EXPECT_TRUE(Contains(file.warnings, "Stereo.ThDepth and ThDepth (line 1) are the same setting"));
  EXPECT_TRUE(Contains(file.warnings, "line 4: Camera.fps is given more than once"));
}

TEST(SettingsTest, ReportsAllMistypedKeysTogetherWithLineValueAndExpectedForm) {
  TempDir dir;
  const auto path = WriteFile(dir,
                              "%YAML:1.0\nORBextractor.nFeatures: many\nThDepth: [1, 2]\n"
                              "ORBextractor.nLevels: 2.5\nCamera.fps: \"ten\"\n"
                              "System.deterministic: maybe\n");
  try {
    LoadTrackerSettings(path, TrackerOptions{}, TestCamera());
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_EQ(e.path(), path.string());
    EXPECT_EQ(e.line(), 2);
    EXPECT_NE(message.find("line 2: ORBextractor.nFeatures = \"many\": expected an integer"),
              std::string::npos)
        << message;
    EXPECT_NE(message.find("line 3: ThDepth = [1, 2]: expected a number"), std::string::npos);
    EXPECT_NE(message.find("line 4: ORBextractor.nLevels = 2.5: expected an integer"),
              std::string::npos);
    EXPECT_NE(message.find("line 5: Camera.fps = \"ten\": expected a number"), std::string::npos);
    EXPECT_NE(
        message.find("line 6: System.deterministic = \"maybe\": expected 0, 1, true or false"),
        std::string::npos);
  }
}

TEST(SettingsTest, RejectsInvalidValuesNamingKeyAndRule) {
  TempDir dir;
  const std::string fps = Message([&] {
    LoadTrackerSettings(WriteFile(dir, "%YAML:1.0\n\nCamera.fps: -1\n"), TrackerOptions{});
  });
  EXPECT_NE(fps.find("settings.yaml:3:"), std::string::npos) << fps;
  EXPECT_NE(fps.find("Camera.fps = -1: expected a valid value"), std::string::npos) << fps;
  EXPECT_NE(fps.find("fps must be > 0"), std::string::npos) << fps;
  const std::string camera = Message([&] {
    LoadTrackerSettings(WriteFile(dir, "Camera1.fx: 700\nCamera1.fy: 700\nCamera1.cx: 600\n"),
                        TrackerOptions{});
  });
  EXPECT_NE(camera.find("Camera1.cy is missing"), std::string::npos) << camera;
  const std::string bf = Message([&] {
    LoadTrackerSettings(WriteFile(dir,
                                  "Camera.fx: 700\nCamera.fy: 700\nCamera.cx: 600\n"
                                  "Camera.cy: 180\nCamera.bf: -3\n"),
                        TrackerOptions{});
  });
  EXPECT_NE(bf.find("line 5: Camera.bf = -3"), std::string::npos) << bf;
  const std::string type = Message([&] {
    LoadTrackerSettings(
        WriteFile(dir, "File.version: \"1.0\"\nCamera.type: \"Pinhole\"\nCamera1.fx: 1\n"),
        TrackerOptions{});
  });
  EXPECT_NE(type.find("line 2: Camera.type = \"Pinhole\": expected \"Rectified\" or \"PinHole\""),
            std::string::npos)
      << type;
  EXPECT_THROW(LoadTrackerSettings(dir.path() / "missing.yaml", TrackerOptions{}), InputError);
}

// Fuzzing finding: a matrix node claiming a huge size made OpenCV allocate it (64 GiB) before
// anything checked it; the claimed size is now checked against the data first. In Release the
// old code also ended in this error (after an overcommitted allocation); under the sanitizers
// (scripts/test.sh --sanitize) the allocation itself aborted the test.
TEST(SettingsTest, MatrixClaimingAHugeSizeIsAnErrorNotAnAllocation) {
  TempDir dir;
  const std::string huge = std::string(kOrbSlam2) +
                           "LEFT.height: 480\nLEFT.width: 752\nLEFT.K: !!opencv-matrix\n"
                           "   rows: 100000\n   cols: 100000\n   dt: d\n"
                           "   data:[458.0, 0.0, 367.0, 0.0]\n";
  const std::string message =
      Message([&] { LoadTrackerSettings(WriteFile(dir, huge), TrackerOptions{}); });
  EXPECT_NE(message.find("LEFT.K"), std::string::npos) << message;
  EXPECT_NE(message.find("a 3x3 !!opencv-matrix"), std::string::npos) << message;
}

// Fuzzing finding (session 33): Camera.height 3700912 in a PinHole pair made the rectification
// maps 1226 x 3700912 x 2 floats (18 GB) before anything checked the size.
TEST(SettingsTest, ImageSideBeyondAnyCameraIsAnErrorNotAnAllocation) {
  TempDir dir;
  std::string huge = kOrbSlam3PinHole;
  huge.replace(huge.find("Camera.height: 370"), 18, "Camera.height: 3700912");
  const std::string message =
      Message([&] { LoadTrackerSettings(WriteFile(dir, huge), TrackerOptions{}); });
  EXPECT_NE(message.find("Camera.height"), std::string::npos) << message;
  EXPECT_NE(message.find("1 to 16384 pixels"), std::string::npos) << message;
}

// Found by the audit after CI's unreplayable settings_reader finding (session 35, fuzz finding 4
// in docs/reliability.md): LocalBA.windowKeyframesTurn 2147483647 made OdometryOptions::Check
// add it to LocalBA.maxFixedKeyframes in int (signed overflow, undefined; UBSan aborted). The sum
// is 64-bit now, and the window it asks for is larger than Mapping.keepKeyframes allows, which is
// the error the user gets.
TEST(SettingsTest, WindowSizeAtIntMaxIsAnErrorNotAnOverflow) {
  TempDir dir;
  const std::string message = Message([&] {
    LoadTrackerSettings(WriteFile(dir,
                                  "%YAML:1.0\nMapping.keepKeyframes: 500\n"
                                  "LocalBA.windowKeyframesTurn: 2147483647\n"
                                  "LocalBA.maxFixedKeyframes: 20\n"),
                        TrackerOptions{});
  });
  EXPECT_NE(message.find("LocalBA.windowKeyframesTurn = 2147483647"), std::string::npos) << message;
  EXPECT_NE(message.find("keep_keyframes"), std::string::npos) << message;
}

TEST(SettingsTest, SyntaxErrorNamesFileAndLine) {
  TempDir dir;
  const auto path =
      WriteFile(dir, "%YAML:1.0\nThDepth: 35\nORBextractor.nLevels: [8, 9\nCamera.fps: 10\n");
  try {
    LoadTrackerSettings(path, TrackerOptions{});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.path(), path.string());
    EXPECT_EQ(e.line(), 4);  // where OpenCV notices the unclosed sequence
    EXPECT_NE(std::string(e.what()).find("not a valid settings file"), std::string::npos);
  }
  // Without a header the line numbers are the file's too.
  try {
    LoadTrackerSettings(WriteFile(dir, "ThDepth: 35\n  nLevels: 3\n"), TrackerOptions{});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 2);
  }
  EXPECT_THROW(LoadTrackerSettings(WriteFile(dir, "- 1\n- 2\n"), TrackerOptions{}), InputError);
}

// Writes the effective settings, reads them back, writes again: the same text means the same
// value of every key (doubles are written in shortest round-trip form).
TEST(SettingsTest, EffectiveSettingsReadBackToTheSameValues) {
  TempDir dir;
  TrackerOptions options;
  options.orb.num_features = 1234;
  options.ba_window_keyframes = 7;
  options.deterministic = true;
  options.triangulate_with_neighbours = true;
  options.min_found_ratio = 0.1 + 0.2;  // 0.30000000000000004
  options.ba.plane_sigma = 1.0 / 3.0;
  options.close_depth_baselines = 1e-3 * 37123.456789;
  StereoCamera camera = TestCamera();
  camera.fx = 707.0912 + 1e-9;
  camera.baseline = 0.5371234567890123;
  const auto path = dir.path() / "effective.yaml";
  WriteTrackerSettings(path, options, camera, true);

  const SettingsFile file = LoadTrackerSettings(path, TrackerOptions{}, camera);
  EXPECT_TRUE(file.warnings.empty()) << file.warnings.front();
  EXPECT_TRUE(file.ignored.empty());
  EXPECT_TRUE(file.calibration_from_settings);
  EXPECT_EQ(file.options.orb.num_features, 1234);
  EXPECT_TRUE(file.options.deterministic);
  EXPECT_EQ(file.options.min_found_ratio, 0.1 + 0.2);
  EXPECT_EQ(file.options.ba.plane_sigma, 1.0 / 3.0);
  std::vector<std::string> warnings;
  const StereoCamera read_camera = ChooseCamera(camera, file.camera, true, path, &warnings);
  EXPECT_EQ(read_camera.fx, camera.fx);
  EXPECT_EQ(read_camera.baseline, camera.baseline);
  EXPECT_EQ(TrackerSettingsYaml(file.options, read_camera, file.calibration_from_settings),
            TrackerSettingsYaml(options, camera, true));

  // cv::FileStorage itself reads the file (as ORB-SLAM3 would).
  cv::FileStorage storage(path.string(), cv::FileStorage::READ);
  ASSERT_TRUE(storage.isOpened());
  EXPECT_EQ(storage["Camera.type"].string(), "Rectified");
  EXPECT_EQ(static_cast<double>(storage["Stereo.b"]), camera.baseline);
  EXPECT_EQ(static_cast<int>(storage["ORBextractor.nFeatures"]), 1234);
}

TEST(SettingsTest, EveryFixtureRoundTrips) {
  TempDir dir;
  for (const char* fixture : {kOrbSlam2, kOrbSlam3Rectified, kOrbSlam3PinHole, kPlanelocKeys}) {
    const SettingsFile file = LoadTrackerSettings(WriteFile(dir, fixture), TrackerOptions{});
    std::vector<std::string> warnings;
    const StereoCamera camera =
        ChooseCamera(TestCamera(), file.camera, file.camera.has_value(), "", &warnings);
    const std::string written = TrackerSettingsYaml(file.options, camera, file.camera.has_value());
    const SettingsFile again =
        LoadTrackerSettings(WriteFile(dir, written, "again.yaml"), TrackerOptions{});
    const StereoCamera camera_again = ChooseCamera(TestCamera(), again.camera, true, "", &warnings);
    EXPECT_EQ(TrackerSettingsYaml(again.options, camera_again, again.calibration_from_settings),
              written);
    ExpectFixtureOptions(again);
  }
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
}  // namespace planeloc::settings_test
