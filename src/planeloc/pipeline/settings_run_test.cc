// Whole runs with settings files: each ORB-SLAM layout runs bit-identical to planeloc keys.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "planeloc/pipeline/run_sequence.h"
#include "planeloc/pipeline/settings.h"
#include "planeloc/pipeline/settings_fixtures_for_test.h"
#include "planeloc/pipeline/tiny_drive_for_test.h"
#include "planeloc/sim/simulator.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc::settings_test {
namespace {

// A run with each ORB-SLAM fixture equals, bit for bit, a run with the same options as planeloc
// keys (deterministic mode, the simulator's tiny drive); the effective settings each run writes
// read back to the same values.
class SettingsRunTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<TempDir>("planeloc-settings-run");
    result_ = &testing::SharedTinySim();
  }
  static void TearDownTestSuite() { dir_.reset(); }

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
  static const sim::SimResult* result_;
};

std::unique_ptr<TempDir> SettingsRunTest::dir_;
const sim::SimResult* SettingsRunTest::result_ = nullptr;

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

}  // namespace
}  // namespace planeloc::settings_test
