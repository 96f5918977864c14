#include "planeloc/eval/html_report.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

#include "planeloc/io/map_updates.h"
#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc {
namespace {

namespace fs = std::filesystem;

void Write(const fs::path& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

// KITTI lines with identity rotation at the given positions.
std::string KittiLines(const std::vector<Eigen::Vector3d>& positions) {
  std::string text;
  for (const Eigen::Vector3d& p : positions) {
    text += "1 0 0 " + std::to_string(p.x()) + " 0 1 0 " + std::to_string(p.y()) + " 0 0 1 " +
            std::to_string(p.z()) + "\n";
  }
  return text;
}

TEST(DecomposeErrorTest, KittiCameraFrameHeightIsMinusY) {
  // y down, driving along +z: up = -y, left = -x.
  const AxisErrors e = DecomposeError(Eigen::Vector3d(1, -2, 3), Eigen::Vector3d(0, 0, 5),
                                      Eigen::Vector3d(0, -1, 0));
  EXPECT_DOUBLE_EQ(e.height, 2.0);
  EXPECT_DOUBLE_EQ(e.along, 3.0);
  EXPECT_DOUBLE_EQ(e.lateral, -1.0);  // 1 m to the right
}

TEST(DecomposeErrorTest, ZUpLeftIsPositiveAndSlopeIgnored) {
  // Driving along +x uphill: the along-track axis is the horizontal part of the direction.
  const AxisErrors e = DecomposeError(Eigen::Vector3d(0.5, 0.25, -0.1), Eigen::Vector3d(2, 0, 1),
                                      Eigen::Vector3d(0, 0, 1));
  EXPECT_DOUBLE_EQ(e.along, 0.5);
  EXPECT_DOUBLE_EQ(e.lateral, 0.25);
  EXPECT_DOUBLE_EQ(e.height, -0.1);
}

TEST(DecomposeErrorTest, NoHorizontalMotionPutsTheRestInLateral) {
  const AxisErrors e =
      DecomposeError(Eigen::Vector3d(3, 4, 1), Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 1));
  EXPECT_DOUBLE_EQ(e.height, 1.0);
  EXPECT_DOUBLE_EQ(e.lateral, 5.0);
  EXPECT_DOUBLE_EQ(e.along, 0.0);
}

TEST(Base64Test, Rfc4648Vectors) {
  EXPECT_EQ(Base64(""), "");
  EXPECT_EQ(Base64("f"), "Zg==");
  EXPECT_EQ(Base64("fo"), "Zm8=");
  EXPECT_EQ(Base64("foo"), "Zm9v");
  EXPECT_EQ(Base64("foob"), "Zm9vYg==");
  EXPECT_EQ(Base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(Base64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(Base64(std::string("\xff\x00\x80", 3)), "/wCA");
}

class ReportFolderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    run_ = temp_.path() / "run";
    fs::create_directories(run_ / "keyframes");
    // GT along +z (KITTI camera frame, y down); the estimate 0.1 m right (+x) and 0.2 m high.
    std::vector<Eigen::Vector3d> gt, est;
    for (int i = 0; i < 4; ++i) {
      gt.emplace_back(0, 0, 2.0 * i);
      est.emplace_back(0.1, -0.2, 2.0 * i);
    }
    Write(temp_.path() / "gt.txt", KittiLines(gt));
    Write(run_ / "trajectory.txt", KittiLines(est));
    Write(run_ / "run.json", R"({"mode": "planes", "sequence": "seq", "format": "kitti"})");
    Write(run_ / "stats.jsonl",
          "{\"frame\":0,\"keyframe\":true,\"tracked_points\":0,\"ms\":{\"extract\":5,\"track\":1,"
          "\"local_map\":0,\"ba\":0},\"map_lock\":\"searching\"}\n"
          "{\"frame\":1,\"keyframe\":false,\"tracked_points\":300,\"ms\":{\"extract\":6,"
          "\"track\":2,\"local_map\":1,\"ba\":0},\"map_lock\":\"partial\",\"ba_plane_residuals\":"
          "42}\n"
          "{\"frame\":2,\"keyframe\":true,\"tracked_points\":280,\"ms\":{\"extract\":6,"
          "\"track\":2,\"local_map\":1,\"ba\":3},\"map_lock\":\"locked\",\"planes_disabled\":1}\n"
          "{\"frame\":3,\"keyframe\":false,\"tracked_points\":270,\"ms\":{\"extract\":6,"
          "\"track\":2,\"local_map\":1,\"ba\":0},\"map_lock\":\"locked\"}\n");
    Write(run_ / "summary.json", R"({"frames": 4, "keyframes": 2})");
    Write(run_ / "settings.yaml", "ORBextractor.nFeatures: 2000\n");
    Write(run_ / "planes.json",
          R"({"planes":[{"id":7,"normal":[0,-1,0],"d":1.6,"kind":"ground",)"
          R"("polygon":[[-5,1.6,0],[5,1.6,0],[5,1.6,10],[-5,1.6,10]]}],)"
          R"("frame":{"name":"map","map":"m.pcd","up":[0,-1,0],"up_source":"given"}})");
    Write(run_ / "keyframes" / "keyframe_000002.png", "foo");
    options_.run_dir = run_;
    options_.gt_path = temp_.path() / "gt.txt";
  }

  TempDir temp_{"planeloc-html-report"};
  fs::path run_;
  HtmlReportOptions options_;
};

TEST_F(ReportFolderTest, ErrorsStatsAndTrackingSeries) {
  const nlohmann::json data = BuildReportData(options_);
  ASSERT_EQ(data["runs"].size(), 1u);
  const nlohmann::json& run = data["runs"][0];
  EXPECT_EQ(run["mode"], "planes");
  EXPECT_EQ(data["up"], nlohmann::json({0.0, -1.0, 0.0}));
  EXPECT_EQ(data["up_source"], "the plane map's frame");
  ASSERT_EQ(data["planes"].size(), 1u);
  EXPECT_EQ(data["planes"][0]["kind"], "ground");
  EXPECT_EQ(data["gt"]["distance"].back(), 6.0);

  const double ate3 = std::hypot(0.1, 0.2);
  EXPECT_EQ(run["errors"]["paired"], 4);
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(run["errors"]["ate3d"][i].get<double>(), ate3, 1e-4);
    EXPECT_NEAR(run["errors"]["ate2d"][i].get<double>(), 0.1, 1e-4);
    EXPECT_NEAR(run["errors"]["height"][i].get<double>(), 0.2, 1e-4);    // above the GT
    EXPECT_NEAR(run["errors"]["lateral"][i].get<double>(), -0.1, 1e-4);  // right of it
    EXPECT_NEAR(run["errors"]["along"][i].get<double>(), 0.0, 1e-4);
  }
  EXPECT_NEAR(run["error_stats"]["ate3d"]["rmse"].get<double>(), ate3, 1e-9);
  EXPECT_NEAR(run["error_stats"]["ate2d"]["max"].get<double>(), 0.1, 1e-9);
  EXPECT_TRUE(run["error_stats"]["kitti_drift"].is_null());  // 6 m path: no 100 m segment

