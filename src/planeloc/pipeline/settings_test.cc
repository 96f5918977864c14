#include "planeloc/pipeline/settings.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <sstream>

#include "planeloc/pipeline/run_sequence.h"
#include "planeloc/sim/simulator.h"
#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc {
namespace {

// The simulator's camera: KITTI odometry sequences 04-12 (bf = 379.708).
StereoCamera TestCamera() { return sim::Kitti07Camera(); }

std::filesystem::path WriteFile(const TempDir& dir, const std::string& text,
                                const std::string& name = "settings.yaml") {
  const auto path = dir.path() / name;
  std::ofstream(path) << text;
  return path;
}

bool Contains(const std::vector<std::string>& list, const std::string& needle) {
  for (const auto& item : list) {
    if (item.find(needle) != std::string::npos) return true;
  }
  return false;
}

std::string Message(const std::function<void()>& load) {
  try {
    load();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected InputError";
  return "";
}

// Fixtures written for these tests in the layouts of ORB-SLAM2's and ORB-SLAM3's stereo examples,
// with their quirks: `%YAML:1.0`, `key:value` without a space, quoted strings, !!opencv-matrix,
// `data:[...]`, viewer keys. They all describe the simulator's camera and the same options:
// close depth 35 baselines, 1500 features, FAST thresholds 12/7.

// ORB-SLAM2 (and ORB-SLAM3 before v1.0) stereo layout.
constexpr const char* kOrbSlam2 = R"(%YAML:1.0

#---------------------------------------------
# Camera (rectified KITTI-like pair)
#---------------------------------------------
Camera.type: "PinHole"
Camera.fx: 707.0912
Camera.fy: 707.0912
Camera.cx: 601.8873
Camera.cy: 183.1104
Camera.k1: 0.0
Camera.k2: 0.0
Camera.p1: 0.0
Camera.p2: 0.0
Camera.bFishEye:0
Camera.width: 1226
Camera.height: 370
Camera.fps:10.0
Camera.bf: 379.708
Camera.RGB:1
ThDepth: 35

# ORB
ORBextractor.nFeatures: 1500
ORBextractor.scaleFactor: 1.2
ORBextractor.nLevels: 8
ORBextractor.iniThFAST: 12
ORBextractor.minThFAST:7

# Viewer
Viewer.KeyFrameSize: 0.5
Viewer.PointSize:3
Viewer.ViewpointY: -90
)";

// ORB-SLAM3 v1.0, rectified pair (Camera.type "Rectified", Stereo.b).
constexpr const char* kOrbSlam3Rectified = R"(%YAML:1.0
File.version: "1.0"

Camera.type: "Rectified"
Camera1.fx: 707.0912
Camera1.fy: 707.0912
Camera1.cx: 601.8873
Camera1.cy: 183.1104
Camera.width: 1226
Camera.height: 370
Camera.newWidth: 1226
Camera.newHeight: 370
Camera.fps: 10
Camera.RGB: 1
Stereo.ThDepth: 35.0
Stereo.b: 0.537

ORBextractor.nFeatures: 1500
ORBextractor.scaleFactor: 1.2
ORBextractor.nLevels: 8
ORBextractor.iniThFAST: 12
ORBextractor.minThFAST: 7

Viewer.KeyFrameSize: 0.05
Viewer.PointSize:2
Viewer.imageViewScale: 1.0
System.thFarPoints: 20.0
)";

// ORB-SLAM3 v1.0, "PinHole" pair with Camera2 and Stereo.T_c1_c2 that happens to be rectified.
constexpr const char* kOrbSlam3PinHole = R"(%YAML:1.0
File.version: "1.0"
Camera.type: "PinHole"

Camera1.fx: 707.0912
Camera1.fy: 707.0912
Camera1.cx: 601.8873
Camera1.cy: 183.1104
Camera1.k1: 0.0
Camera1.k2: 0.0
Camera1.p1: 0.0
Camera1.p2: 0.0

