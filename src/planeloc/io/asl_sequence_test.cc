// AslSequence on ASL/EuRoC-layout folders written to a temp dir: EuRoC's published calibration of
// cam0/cam1 (V1_01_easy's sensor.yaml values), an ideal pair whose rectification is the identity,
// unpaired frames, and the bad-input cases.
#include "planeloc/io/asl_sequence.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc {
namespace {

namespace fs = std::filesystem;

struct CameraYaml {
  std::string t_bs, intrinsics, distortion, model = "radial-tangential";
};

// EuRoC MAV's VI-Sensor (the sensor.yaml of every sequence).
const CameraYaml kEurocCam0{
    "0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975, 0.999557249008, "
    "0.0149672133247, 0.025715529948, -0.064676986768, -0.0257744366974, 0.00375618835797, "
    "0.999660727178, 0.00981073058949, 0.0, 0.0, 0.0, 1.0",
    "458.654, 457.296, 367.215, 248.375", "-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05"};
const CameraYaml kEurocCam1{
    "0.0125552670891, -0.999755099723, 0.0182237714554, -0.0198435579556, 0.999598781151, "
    "0.0130119051815, 0.0251588363115, 0.0453689425024, -0.0253898008918, 0.0179005838253, "
    "0.999517347078, 0.00786212447038, 0.0, 0.0, 0.0, 1.0",
    "457.587, 456.134, 379.999, 255.238", "-0.28368365, 0.07451284, -0.00010473, -3.55590700e-05"};

void WriteText(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

// In EuRoC's own form: no `%YAML:1.0` header (cv::FileStorage refuses such a file unless the
// reader adds one), a comment first, T_BS as a cols/rows/data map.
void WriteSensor(const fs::path& camera, const CameraYaml& yaml) {
  WriteText(camera / "sensor.yaml",
            fmt::format("# General sensor definitions.\nsensor_type: camera\ncomment: VI-Sensor\n"
                        "\n# Sensor extrinsics wrt. the body-frame.\nT_BS:\n  cols: 4\n"
                        "  rows: 4\n  data: [{}]\nrate_hz: 20\nresolution: [752, 480]\n"
                        "camera_model: pinhole\nintrinsics: [{}] #fu, fv, cu, cv\n"
                        "distortion_model: {}\ndistortion_coefficients: [{}]\n",
                        yaml.t_bs, yaml.intrinsics, yaml.model, yaml.distortion));
}

cv::Mat Texture(int seed) {
  cv::Mat image(480, 752, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  return image;
}

// dir/mav0 with `stamps` (ns) for cam0; cam1 has them all but `skip_right`.
fs::path WriteAsl(const fs::path& dir, const CameraYaml& left, const CameraYaml& right,
                  const std::vector<long long>& stamps, long long skip_right = -1) {
  const fs::path mav0 = dir / "mav0";
  for (const auto& [name, yaml] : {std::pair{"cam0", &left}, std::pair{"cam1", &right}}) {
    fs::create_directories(mav0 / name / "data");
    WriteSensor(mav0 / name, *yaml);
    std::string csv = "#timestamp [ns],filename\n";
    for (std::size_t i = 0; i < stamps.size(); ++i) {
      if (std::string(name) == "cam1" && stamps[i] == skip_right) continue;
      csv += fmt::format("{},{}.png\r\n", stamps[i], stamps[i]);  // EuRoC's files end in CRLF
      cv::imwrite((mav0 / name / "data" / fmt::format("{}.png", stamps[i])).string(),
                  Texture(static_cast<int>(i) + (std::string(name) == "cam1" ? 100 : 0)));
    }
    WriteText(mav0 / name / "data.csv", csv);
  }
  return mav0;
}

const std::vector<long long> kStamps = {1403715273262142976, 1403715273312143104,
                                        1403715273362142976};

TEST(AslSequenceTest, ReadsEurocsCalibrationAndRectifiesOnLoad) {
  TempDir dir("planeloc-asl");
  const fs::path mav0 = WriteAsl(dir.path(), kEurocCam0, kEurocCam1, kStamps);
  EXPECT_TRUE(AslSequence::IsAslFolder(dir.path()));
  EXPECT_TRUE(AslSequence::IsAslFolder(mav0));
  EXPECT_FALSE(AslSequence::IsAslFolder(mav0 / "cam0"));
  const AslSequence sequence = AslSequence::Open(dir.path());
  EXPECT_EQ(sequence.mav0(), mav0);
  ASSERT_EQ(sequence.size(), 3u);
  EXPECT_NEAR(sequence.timestamp(0), 1403715273.262142976, 1e-6);  // the dataset's clock
  EXPECT_NEAR(sequence.timestamp(2) - sequence.timestamp(0), 0.1, 1e-6);
  EXPECT_EQ(sequence.timestamp_ns(1), 1403715273312143104);
  // The two T_BS put the cameras 0.1101 m apart (EuRoC's stereo baseline).
  const StereoCamera& camera = sequence.camera();
  EXPECT_NEAR(camera.baseline, 0.1101, 5e-4);
  EXPECT_EQ(camera.width, 752);
  EXPECT_EQ(camera.height, 480);
  EXPECT_GT(camera.fx, 380.0);  // alpha 0 crops the distorted border: fx above the raw 458
  EXPECT_LT(camera.fx, 600.0);
  // The rectified left camera looks where cam0 does, to within the rectification's rotation.
  const Eigen::Vector3d axis_cam0(0.00414029679422, 0.025715529948, 0.999660727178);
  const Eigen::Vector3d axis = sequence.body_from_camera().rotation * Eigen::Vector3d::UnitZ();
  EXPECT_LT(std::acos(axis.dot(axis_cam0)), 0.02);
  EXPECT_NEAR((sequence.body_from_camera().translation -
               Eigen::Vector3d(-0.0216401454975, -0.064676986768, 0.00981073058949))
                  .norm(),
              0.0, 1e-9);
  const StereoPair pair = sequence.LoadStereoPair(1);
  EXPECT_EQ(pair.left.type(), CV_8UC1);
  EXPECT_EQ(pair.left.size(), cv::Size(752, 480));
  EXPECT_EQ(pair.right.size(), cv::Size(752, 480));
}

TEST(AslSequenceTest, AnIdealPairIsLeftAsItIs) {
  // No distortion, parallel cameras 0.1 m apart along x: rectification is the identity.
  TempDir dir("planeloc-asl");
  CameraYaml left{"1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1", "450, 450, 376, 240", "0, 0, 0, 0"};
  CameraYaml right = left;
  right.t_bs = "1,0,0,0.1, 0,1,0,0, 0,0,1,0, 0,0,0,1";
  WriteAsl(dir.path(), left, right, kStamps);
  const AslSequence sequence = AslSequence::Open(dir.path() / "mav0");
  EXPECT_NEAR(sequence.camera().fx, 450.0, 1e-3);  // cv::stereoRectify: 450.0000143
  EXPECT_NEAR(sequence.camera().cx, 376.0, 1e-3);
  EXPECT_NEAR(sequence.camera().baseline, 0.1, 1e-9);
  const StereoPair pair = sequence.LoadStereoPair(0);
  EXPECT_EQ(cv::norm(pair.left, Texture(0), cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(pair.right, Texture(100), cv::NORM_INF), 0.0);
}

TEST(AslSequenceTest, FramesWithoutARightImageAreLeftOut) {
  TempDir dir("planeloc-asl");
  WriteAsl(dir.path(), kEurocCam0, kEurocCam1, kStamps, kStamps[1]);
  const AslSequence sequence = AslSequence::Open(dir.path());
  ASSERT_EQ(sequence.size(), 2u);
  EXPECT_EQ(sequence.unpaired_frames(), 1u);
  EXPECT_EQ(sequence.timestamp_ns(1), kStamps[2]);
}

TEST(AslSequenceTest, CameraPoseFromTheBodysGroundTruth) {
  // Body poses 10 ms before and after frame 1 (a 0.2 m step along x and 2 degrees of yaw): the
  // camera pose is their midpoint, composed with T_BS(cam0) and the rectification.
  TempDir dir("planeloc-asl");
  WriteAsl(dir.path(), kEurocCam0, kEurocCam1, kStamps);
  const AslSequence sequence = AslSequence::Open(dir.path());
  const Eigen::Quaterniond yaw(Eigen::AngleAxisd(2.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()));
  const long long t = kStamps[1];
  WriteText(
      dir.path() / "gt.csv",
      fmt::format("#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], "
                  "q_RS_x [], q_RS_y [], q_RS_z []\n{},1,2,3,1,0,0,0\n{},1.2,2,3,{},{},{},{}\n",
                  t - 10000000, t + 10000000, yaw.w(), yaw.x(), yaw.y(), yaw.z()));
  const Rigid3d camera = sequence.CameraPoseFromGroundTruth(dir.path() / "gt.csv", 1);
  const Eigen::Quaterniond half(Eigen::AngleAxisd(1.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()));
  const Rigid3d expected = Rigid3d(half, Eigen::Vector3d(1.1, 2, 3)) * sequence.body_from_camera();
  // Times are doubles of Unix seconds (0.24 us apart at 1.4e9 s): 1.2 um at this 10 m/s.
  EXPECT_LT((camera.translation - expected.translation).norm(), 1e-5);
  EXPECT_LT(RotationAngle(camera.rotation, expected.rotation), 1e-6);
  // Frame 2 is 40 ms after the last ground-truth pose: beyond the 10 ms tolerance.
  EXPECT_THROW(sequence.CameraPoseFromGroundTruth(dir.path() / "gt.csv", 2), InputError);
}

// The message of the InputError that opening `dir` throws ("" when none).
std::string OpenError(const fs::path& dir) {
  try {
    AslSequence::Open(dir);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(AslSequenceTest, BadInputNamesTheFileAndTheFix) {
  {
    TempDir dir("planeloc-asl");
    const fs::path mav0 = WriteAsl(dir.path(), kEurocCam0, kEurocCam1, kStamps);
    WriteText(mav0 / "cam1" / "data.csv", "#timestamp [ns],filename\n1,a.png\nsoon,b.png\n");
    const std::string message = OpenError(dir.path());
    EXPECT_NE(message.find("cam1/data.csv"), std::string::npos) << message;
    EXPECT_NE(message.find(":3"), std::string::npos) << message;  // the line
  }
  {
    TempDir dir("planeloc-asl");
    const fs::path mav0 = WriteAsl(dir.path(), kEurocCam0, kEurocCam1, kStamps);
    fs::remove(mav0 / "cam0" / "sensor.yaml");
    EXPECT_NE(OpenError(dir.path()).find("cam0/sensor.yaml"), std::string::npos);
  }
  {
    TempDir dir("planeloc-asl");
    CameraYaml fisheye = kEurocCam1;
    fisheye.model = "equidistant";
    WriteAsl(dir.path(), kEurocCam0, fisheye, kStamps);
    const std::string message = OpenError(dir.path());
    EXPECT_NE(message.find("equidistant"), std::string::npos) << message;
  }
  {
    TempDir dir("planeloc-asl");
    CameraYaml scaled = kEurocCam1;
    scaled.t_bs = "2,0,0,0, 0,1,0,0.1, 0,0,1,0, 0,0,0,1";
    WriteAsl(dir.path(), kEurocCam0, scaled, kStamps);
    const std::string message = OpenError(dir.path());
    EXPECT_NE(message.find("not a rigid transform"), std::string::npos) << message;
  }
  {
    TempDir dir("planeloc-asl");
    const fs::path mav0 = WriteAsl(dir.path(), kEurocCam0, kEurocCam1, kStamps);
    cv::imwrite((mav0 / "cam0" / "data" / fmt::format("{}.png", kStamps[0])).string(),
                cv::Mat(240, 376, CV_8UC1, cv::Scalar(0)) + Texture(1)(cv::Rect(0, 0, 376, 240)));
    const AslSequence sequence = AslSequence::Open(dir.path());
    EXPECT_THROW(sequence.LoadStereoPair(0), InputError);
  }
}

}  // namespace
}  // namespace planeloc