  EXPECT_EQ(run["frames"], nlohmann::json({0, 1, 2, 3}));
  EXPECT_EQ(run["timing"]["ba"], nlohmann::json({0.0, 0.0, 3.0, 0.0}));
  EXPECT_EQ(run["keyframes"]["frame"], nlohmann::json({0, 2}));
  EXPECT_EQ(run["keyframes"]["tracked_points"], nlohmann::json({0, 280}));
  EXPECT_EQ(run["keyframes"]["planes_disabled"], nlohmann::json({nullptr, 1}));
  EXPECT_EQ(run["ba"]["frame"], nlohmann::json({1}));
  EXPECT_EQ(run["ba"]["plane_residuals"], nlohmann::json({42}));
  EXPECT_EQ(run["map_lock"], nlohmann::json({"searching", "partial", "locked", "locked"}));
  EXPECT_EQ(run["summary"]["frames"], 4);
  ASSERT_EQ(run["images"].size(), 1u);
  EXPECT_EQ(run["images"][0]["name"], "keyframe_000002");
  EXPECT_EQ(run["images"][0]["mime"], "image/png");
  EXPECT_EQ(run["images"][0]["data"], "Zm9v");
}

TEST_F(ReportFolderTest, PlanesTakeTheirStateFromTheRunsMapUpdate) {
  EXPECT_FALSE(BuildReportData(options_)["plane_states"].get<bool>());
  MapUpdates updates;
  updates.planes_count = 1;
  PlaneUpdate update;
  update.id = 7;
  update.status = PlaneUpdateStatus::kContradicted;
  update.through = 40;
  updates.planes = {update};
  WriteMapUpdates(run_ / "map_update.json", updates);
  const nlohmann::json data = BuildReportData(options_);
  EXPECT_TRUE(data["plane_states"].get<bool>());
  ASSERT_EQ(data["planes"].size(), 1u);
  EXPECT_EQ(data["planes"][0]["state"], "contradicted");
}