Camera2.fx: 707.0912
Camera2.fy: 707.0912
Camera2.cx: 601.8873
Camera2.cy: 183.1104
Camera2.k1: 0.0
Camera2.k2: 0.0
Camera2.p1: 0.0
Camera2.p2: 0.0

Camera.width: 1226
Camera.height: 370
Camera.fps: 10
Camera.RGB: 1

Stereo.ThDepth: 35.0
Stereo.T_c1_c2: !!opencv-matrix
  rows: 4
  cols: 4
  dt: d
  data:[1.0, 0.0, 0.0, 0.537,
        0.0, 1.0, 0.0, 0.0,
        0.0, 0.0, 1.0, 0.0,
        0.0, 0.0, 0.0, 1.0]

ORBextractor.nFeatures: 1500
ORBextractor.scaleFactor: 1.2
ORBextractor.nLevels: 8
ORBextractor.iniThFAST: 12
ORBextractor.minThFAST: 7

Viewer.PointSize: 2
)";

// The same options as planeloc keys only (no header, no camera).
constexpr const char* kPlanelocKeys = R"(Stereo.ThDepth: 35
ORBextractor.nFeatures: 1500
ORBextractor.iniThFAST: 12
ORBextractor.minThFAST: 7
Camera.fps: 10
)";

void ExpectFixtureOptions(const SettingsFile& file) {
  EXPECT_DOUBLE_EQ(file.options.close_depth_baselines, 35.0);
  EXPECT_EQ(file.options.orb.num_features, 1500);
  EXPECT_EQ(file.options.orb.initial_fast_threshold, 12);
  EXPECT_EQ(file.options.orb.min_fast_threshold, 7);
  EXPECT_EQ(file.options.orb.num_levels, 8);
  EXPECT_DOUBLE_EQ(file.options.fps, 10.0);
}

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

// ORB-SLAM2 EuRoC-style raw rig (numbers made up, EuRoC-like): LEFT/RIGHT K, D, R, P.
constexpr const char* kOrbSlam2RawRig = R"(%YAML:1.0
Camera.type: "PinHole"
Camera.fx: 436.0
Camera.fy: 436.0
Camera.cx: 367.5
Camera.cy: 252.0
Camera.k1: 0.0
Camera.k2: 0.0
Camera.p1: 0.0
Camera.p2: 0.0
Camera.width: 752
Camera.height: 480
Camera.fps: 20.0
Camera.bf: 47.96
Camera.RGB: 1
ThDepth: 35

# Rectification of the raw images.
LEFT.height: 480
LEFT.width: 752
LEFT.D: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data:[-0.28, 0.074, 2.0e-4, 2.0e-5, 0.0]
LEFT.K: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [458.0, 0.0, 367.0, 0.0, 457.0, 248.0, 0.0, 0.0, 1.0]
LEFT.R:  !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [0.99997, -0.0014, 0.0081, 0.0014, 0.99997, 0.0071, -0.0081, -0.0071, 0.99994]
LEFT.P:  !!opencv-matrix
   rows: 3
   cols: 4
   dt: d
   data: [436.0, 0, 367.5, 0,  0, 436.0, 252.0, 0,  0, 0, 1, 0]

RIGHT.height: 480
RIGHT.width: 752
RIGHT.D: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data:[-0.283, 0.0745, -1.0e-4, -3.5e-5, 0.0]
RIGHT.K: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [457.5, 0.0, 380.0, 0.0, 456.0, 255.0, 0.0, 0.0, 1]
RIGHT.R:  !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [0.99996, -0.0036, 0.0078, 0.0037, 0.99997, -0.0070, -0.0077, 0.0071, 0.99995]
RIGHT.P:  !!opencv-matrix
   rows: 3
   cols: 4
   dt: d
   data: [436.0, 0, 367.5, -47.96, 0, 436.0, 252.0, 0, 0, 0, 1, 0]

ORBextractor.nFeatures: 1200
Viewer.PointSize:2
)";

