// The ASL writers against the project's readers: a 5-frame EuRoC-rig folder written to a temp
// dir opens with AslSequence and its ground truth reads back with ReadEurocTrajectory; the
// velocity columns are checked against trajectories whose velocity is known in closed form.
#include "planeloc/sim/asl_output.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "planeloc/io/asl_sequence.h"
#include "planeloc/io/settings_reader.h"
#include "planeloc/io/trajectory.h"
#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc::sim {
namespace {

namespace fs = std::filesystem;

std::string ReadText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The numeric rows of a csv with a '#' header line.
std::vector<std::vector<double>> CsvRows(const fs::path& path) {
  std::vector<std::vector<double>> rows;
  std::istringstream text(ReadText(path));
  std::string line;
  while (std::getline(text, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<double> row;
    std::istringstream fields(line);
    std::string field;
    while (std::getline(fields, field, ',')) row.push_back(std::stod(field));
    rows.push_back(row);
  }
  return rows;
}

// A 752x480 grey pattern (stripes shifted per frame and camera) that PNG encodes quickly.
cv::Mat Pattern(int seed) {
  cv::Mat image(480, 752, CV_8UC1);
  for (int r = 0; r < image.rows; ++r) {
    for (int c = 0; c < image.cols; ++c) {
      image.at<std::uint8_t>(r, c) =
          static_cast<std::uint8_t>(((c + 7 * seed) / 16 + r / 16) % 2 ? 200 : 40 + (r + c) % 32);
    }
  }
  return image;
}

// EuRoC's clock (Unix ns of V1_01_easy), 20 Hz.
std::vector<std::int64_t> Stamps(int frames) {
  std::vector<std::int64_t> stamps;
  for (int i = 0; i < frames; ++i) stamps.push_back(1403715273262142976 + i * 50000000LL);
  return stamps;
}

// A drive along x at 2 m/s turning 1 degree a frame about z, for the ground truth.
std::vector<Rigid3d> Drive(int frames) {
  std::vector<Rigid3d> poses;
  for (int i = 0; i < frames; ++i) {
    const Eigen::Quaterniond yaw(Eigen::AngleAxisd(i * M_PI / 180.0, Eigen::Vector3d::UnitZ()));
    poses.emplace_back(yaw, Eigen::Vector3d(4.0 + 0.1 * i, -1.5, 0.8));
  }
  return poses;
}

// dir/mav0 as the simulator would write it: EuRoC's rig, `stamps`, the ground truth `poses`.
fs::path WriteFolder(const fs::path& dir, const std::vector<std::int64_t>& stamps,
                     const std::vector<Rigid3d>& poses) {
  const fs::path mav0 = dir / "mav0";
  const std::pair<const char*, AslCamera> cameras[] = {{"cam0", EurocCam0()},
                                                       {"cam1", EurocCam1()}};
  for (int k = 0; k < 2; ++k) {
    const fs::path camera = mav0 / cameras[k].first;
    fs::create_directories(camera / "data");
    WriteAslCameraYaml(camera / "sensor.yaml", cameras[k].second,
                       fmt::format("planeloc sim {}", cameras[k].first));
    WriteAslImageList(camera / "data.csv", stamps);
    for (std::size_t i = 0; i < stamps.size(); ++i) {
      EXPECT_TRUE(cv::imwrite((camera / "data" / AslImageName(stamps[i])).string(),
                              Pattern(static_cast<int>(i) + 100 * k)));
    }
  }
  fs::create_directories(mav0 / "state_groundtruth_estimate0");
  WriteAslGroundTruth(mav0 / "state_groundtruth_estimate0" / "data.csv", stamps, poses);
  return mav0;
}

TEST(AslOutputTest, SensorYamlHasEurocsFieldsAtFullPrecision) {
  TempDir dir("planeloc-asl-out");
  const AslCamera cam0 = EurocCam0();
  WriteAslCameraYaml(dir.path() / "sensor.yaml", cam0, "VI-Sensor cam0 (MT9M034)");
  const std::string text = ReadText(dir.path() / "sensor.yaml");
  EXPECT_EQ(text.rfind("# General sensor definitions.\nsensor_type: camera\n"
                       "comment: VI-Sensor cam0 (MT9M034)\n",
                       0),
            0u)
      << text;
  for (const char* line :
       {"T_BS:\n  cols: 4\n  rows: 4\n  data: [", "rate_hz: 20\n", "resolution: [752, 480]\n",
        "camera_model: pinhole\n",
        "intrinsics: [458.654, 457.296, 367.215, 248.375] #fu, fv, cu, cv\n",
        "distortion_model: radial-tangential\n",
        "distortion_coefficients: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]\n",
        "0.0, 0.0, 0.0, 1.0]\n"}) {
    EXPECT_NE(text.find(line), std::string::npos) << line << "\n" << text;
  }
  // The matrix reads back bit for bit, and is EuRoC's published T_BS up to the re-orthonormalizing
  // of Rigid3d (measured 2.8e-13 at most).
  // Without a `%YAML` header, as EuRoC writes it: OpenCV reads it once the header is added.
  std::string normalized = text;
  ASSERT_EQ(NormalizeYamlHeader(normalized), 1);
  cv::FileStorage yaml(normalized, cv::FileStorage::READ | cv::FileStorage::MEMORY);
  ASSERT_TRUE(yaml.isOpened());
  const cv::FileNode data = yaml["T_BS"]["data"];
  ASSERT_EQ(data.size(), 16u);
  const Eigen::Matrix4d written = cam0.body_from_sensor.Matrix4d();
  Eigen::Matrix4d published;
  published << 0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975,  //
      0.999557249008, 0.0149672133247, 0.025715529948, -0.064676986768,               //
      -0.0257744366974, 0.00375618835797, 0.999660727178, 0.00981073058949,           //
      0.0, 0.0, 0.0, 1.0;
  double deviation = 0.0;
  for (int k = 0; k < 16; ++k) {
    EXPECT_EQ(static_cast<double>(data[k]), written(k / 4, k % 4)) << k;
    deviation =
        std::max(deviation, std::abs(static_cast<double>(data[k]) - published(k / 4, k % 4)));
  }
  EXPECT_LT(deviation, 1e-12);
}

TEST(AslOutputTest, AslSequenceOpensTheWrittenFolder) {
  TempDir dir("planeloc-asl-out");
  const std::vector<std::int64_t> stamps = Stamps(5);
  const fs::path mav0 = WriteFolder(dir.path(), stamps, Drive(5));
  EXPECT_EQ(ReadText(mav0 / "cam1" / "data.csv"),
            fmt::format("#timestamp [ns],filename\n{0},{0}.png\n{1},{1}.png\n{2},{2}.png\n"
                        "{3},{3}.png\n{4},{4}.png\n",
                        stamps[0], stamps[1], stamps[2], stamps[3], stamps[4]));
  ASSERT_TRUE(AslSequence::IsAslFolder(dir.path()));
  const AslSequence sequence = AslSequence::Open(dir.path());
  ASSERT_EQ(sequence.size(), 5u);
  EXPECT_EQ(sequence.unpaired_frames(), 0u);
  for (std::size_t i = 0; i < stamps.size(); ++i) EXPECT_EQ(sequence.timestamp_ns(i), stamps[i]);
  const StereoCamera& camera = sequence.camera();
  EXPECT_EQ(camera.width, 752);
  EXPECT_EQ(camera.height, 480);
  // The two T_BS put the cameras 0.1101 m apart (EuRoC's baseline; asl_sequence_test.cc).
  EXPECT_NEAR(camera.baseline, 0.1101, 5e-4);
  // The rectified left camera sits at cam0's origin and turns from it by the rectification's
  // rotation only: a fraction of a degree for the nearly parallel VI-Sensor pair.
  const Rigid3d body_from_cam0 = EurocCam0().body_from_sensor;
  EXPECT_LT((sequence.body_from_camera().translation - body_from_cam0.translation).norm(), 1e-12);
  EXPECT_LT(RotationAngle(sequence.body_from_camera().rotation, body_from_cam0.rotation), 0.02);
  const StereoPair pair = sequence.LoadStereoPair(4);
  EXPECT_EQ(pair.left.size(), cv::Size(752, 480));
  EXPECT_EQ(pair.right.size(), cv::Size(752, 480));
}

TEST(AslOutputTest, GroundTruthReadsBackAsTheBodyPoses) {
  TempDir dir("planeloc-asl-out");
  const std::vector<std::int64_t> stamps = Stamps(5);
  std::vector<Rigid3d> poses = Drive(5);
  // A quaternion with w < 0 (the same rotation as -q) is written with w >= 0.
  poses[3].rotation.coeffs() = -poses[3].rotation.coeffs();
  const fs::path mav0 = WriteFolder(dir.path(), stamps, poses);
  const fs::path csv = mav0 / "state_groundtruth_estimate0" / "data.csv";
  const Trajectory body = ReadEurocTrajectory(csv);
  ASSERT_EQ(body.size(), 5u);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    // Seconds as doubles of 1.4e18 ns: 256 ns resolution (trajectory.cc).
    EXPECT_NEAR(body.timestamps[i], static_cast<double>(stamps[i]) * 1e-9, 1e-6) << i;
    EXPECT_LT((body.world_from_cam[i].translation - poses[i].translation).norm(), 1e-9) << i;
    EXPECT_LT(RotationAngle(body.world_from_cam[i].rotation, poses[i].rotation), 1e-9) << i;
  }
  const std::vector<std::vector<double>> rows = CsvRows(csv);
  ASSERT_EQ(rows.size(), 5u);
  for (const auto& row : rows) {
    ASSERT_EQ(row.size(), 17u);
    EXPECT_GE(row[4], 0.0);
    for (int c = 11; c < 17; ++c) EXPECT_EQ(row[c], 0.0) << c;  // biases
  }
  EXPECT_EQ(ReadText(csv).rfind("#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], "
                                "q_RS_x [], q_RS_y [], q_RS_z [], v_RS_R_x [m s^-1], ",
                                0),
            0u);

  // The camera pose of each frame is the body pose at the frame's stamp times body_from_camera.
  // The reader times both as doubles of Unix seconds (2.4e-7 s apart at 1.4e9 s), so its
  // interpolation may move up to ~1e-5 of a frame's 0.1 m and 1 degree step: < 1e-6 m, rad.
  const AslSequence sequence = AslSequence::Open(dir.path());
  for (std::size_t i = 0; i < sequence.size(); ++i) {
    const Rigid3d camera = sequence.CameraPoseFromGroundTruth(csv, i);
    const Rigid3d expected = poses[i] * sequence.body_from_camera();
    EXPECT_LT((camera.translation - expected.translation).norm(), 1e-6) << i;
    EXPECT_LT(RotationAngle(camera.rotation, expected.rotation), 1e-6) << i;
  }
}

TEST(AslOutputTest, VelocityIsTheDerivativeOfThePositions) {
  TempDir dir("planeloc-asl-out");
  // Uneven steps (50, 30, 70, 50 ms): a constant velocity is exact in every difference, central
  // or one-sided, whatever the spacing.
  const std::vector<std::int64_t> stamps = {1403715273262142976, 1403715273312142976,
                                            1403715273342142976, 1403715273412142976,
                                            1403715273462142976};
  const Eigen::Vector3d velocity(1.5, -0.25, 0.125);
  std::vector<Rigid3d> poses;
  for (const std::int64_t stamp : stamps) {
    const double t = static_cast<double>(stamp - stamps[0]) * 1e-9;
    poses.emplace_back(Eigen::Quaterniond(Eigen::AngleAxisd(0.3 * t, Eigen::Vector3d::UnitY())),
                       Eigen::Vector3d(1, 2, 3) + velocity * t);
  }
  WriteAslGroundTruth(dir.path() / "constant.csv", stamps, poses);
  for (const auto& row : CsvRows(dir.path() / "constant.csv")) {
    EXPECT_LT((Eigen::Vector3d(row[8], row[9], row[10]) - velocity).norm(), 1e-12);
  }

  // p = a t^2 at even 50 ms steps: the central difference of a parabola is its exact derivative
  // 2 a t inside; the ends are one-sided, (p1 - p0) / dt = a dt at t = 0.
  const Eigen::Vector3d a(2.0, 0.0, -1.0);
  const std::vector<std::int64_t> even = Stamps(5);
  std::vector<Rigid3d> parabola;
  for (const std::int64_t stamp : even) {
    const double t = static_cast<double>(stamp - even[0]) * 1e-9;
    parabola.emplace_back(Eigen::Quaterniond::Identity(), a * t * t);
  }
  WriteAslGroundTruth(dir.path() / "parabola.csv", even, parabola);
  const std::vector<std::vector<double>> rows = CsvRows(dir.path() / "parabola.csv");
  ASSERT_EQ(rows.size(), 5u);
  const auto v = [&](std::size_t i) {
    return Eigen::Vector3d(rows[i][8], rows[i][9], rows[i][10]);
  };
  EXPECT_LT((v(0) - a * 0.05).norm(), 1e-12);
  for (std::size_t i = 1; i < 4; ++i)
    EXPECT_LT((v(i) - 2 * a * 0.05 * static_cast<double>(i)).norm(), 1e-12) << i;
  EXPECT_LT((v(4) - a * (0.2 + 0.15)).norm(), 1e-12);  // (p4 - p3) / dt = a (t4 + t3)

  // One pose: no difference to take, the velocity is zero.
  WriteAslGroundTruth(dir.path() / "one.csv", {stamps[0]}, {poses[0]});
  const std::vector<std::vector<double>> one = CsvRows(dir.path() / "one.csv");
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(Eigen::Vector3d(one[0][8], one[0][9], one[0][10]), Eigen::Vector3d::Zero());
}

// The message of the InputError that `write` throws ("" when none).
template <typename Write>
std::string WriteError(Write write) {
  try {
    write();
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(AslOutputTest, BadCallsAreErrorsNamingThePathAndWriteNothing) {
  TempDir dir("planeloc-asl-out");
  const fs::path csv = dir.path() / "data.csv";
  const std::vector<std::int64_t> stamps = Stamps(3);
  for (const std::string& message : {
           WriteError([&] { WriteAslGroundTruth(csv, stamps, Drive(2)); }),
           WriteError([&] {
             WriteAslImageList(csv, {stamps[1], stamps[0]});
           }),
           WriteError([&] {
             WriteAslImageList(csv, {stamps[0], stamps[0]});
           }),
           WriteError([&] { WriteAslImageList(csv, {-1}); }),
           WriteError([&] { WriteAslImageList(csv, {}); }),
           WriteError([&] { WriteAslCameraYaml(csv, AslCamera{}, "no intrinsics"); }),
           WriteError([&] { WriteAslCameraYaml(csv, EurocCam0(), "two\nlines"); }),
       }) {
    EXPECT_NE(message.find(csv.string()), std::string::npos) << message;
  }
  EXPECT_FALSE(fs::exists(csv));
  // A missing folder: WriteFileWhole's error names it.
  const std::string message =
      WriteError([&] { WriteAslImageList(dir.path() / "missing" / "data.csv", stamps); });
  EXPECT_NE(message.find("missing"), std::string::npos) << message;
}

}  // namespace
}  // namespace planeloc::sim