// Pose k of a run and of the GT are the same frame, as `planeloc eval` pairs them: a run cut
// short (issue 37: 20 of 60 frames was accepted, and --compare marked it "best") or a GT of
// fewer frames (8 poses for a 60-frame run gave an ATE over 8 frames) is an error.
TEST_F(ReportFolderTest, RunAndGtOfDifferentLengthsAreRefusedAsEvalRefusesThem) {
  const fs::path vo = temp_.path() / "vo";
  fs::create_directories(vo);
  Write(vo / "trajectory.txt", KittiLines({{0, 0, 0}, {0, 0, 2.5}}));
  options_.compare_dir = vo;
  try {
    BuildReportData(options_);
    ADD_FAILURE() << "a 2-pose run against a 4-pose GT was accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.path(), (vo / "trajectory.txt").string());
    EXPECT_NE(std::string(error.what()).find("2 poses against 4 in the GT"), std::string::npos)
        << error.what();
  }
  options_.compare_dir.reset();
  Write(temp_.path() / "gt.txt", KittiLines({{0, 0, 0}, {0, 0, 2}, {0, 0, 4}}));
  EXPECT_THROW(BuildReportData(options_), InputError);
}

TEST_F(ReportFolderTest, PageInlinesThreeJsAndKeepsScriptsClosed) {
  const fs::path three = temp_.path() / "three";
  fs::create_directories(three / "examples/js/controls");
  Write(three / "three.min.js", "var THREE = {s: '</script><!--'};");
  Write(three / "examples/js/controls/OrbitControls.js", "THREE.OrbitControls = null;");
  options_.three_js_dir = three;
  Write(run_ / "settings.yaml", "note: </script><script>alert(1)</script>\n");
  const std::string page = RenderHtmlReport(options_);
  EXPECT_NE(page.find("var THREE = {s: '<\\/script><\\!--'};"), std::string::npos);
  EXPECT_NE(page.find("THREE.OrbitControls = null;"), std::string::npos);
  EXPECT_NE(page.find("id=\"report-data\""), std::string::npos);
  // Five <script> elements open and close: the error hook, three.js, OrbitControls, the data,
  // the page script; the settings text cannot close one early.
  std::size_t opened = 0, closed = 0;
  for (std::size_t at = page.find("<script"); at != std::string::npos;
       at = page.find("<script", at + 1)) {
    ++opened;
  }
  for (std::size_t at = page.find("</script>"); at != std::string::npos;
       at = page.find("</script>", at + 1)) {
    ++closed;
  }
  EXPECT_EQ(opened, 5u);
  EXPECT_EQ(closed, 5u);
  EXPECT_EQ(page.find("http://"), std::string::npos);
  EXPECT_EQ(page.find("https://"), std::string::npos);
}

TEST_F(ReportFolderTest, MissingThreeJsNamesThePackage) {
  options_.three_js_dir = temp_.path() / "nowhere";
  try {
    RenderHtmlReport(options_);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("three.min.js"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("libjs-three"), std::string::npos);
  }
}

TEST_F(ReportFolderTest, StatsFieldOfTheWrongTypeNamesTheLine) {
  Write(run_ / "stats.jsonl", "{\"frame\":0}\n{\"frame\":1,\"keyframe\":\"yes\"}\n");
  try {
    BuildReportData(options_);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 2);
    EXPECT_NE(e.path().find("stats.jsonl"), std::string::npos);
  }
  Write(run_ / "stats.jsonl", "");
  Write(run_ / "run.json", R"({"mode": 3})");
  EXPECT_THROW(BuildReportData(options_), InputError);
}

TEST_F(ReportFolderTest, FolderWithoutTrajectoryIsAnInputError) {
  fs::remove(run_ / "trajectory.txt");
  EXPECT_THROW(BuildReportData(options_), InputError);
  options_.run_dir = temp_.path() / "missing";
  EXPECT_THROW(BuildReportData(options_), InputError);
}

}  // namespace
}  // namespace planeloc