TEST(SettingsTest, RawOrbSlam2RigIsRectifiedOnLoad) {
  TempDir dir;
  const SettingsFile file = LoadTrackerSettings(WriteFile(dir, kOrbSlam2RawRig), {});
  ASSERT_TRUE(file.camera.has_value());
  ASSERT_TRUE(file.camera->rectifier);
  EXPECT_EQ(file.camera->fx, 436.0);
  EXPECT_EQ(file.camera->cy, 252.0);
  EXPECT_DOUBLE_EQ(file.camera->baseline, 0.11);
  EXPECT_EQ(file.camera->rectifier->size(), cv::Size(752, 480));
  EXPECT_TRUE(file.warnings.empty()) << file.warnings.front();
  EXPECT_EQ(file.options.orb.num_features, 1200);

  // LEFT/RIGHT alone (no Camera.fx/fy/cx/cy/bf) define the camera too.
  std::string rig_only = kOrbSlam2RawRig;
  for (const char* key : {"Camera.fx", "Camera.fy", "Camera.cx", "Camera.cy", "Camera.bf"}) {
    const auto begin = rig_only.find(key);
    rig_only.erase(begin, rig_only.find('\n', begin) + 1 - begin);
  }
  const SettingsFile only = LoadTrackerSettings(WriteFile(dir, rig_only, "rig_only.yaml"), {});
  ASSERT_TRUE(only.camera && only.camera->rectifier);
  EXPECT_EQ(only.camera->fx, 436.0);
  EXPECT_EQ(only.camera->line, 31);  // LEFT.P
  EXPECT_TRUE(only.warnings.empty()) << only.warnings.front();

  // The settings' camera is used whatever the sequence says; the images must have the rig's size.
  StereoCamera sequence = TestCamera();
  std::vector<std::string> warnings;
  EXPECT_THROW(ChooseCamera(sequence, file.camera, false, "s.yaml", &warnings), InputError);
  sequence.width = 752;
  sequence.height = 480;
  EXPECT_EQ(ChooseCamera(sequence, file.camera, false, "s.yaml", &warnings).fx, 436.0);

  // Written back (LEFT/RIGHT in ORB-SLAM2 layout) and read again: the same rectification.
  const std::string written = TrackerSettingsYaml(file.options, file.camera->rectifier->camera(),
                                                  true, file.camera->rectifier.get());
  const SettingsFile again = LoadTrackerSettings(WriteFile(dir, written, "again.yaml"), {});
  ASSERT_TRUE(again.camera && again.camera->rectifier);
  EXPECT_TRUE(again.warnings.empty()) << again.warnings.front();
  EXPECT_EQ(TrackerSettingsYaml(again.options, again.camera->rectifier->camera(), true,
                                again.camera->rectifier.get()),
            written);
  cv::Mat image(480, 752, CV_8UC1);
  cv::randu(image, 0, 255);
  const StereoPair a = file.camera->rectifier->Rectify({image, image});
  const StereoPair b = again.camera->rectifier->Rectify({image, image});
  EXPECT_EQ(cv::norm(a.left, b.left, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a.right, b.right, cv::NORM_INF), 0.0);
}

TEST(SettingsTest, RawOrbSlam3PinHolePairIsRectifiedOnLoad) {
  TempDir dir;
  std::string raw = kOrbSlam3PinHole;
  raw.replace(raw.find("Camera2.k1: 0.0"), 15, "Camera2.k1: -0.28");
  raw.replace(raw.find("data:[1.0, 0.0, 0.0"), 19, "data:[0.9999, 0.0141, 0.0");
  raw.replace(raw.find("0.0, 1.0, 0.0, 0.0,"), 19, "-0.0141, 0.9999, 0.0, 0.0,");
  const SettingsFile file = LoadTrackerSettings(WriteFile(dir, raw), {});
  ASSERT_TRUE(file.camera && file.camera->rectifier);
  EXPECT_NEAR(file.camera->baseline, 0.537, 1e-6);
  EXPECT_EQ(file.ignored,
            (std::vector<std::string>{
                "Camera.RGB", "Viewer.PointSize"}));  // the written rotation is orthonormal to 1e-6
  ASSERT_EQ(file.warnings.size(), 1u);
  EXPECT_NE(file.warnings[0].find(
                "not rectified (distortion, a rotation between the cameras): rectifying every "
                "frame on load"),
            std::string::npos)
      << file.warnings[0];
}

