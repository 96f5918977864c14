// Settings that describe a raw (unrectified) stereo rig: rectified on load, refused where they
// cannot be, and how they meet the sequence's own calibration.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "planeloc/pipeline/settings.h"
#include "planeloc/pipeline/settings_fixtures_for_test.h"
#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc::settings_test {
namespace {

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

}  // namespace
}  // namespace planeloc::settings_test
