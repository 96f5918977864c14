// `planeloc eval` as a library: loading and pairing, the JSON document's sections and keys, the
// table and the plot CSV. Runs nothing external (the plot script is exercised by shell tests).
#include "planeloc/eval/evaluation.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <fstream>
#include <sstream>

#include "planeloc/eval/report.h"
#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"
#include "planeloc/util/test_data.h"

namespace planeloc {
namespace {

// A 3-D square-ish loop, 60 poses, written as GT; the estimate is it scaled by 1.1 and shifted.
Trajectory LoopTrajectory(double scale, const Eigen::Vector3d& offset) {
  Trajectory trajectory;
  for (int i = 0; i < 60; ++i) {
    const double angle = 2.0 * 3.14159 * i / 60.0;
    const Eigen::Vector3d position(10.0 * std::cos(angle), 0.3 * std::sin(3 * angle),
                                   10.0 * std::sin(angle));
    trajectory.world_from_cam.emplace_back(
        Eigen::Quaterniond(Eigen::AngleAxisd(-angle, Eigen::Vector3d::UnitY())),
        scale * position + offset);
    trajectory.timestamps.push_back(100.0 + 0.1 * i);
  }
  return trajectory;
}

class EvaluationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    gt_ = dir_.path() / "gt.txt";
    est_ = dir_.path() / "est.txt";
    WriteKittiTrajectory(gt_, LoopTrajectory(1.0, Eigen::Vector3d::Zero()));
    WriteKittiTrajectory(est_, LoopTrajectory(1.1, Eigen::Vector3d(1, 2, 3)));
  }
  TempDir dir_;
  std::filesystem::path gt_;
  std::filesystem::path est_;
};

TEST_F(EvaluationTest, JsonHasExactlyTheRequestedSections) {
  EvalOptions options;
  options.alignment = AlignmentType::kSim3;
  EvalInputs inputs = LoadEvalInputs(gt_, est_, options);
  EvalReport report = Evaluate(inputs, options);
  nlohmann::json json = ReportToJson(inputs, options, report);
  EXPECT_TRUE(json.contains("ape"));
  EXPECT_FALSE(json.contains("rpe"));
  EXPECT_FALSE(json.contains("kitti_drift"));
  for (const char* key : {"rmse", "mean", "median", "std", "min", "max", "sse", "n"}) {
    EXPECT_TRUE(json["ape"].contains(key)) << key;
  }
  EXPECT_EQ(json["ape"]["n"], 60);
  EXPECT_LT(json["ape"]["rmse"].get<double>(), 1e-9);  // Sim(3) undoes scale and shift
  EXPECT_EQ(json["alignment"]["type"], "sim3");
  EXPECT_NEAR(json["alignment"]["scale"].get<double>(), 1.0 / 1.1, 1e-9);
  EXPECT_EQ(json["alignment"]["rotation"].size(), 3u);
  EXPECT_EQ(json["alignment"]["translation"].size(), 3u);

  options.rpe = RpeOptions{};
  options.rpe->delta = 5;
  inputs = LoadEvalInputs(gt_, est_, options);
  report = Evaluate(inputs, options);
  json = ReportToJson(inputs, options, report);
  ASSERT_TRUE(json.contains("rpe"));
  EXPECT_EQ(json["rpe"]["n"], 11);  // checkpoints 0, 5, ..., 55
  EXPECT_TRUE(json["rpe"]["rot_deg"].contains("median"));
  const std::string table = FormatReportTable(inputs, options, report);
  EXPECT_NE(table.find("APE trans (m)"), std::string::npos);
  EXPECT_NE(table.find("RPE rot (deg)"), std::string::npos);
}

TEST_F(EvaluationTest, KittiLengthMismatchIsAnInputError) {
  Trajectory shorter = LoopTrajectory(1.0, Eigen::Vector3d::Zero());
  shorter.world_from_cam.pop_back();
  WriteKittiTrajectory(est_, shorter);
  try {
    LoadEvalInputs(gt_, est_, EvalOptions{});
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.path(), est_.string());
    EXPECT_NE(e.problem().find("59 poses"), std::string::npos);
  }
}

TEST_F(EvaluationTest, TumIsPairedByTimestamp) {
  Trajectory gt = LoopTrajectory(1.0, Eigen::Vector3d::Zero());
  Trajectory est = gt;
  // Every other estimate pose, 3 ms late: 30 pairs.
  Trajectory sparse;
  for (std::size_t i = 0; i < est.size(); i += 2) {
    sparse.timestamps.push_back(est.timestamps[i] + 0.003);
    sparse.world_from_cam.push_back(est.world_from_cam[i]);
  }
  WriteTumTrajectory(dir_.path() / "gt.tum", gt);
  WriteTumTrajectory(dir_.path() / "est.tum", sparse);
  EvalOptions options;
  options.format = TrajectoryFormat::kTum;
  const EvalInputs inputs =
      LoadEvalInputs(dir_.path() / "gt.tum", dir_.path() / "est.tum", options);
  EXPECT_EQ(inputs.reference.size(), 30u);
  EXPECT_TRUE(inputs.has_time);
  EXPECT_LT(Evaluate(inputs, options).ape.stats.max, 1e-9);

  for (double& t : sparse.timestamps) t += 50.0;
  WriteTumTrajectory(dir_.path() / "late.tum", sparse);
  EXPECT_THROW(LoadEvalInputs(dir_.path() / "gt.tum", dir_.path() / "late.tum", options),
               InputError);
}