TEST(SettingsTest, RefusesIncompleteRigsFisheyeAndResizedInput) {
  TempDir dir;
  const std::string incomplete = std::string(kOrbSlam2) +
                                 "LEFT.height: 480\nLEFT.width: 752\nLEFT.K: !!opencv-matrix\n"
                                 "   rows: 3\n   cols: 3\n   dt: d\n"
                                 "   data:[458.0, 0.0, 367.0, 0.0, 457.0, 248.0, 0.0, 0.0, 1.0]\n";
  const std::string rig =
      Message([&] { LoadTrackerSettings(WriteFile(dir, incomplete), TrackerOptions{}); });
  EXPECT_NE(rig.find("settings.yaml:36:"), std::string::npos) << rig;
  EXPECT_NE(rig.find("LEFT.D is missing: a raw stereo pair needs LEFT. and RIGHT. K, D, R, P"),
            std::string::npos)
      << rig;
  EXPECT_NE(rig.find("RIGHT.K is missing"), std::string::npos) << rig;

  std::string fisheye = kOrbSlam3Rectified;
  fisheye.replace(fisheye.find("\"Rectified\""), 11, "\"KannalaBrandt8\"");
  EXPECT_NE(Message([&] {
              LoadTrackerSettings(WriteFile(dir, fisheye), TrackerOptions{});
            }).find("settings.yaml:4: Camera.type \"KannalaBrandt8\" is a fisheye camera"),
            std::string::npos);

  std::string resized = kOrbSlam3Rectified;
  resized.replace(resized.find("Camera.newWidth: 1226"), 21, "Camera.newWidth: 600");
  EXPECT_NE(Message([&] {
              LoadTrackerSettings(WriteFile(dir, resized), TrackerOptions{});
            }).find("settings.yaml:11: Camera.newWidth = 600 asks for resized images"),
            std::string::npos);
}

TEST(SettingsTest, SequenceCalibrationWinsAndDifferencesAreWarnedWithBothValues) {
  SettingsCamera file;
  file.fx = 707.0912 + 0.4;  // within 0.5 px: silent
  file.fy = 718.856;
  file.cx = 601.8873;
  file.cy = 183.1104;
  file.baseline = 0.537 * 1.004;  // within 0.5 %: silent
  file.fx_key = "Camera.fx";
  file.fy_key = "Camera.fy";
  file.baseline_key = "Camera.bf";
  std::vector<std::string> warnings;
  const StereoCamera sequence = TestCamera();
  const StereoCamera chosen = ChooseCamera(sequence, file, false, "s.yaml", &warnings);
  EXPECT_EQ(chosen.fx, sequence.fx);
  EXPECT_EQ(chosen.fy, sequence.fy);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("Camera.fy: fy = 718.856 (settings) but 707.0912 (sequence"),
            std::string::npos)
      << warnings[0];

  file.baseline = 0.537 * 1.006;
  warnings.clear();
  const StereoCamera from_file = ChooseCamera(sequence, file, true, "s.yaml", &warnings);
  EXPECT_EQ(from_file.fy, 718.856);
  EXPECT_EQ(from_file.baseline, file.baseline);
  EXPECT_EQ(from_file.width, sequence.width);
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_NE(warnings[1].find("Camera.bf: baseline (m)"), std::string::npos) << warnings[1];
  EXPECT_NE(warnings[1].find("settings' value is used"), std::string::npos);

  EXPECT_THROW(ChooseCamera(sequence, std::nullopt, true, "s.yaml", &warnings), InputError);
  EXPECT_EQ(ChooseCamera(sequence, std::nullopt, false, "s.yaml", &warnings).fx, sequence.fx);
}

TEST(SettingsTest, CalibrationFromSettingsKey) {
  TempDir dir;
  const SettingsFile file = LoadTrackerSettings(
      WriteFile(dir, std::string(kOrbSlam2) + "System.calibrationFromSettings: 1\n"), {});
  EXPECT_TRUE(file.calibration_from_settings);
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

// A run with each ORB-SLAM fixture equals, bit for bit, a run with the same options as planeloc
// keys (deterministic mode, the simulator's tiny drive); the effective settings each run writes
// read back to the same values.
class SettingsRunTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<TempDir>("planeloc-settings-run");
    sim::SimOptions options = sim::SimOptions::FromPreset("tiny");
    options.show_progress = false;
    result_ =
        std::make_unique<sim::SimResult>(sim::GenerateSequence(options, dir_->path() / "sim"));
  }
  static void TearDownTestSuite() {
    result_.reset();
    dir_.reset();
  }

  static RunSummary RunWith(const std::string& name, const char* settings, bool from_settings) {
    RunOptions run;
    run.sequence = result_->sequence_dir;
    run.trajectory_path = dir_->path() / (name + ".txt");
    run.settings_path = WriteFile(*dir_, settings, name + ".yaml");
    run.calibration_from_settings = from_settings;
    run.deterministic = true;
    run.show_progress = false;
    run.max_frames = kFrames;
    return RunSequence(run);
  }

  static std::string ReadBytes(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream out;
    out << in.rdbuf();
    return out.str();
  }

  static constexpr int kFrames = 30;
  static std::unique_ptr<TempDir> dir_;
  static std::unique_ptr<sim::SimResult> result_;
};

std::unique_ptr<TempDir> SettingsRunTest::dir_;
std::unique_ptr<sim::SimResult> SettingsRunTest::result_;

TEST_F(SettingsRunTest, OrbSlamFilesRunBitIdenticalToPlanelocKeys) {
  const RunSummary reference = RunWith("planeloc", kPlanelocKeys, false);
  ASSERT_EQ(reference.frames, kFrames);
  EXPECT_EQ(reference.lost, 0);
  EXPECT_GT(reference.keyframes, 1);
  EXPECT_EQ(reference.options.orb.num_features, 1500);
  const std::string expected = ReadBytes(dir_->path() / "planeloc.txt");
  ASSERT_FALSE(expected.empty());
  const std::vector<std::pair<std::string, const char*>> fixtures = {
      {"orbslam2", kOrbSlam2}, {"orbslam3", kOrbSlam3Rectified}, {"pinhole", kOrbSlam3PinHole}};
  for (const auto& [name, text] : fixtures) {
    const RunSummary summary = RunWith(name, text, false);
    EXPECT_EQ(ReadBytes(dir_->path() / (name + ".txt")), expected) << name;
    // The effective settings: the options and the camera of the run.
    const SettingsFile effective =
        LoadTrackerSettings(dir_->path() / (name + ".txt.config.yaml"), TrackerOptions{});
    EXPECT_EQ(TrackerSettingsYaml(effective.options, summary.camera, false),
              TrackerSettingsYaml(summary.options, summary.camera, false))
        << name;
    ASSERT_TRUE(effective.camera.has_value());
    EXPECT_EQ(effective.camera->fx, summary.camera.fx);
    EXPECT_EQ(effective.camera->baseline, summary.camera.baseline);
  }
}