TEST_F(EvaluationTest, EurocGroundTruthPairsWithATumEstimate) {
  // The same GT as a EuRoC csv (ns, p, q with w first, velocities and biases after) and as a TUM
  // file: the same pairs and the same APE against a TUM estimate 3 ms late and 1.1x scaled.
  const Trajectory gt = LoopTrajectory(1.0, Eigen::Vector3d::Zero());
  Trajectory est = LoopTrajectory(1.1, Eigen::Vector3d(1, 2, 3));
  for (double& t : est.timestamps) t += 0.003;
  std::string csv =
      "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
      "q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], "
      "b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], "
      "b_a_RS_S_z [m s^-2]\r\n";
  for (std::size_t i = 0; i < gt.size(); ++i) {
    const Eigen::Vector3d& p = gt.world_from_cam[i].translation;
    const Eigen::Quaterniond& q = gt.world_from_cam[i].rotation;
    csv += fmt::format("{},{},{},{},{},{},{},{},0,0,0,0,0,0,0,0,0\r\n",
                       std::llround(gt.timestamps[i] * 1e9), p.x(), p.y(), p.z(), q.w(), q.x(),
                       q.y(), q.z());
  }
  std::ofstream(dir_.path() / "data.csv") << csv;
  WriteTumTrajectory(dir_.path() / "gt.tum", gt);
  WriteTumTrajectory(dir_.path() / "est.tum", est);
  EvalOptions tum;
  tum.format = TrajectoryFormat::kTum;
  tum.alignment = AlignmentType::kSim3;
  EvalOptions euroc = tum;
  euroc.euroc_reference = true;
  const EvalInputs from_tum = LoadEvalInputs(dir_.path() / "gt.tum", dir_.path() / "est.tum", tum);
  const EvalInputs from_csv =
      LoadEvalInputs(dir_.path() / "data.csv", dir_.path() / "est.tum", euroc);
  ASSERT_EQ(from_csv.reference.size(), 60u);
  ASSERT_EQ(from_tum.reference.size(), 60u);
  const double rmse_tum = Evaluate(from_tum, tum).ape.stats.rmse;
  const double rmse_csv = Evaluate(from_csv, euroc).ape.stats.rmse;
  EXPECT_LT(rmse_csv, 1e-6);  // Sim(3) removes the scale and the offset
  EXPECT_NEAR(rmse_csv, rmse_tum, 1e-9);
  EXPECT_EQ(ReportToJson(from_csv, euroc, Evaluate(from_csv, euroc))["inputs"]["format"], "euroc");
  // A line with 7 numbers is named with its line.
  std::ofstream(dir_.path() / "short.csv") << "#t\n1,0,0,0,1,0,0,0\n2,0,0,0,1,0,0\n";
  try {
    LoadEvalInputs(dir_.path() / "short.csv", dir_.path() / "est.tum", euroc);
    ADD_FAILURE() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("short.csv:3"), std::string::npos) << error.what();
  }
}

TEST_F(EvaluationTest, PlotCsvHasOneRowPerPose) {
  EvalOptions options;
  options.alignment = AlignmentType::kSe3;
  const EvalInputs inputs = LoadEvalInputs(gt_, est_, options);
  const EvalReport report = Evaluate(inputs, options);
  WritePlotCsv(dir_.path() / "plot.csv", inputs, report);
  std::ifstream stream(dir_.path() / "plot.csv");
  std::string header;
  std::getline(stream, header);
  EXPECT_EQ(header, "frame,gt_x,gt_y,gt_z,est_x,est_y,est_z,ape");
  int rows = 0;
  for (std::string line; std::getline(stream, line);) ++rows;
  EXPECT_EQ(rows, 60);
}

TEST_F(EvaluationTest, OptionsAreChecked) {
  EvalOptions options;
  options.plane_before_align = true;
  EXPECT_THROW(options.Check(), OptionsError);
  options = EvalOptions{};
  options.format = TrajectoryFormat::kTum;
  options.gt_times = "times.txt";
  EXPECT_THROW(options.Check(), OptionsError);
}

// The whole CLI path on the real evo data: SE(3)-aligned APE of ORB-SLAM2 equals evo's value.
TEST(EvaluationSharedDataTest, CliPipelineMatchesEvo) {
  PLANELOC_SHARED_DATA_OR_SKIP(dir, "evo-kitti00");
  EvalOptions options;
  options.alignment = AlignmentType::kSe3;
  options.gt_times = dir / "KITTI_00_gt_times.txt";
  options.kitti_drift = true;
  const EvalInputs inputs =
      LoadEvalInputs(dir / "KITTI_00_gt.txt", dir / "KITTI_00_ORB.txt", options);
  const EvalReport report = Evaluate(inputs, options);
  std::ifstream stream(dir / "evo-reference.json");
  const nlohmann::json records = nlohmann::json::parse(stream)["records"];
  bool found = false;
  for (const auto& record : records) {
    if (record["tool"] == "evo_ape" && record["est_file"] == "KITTI_00_ORB.txt" &&
        record["options"]["alignment"] == "se3" &&
        record["options"]["project_to_plane"].is_null()) {
      const double rmse = record["stats"]["rmse"].get<double>();
      EXPECT_NEAR(report.ape.stats.rmse, rmse, 1e-6 * rmse);
      found = true;
    }
  }
  EXPECT_TRUE(found);
  // ORB-SLAM2 (stereo) on KITTI 00 as published: 0.70 % and 0.25 deg/100 m.
  ASSERT_TRUE(report.kitti_drift.has_value());
  EXPECT_NEAR(report.kitti_drift->translation_percent, 0.70, 0.01);
  EXPECT_NEAR(report.kitti_drift->rotation_deg_per_100m, 0.25, 0.01);
}

}  // namespace
}  // namespace planeloc