TEST_F(SettingsRunTest, CalibrationFromSettingsIsUsedAndWrittenBack) {
  std::string wider = kOrbSlam3Rectified;
  wider.replace(wider.find("Stereo.b: 0.537"), 15, "Stereo.b: 0.55");
  const RunSummary summary = RunWith("from_settings", wider.c_str(), true);
  EXPECT_EQ(summary.camera.baseline, 0.55);
  EXPECT_EQ(summary.camera.fx, 707.0912);
  EXPECT_EQ(summary.camera.width, result_->camera.width);
  const SettingsFile effective =
      LoadTrackerSettings(dir_->path() / "from_settings.txt.config.yaml", TrackerOptions{});
  EXPECT_TRUE(effective.calibration_from_settings);
  ASSERT_TRUE(effective.camera.has_value());
  EXPECT_EQ(effective.camera->baseline, 0.55);
  // The sequence's calibration wins by default.
  EXPECT_NEAR(RunWith("sequence_calib", wider.c_str(), false).camera.baseline, 0.537, 1e-9);
}

// A raw rig whose rectification is the identity (the sim's rectified K, no distortion, R = I,
// P from calib.txt): the run rectifies every frame on load and still equals the reference run
// bit for bit; its effective settings record the rig and read back to it.
TEST_F(SettingsRunTest, RawRigRectifiedOnLoadRunsLikeTheRectifiedSequence) {
  std::ifstream calib(result_->sequence_dir / "calib.txt");
  std::map<std::string, std::string> rows;
  std::string line;
  while (std::getline(calib, line)) {
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::istringstream values(line.substr(colon + 1));
    std::string value, joined;
    while (values >> value) joined.append(joined.empty() ? "" : ", ").append(value);
    rows[line.substr(0, colon)] = joined;
  }
  ASSERT_TRUE(rows.count("P0") && rows.count("P1"));
  const RunSummary reference = RunWith("reference", kPlanelocKeys, false);
  const StereoCamera& c = reference.camera;
  const std::string k = fmt::format("[{}, 0, {}, 0, {}, {}, 0, 0, 1]", c.fx, c.cx, c.fy, c.cy);
  std::string rig = std::string(kPlanelocKeys) + "Viewer.PointSize:2\n";
  for (const auto& [side, p] :
       {std::pair<std::string, std::string>{"LEFT", "P0"}, {"RIGHT", "P1"}}) {
    rig += fmt::format(
        "{0}.width: {1}\n{0}.height: {2}\n"
        "{0}.K: !!opencv-matrix\n  rows: 3\n  cols: 3\n  dt: d\n  data:{3}\n"
        "{0}.D: !!opencv-matrix\n  rows: 1\n  cols: 5\n  dt: d\n  data:[0, 0, 0, 0, 0]\n"
        "{0}.R: !!opencv-matrix\n  rows: 3\n  cols: 3\n  dt: d\n  data:[1, 0, 0, 0, 1, 0, 0, 0, "
        "1]\n"
        "{0}.P: !!opencv-matrix\n  rows: 3\n  cols: 4\n  dt: d\n  data:[{4}]\n",
        side, c.width, c.height, k, rows[p]);
  }
  rig = "%YAML:1.0\n" +
        fmt::format(
            "Camera.fx: {}\nCamera.fy: {}\nCamera.cx: {}\nCamera.cy: {}\n"
            "Camera.bf: {}\n",
            c.fx, c.fy, c.cx, c.cy, c.BaselineTimesFx()) +
        rig;
  const RunSummary raw = RunWith("raw_rig", rig.c_str(), false);
  EXPECT_EQ(raw.camera.fx, reference.camera.fx);
  EXPECT_EQ(raw.camera.baseline, reference.camera.baseline);
  EXPECT_EQ(ReadBytes(dir_->path() / "raw_rig.txt"), ReadBytes(dir_->path() / "reference.txt"));
  const SettingsFile effective =
      LoadTrackerSettings(dir_->path() / "raw_rig.txt.config.yaml", TrackerOptions{});
  ASSERT_TRUE(effective.camera && effective.camera->rectifier);
  EXPECT_TRUE(effective.calibration_from_settings);
  EXPECT_EQ(effective.camera->rectifier->camera().baseline, raw.camera.baseline);
  EXPECT_EQ(
      TrackerSettingsYaml(effective.options, raw.camera, true, effective.camera->rectifier.get()),
      ReadBytes(dir_->path() / "raw_rig.txt.config.yaml"));
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
