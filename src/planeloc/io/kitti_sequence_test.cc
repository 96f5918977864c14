// KittiSequence on the real KITTI data in ../shared/data and on tiny synthetic sequences written
// to a temp dir (the odometry GT folder has no images), then the bad-input cases.
#include "planeloc/io/kitti_sequence.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <opencv2/imgcodecs.hpp>

#include "planeloc/io/kitti_calib.h"
#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"
#include "planeloc/util/test_data.h"

namespace planeloc {
namespace {

namespace fs = std::filesystem;

// Calibration of KITTI odometry sequences 04-12 (values of sequences/07/calib.txt).
constexpr const char* kOdometryCalib =
    "P0: 7.070912e+02 0 6.018873e+02 0 0 7.070912e+02 1.831104e+02 0 0 0 1 0\n"
    "P1: 7.070912e+02 0 6.018873e+02 -3.798145e+02 0 7.070912e+02 1.831104e+02 0 0 0 1 0\n"
    "P2: 7.070912e+02 0 6.018873e+02 4.688783e+01 0 7.070912e+02 1.831104e+02 1.178601e-01 0 0 1 "
    "6.203223e-03\n"
    "P3: 7.070912e+02 0 6.018873e+02 -3.334597e+02 0 7.070912e+02 1.831104e+02 1.930130e+00 0 0 1 "
    "3.318498e-03\n"
    "Tr: -1.857739385241e-03 -9.999659513510e-01 -8.039975204516e-03 -4.784029760483e-03 "
    "-6.481465826011e-03 8.051860151134e-03 -9.999466081774e-01 -7.337429464231e-02 "
    "9.999773098287e-01 -1.805528627661e-03 -6.496203536139e-03 -3.339968064433e-01\n";
constexpr double kTr[12] = {-1.857739385241e-03, -9.999659513510e-01, -8.039975204516e-03,
                            -4.784029760483e-03, -6.481465826011e-03, 8.051860151134e-03,
                            -9.999466081774e-01, -7.337429464231e-02, 9.999773098287e-01,
                            -1.805528627661e-03, -6.496203536139e-03, -3.339968064433e-01};

void WriteText(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

// A deterministic grey texture, different per frame and camera.
cv::Mat Pattern(int width, int height, int seed) {
  cv::Mat image(height, width, CV_8UC1);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) image.at<uint8_t>(y, x) = (x * 3 + y * 5 + seed * 17) % 256;
  }
  return image;
}

void WritePng(const fs::path& path, const cv::Mat& image) {
  ASSERT_TRUE(cv::imwrite(path.string(), image)) << path;
}

struct SyntheticOdometryOptions {
  bool colour = false;  // also write a colour pair image_2/image_3
};

// <root>/sequences/05 with 3 frames of 64x48 and <root>/poses/05.txt.
struct SyntheticOdometry {
  fs::path folder;
  int width = 64;
  int height = 48;
  Rigid3d cam0_from_velo;
  std::vector<Rigid3d> world_from_cam0;
  cv::Mat left_image(int frame) const { return Pattern(width, height, 2 * frame); }
};

std::string KittiPoseLine(const Rigid3d& pose) {
  const Matrix3x4d m = pose.Matrix3x4();
  std::string line;
  for (int i = 0; i < 12; ++i)
    line += fmt::format("{:.17g}{}", m(i / 4, i % 4), i < 11 ? " " : "\n");
  return line;
}

SyntheticOdometry WriteSyntheticOdometry(const fs::path& root, SyntheticOdometryOptions options) {
  SyntheticOdometry data;
  data.folder = root / "sequences" / "05";
  for (const char* camera : {"image_0", "image_1", "velodyne"}) {
    fs::create_directories(data.folder / camera);
  }
  if (options.colour) {
    fs::create_directories(data.folder / "image_2");
    fs::create_directories(data.folder / "image_3");
  }
  fs::create_directories(root / "poses");
  for (int frame = 0; frame < 3; ++frame) {
    const std::string name = fmt::format("{:06d}.png", frame);
    WritePng(data.folder / "image_0" / name, data.left_image(frame));
    WritePng(data.folder / "image_1" / name, Pattern(data.width, data.height, 2 * frame + 1));
    if (options.colour) {
      cv::Mat bgr;
      cv::merge(std::vector<cv::Mat>(3, data.left_image(frame)), bgr);
      WritePng(data.folder / "image_2" / name, bgr);
      WritePng(data.folder / "image_3" / name, bgr);
    }
  }
  WriteText(data.folder / "calib.txt", kOdometryCalib);
  WriteText(data.folder / "times.txt", "0.000000e+00\n1.038752e-01\n2.078941e-01\n");
  VelodyneScan scan;
  scan.points = {{5, 1, -1.7}, {6, -1, -1.7}};
  WriteVelodyneScan(data.folder / "velodyne" / "000001.bin", scan);
  Matrix3x4d tr;
  for (int i = 0; i < 12; ++i) tr(i / 4, i % 4) = kTr[i];
  data.cam0_from_velo = Rigid3d::FromMatrix3x4(tr);
  // First pose not the identity, to check rebasing; then 1 m forward; then a 90 deg yaw in place.
  const Rigid3d start(Eigen::Matrix3d(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY())),
                      Eigen::Vector3d(1, 2, 3));
  const Rigid3d forward(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 1));
  const Rigid3d yaw(Eigen::Matrix3d(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY())),
                    Eigen::Vector3d::Zero());
  data.world_from_cam0 = {start, start * forward, start * forward * yaw};
  std::string poses;
  for (const Rigid3d& pose : data.world_from_cam0) poses += KittiPoseLine(pose);
  WriteText(root / "poses" / "05.txt", poses);
  return data;
}

// <root>/2011_09_26/2011_09_26_drive_0001_sync with 2 grey frames of 64x48.
fs::path WriteSyntheticRaw(const fs::path& root, bool calib_in_parent) {
  const fs::path folder = root / "2011_09_26" / "2011_09_26_drive_0001_sync";
  for (const char* camera : {"image_00", "image_01"}) {
    fs::create_directories(folder / camera / "data");
    for (int frame = 0; frame < 2; ++frame) {
      WritePng(folder / camera / "data" / fmt::format("{:010d}.png", frame),
               Pattern(64, 48, frame));
    }
  }
  WriteText(folder / "image_00" / "timestamps.txt",
            "2011-09-26 13:02:25.964389445\n2011-09-26 13:02:26.068543144\n");
  WriteText((calib_in_parent ? folder.parent_path() : folder) / "calib_cam_to_cam.txt",
            "calib_time: 09-Jan-2012 13:57:47\n"
            "S_rect_00: 1.242000e+03 3.750000e+02\n"
            "R_rect_00: 1 0 0 0 1 0 0 0 1\n"
            "P_rect_00: 7.215377e+02 0 6.095593e+02 0 0 7.215377e+02 1.728540e+02 0 0 0 1 0\n"
            "P_rect_01: 7.215377e+02 0 6.095593e+02 -3.875744e+02 0 7.215377e+02 1.728540e+02 0 "
            "0 0 1 0\n");
  return folder;
}

double PathLength(const std::vector<Rigid3d>& poses) {
  double length = 0;
  for (std::size_t i = 1; i < poses.size(); ++i) {
    length += (poses[i].translation - poses[i - 1].translation).norm();
  }
  return length;
}

void ExpectIdentity(const Rigid3d& pose) {
  EXPECT_NEAR(pose.translation.norm(), 0.0, 1e-9);
  EXPECT_NEAR(RotationAngle(pose.rotation, Eigen::Quaterniond::Identity()), 0.0, 1e-9);
}

TEST(KittiSequenceRaw, LoadsGreyDrive0001) {
  PLANELOC_SHARED_DATA_OR_SKIP(folder, "kitti-raw-2011_09_26_drive_0001");
  const KittiSequence sequence = KittiSequence::Open(folder);
  EXPECT_EQ(sequence.layout(), KittiLayout::kRaw);
  ASSERT_EQ(sequence.size(), 108u);
  EXPECT_EQ(sequence.camera().width, 1242);
  EXPECT_EQ(sequence.camera().height, 375);
  EXPECT_DOUBLE_EQ(sequence.camera().fx, 721.5377);
  EXPECT_NEAR(sequence.camera().baseline, 387.5744 / 721.5377, 1e-12);
  EXPECT_NEAR(sequence.camera().baseline, 0.537, 1e-3);
  EXPECT_EQ(sequence.left_image_path(0).filename(), "0000000000.png");
  EXPECT_EQ(sequence.right_image_path(107).parent_path().parent_path().filename(), "image_01");
  EXPECT_EQ(sequence.timestamp(0), 0.0);
  for (std::size_t i = 1; i < sequence.size(); ++i) {
    const double step = sequence.timestamp(i) - sequence.timestamp(i - 1);
    EXPECT_GT(step, 0.09) << i;
    EXPECT_LT(step, 0.11) << i;
  }
  // 13:02:25.967790592 to 13:02:37.004875264: the nanoseconds survive the subtraction.
  EXPECT_NEAR(sequence.timestamp(107), 11.037084672, 1e-9);
  EXPECT_FALSE(sequence.ground_truth().has_value());
  EXPECT_FALSE(sequence.velodyne_path(0).has_value());
  ASSERT_TRUE(sequence.cam_from_velo().has_value());
  // The Velodyne sits ~0.27 m behind and ~0.08 m above camera 0 (KITTI set-up figure).
  const Eigen::Vector3d velo_in_cam = sequence.cam_from_velo()->translation;
  EXPECT_NEAR(velo_in_cam.z(), -0.27, 0.02);
  EXPECT_NEAR(velo_in_cam.y(), -0.08, 0.02);

  EXPECT_TRUE(sequence.HasFrame(5));
  const StereoPair pair = sequence.LoadStereoPair(5);
  EXPECT_EQ(pair.left.type(), CV_8UC1);
  EXPECT_EQ(pair.right.type(), CV_8UC1);
  EXPECT_EQ(pair.left.cols, 1242);
  EXPECT_EQ(pair.right.rows, 375);
  EXPECT_GT(cv::norm(pair.left, pair.right, cv::NORM_L1), 0.0);

  // image_02 holds timestamps only: the colour pair cannot be chosen.
  EXPECT_THROW(KittiSequence::Open(folder, CameraChoice::kColor), InputError);
}

TEST(KittiSequenceRaw, ColourDrive0023WithOxtsGroundTruth) {
  PLANELOC_SHARED_DATA_OR_SKIP(folder, "kitti-raw-2011_09_26_drive_0023-7frames");
  const KittiSequence sequence = KittiSequence::Open(folder);  // no grey pair: colour
  ASSERT_EQ(sequence.size(), 7u);
  EXPECT_EQ(sequence.left_image_path(0).parent_path().parent_path().filename(), "image_02");
  EXPECT_NEAR(sequence.camera().baseline, (44.85728 + 339.5242) / 721.5377, 1e-9);
  const StereoPair pair = sequence.LoadStereoPair(6);
  EXPECT_EQ(pair.left.type(), CV_8UC1);  // converted from colour
  EXPECT_EQ(pair.left.size(), cv::Size(1242, 375));

  ASSERT_TRUE(sequence.ground_truth().has_value());
  const std::vector<Rigid3d>& world_from_cam = *sequence.ground_truth();
  ASSERT_EQ(world_from_cam.size(), 7u);
  ExpectIdentity(world_from_cam[0]);
  EXPECT_NEAR(PathLength(world_from_cam), 5.62, 0.01);
  // Camera frame: the car drives forward, along +z, staying level (small x and y).
  const Eigen::Vector3d last = world_from_cam.back().translation;
  EXPECT_GT(last.z(), 5.5);
  EXPECT_LT(std::abs(last.x()), 0.3);
  EXPECT_LT(std::abs(last.y()), 0.1);
}

// poses_cam02.txt: the source's OXTS-derived image_02 poses relative to the drive's frame 0 (our
// frame 0 is its frame 139), so compare motions relative to our first frame.
TEST(KittiSequenceRaw, OxtsPosesMatchTheSourcesCameraPoses) {
  PLANELOC_SHARED_DATA_OR_SKIP(folder, "kitti-raw-2011_09_26_drive_0023-7frames");
  const KittiSequence sequence = KittiSequence::Open(folder, CameraChoice::kColor);
  ASSERT_TRUE(sequence.ground_truth().has_value());
  std::ifstream stream(folder / "poses_cam02.txt");
  std::vector<Rigid3d> reference;
  Matrix3x4d m;
  while (stream >> m(0, 0)) {
    for (int i = 1; i < 12; ++i) stream >> m(i / 4, i % 4);
    reference.push_back(Rigid3d::FromMatrix3x4(m));
  }
  ASSERT_EQ(reference.size(), sequence.size());
  const Rigid3d first_inverse = reference.front().Inverse();
  double max_translation = 0, max_rotation_deg = 0;
  for (std::size_t i = 0; i < reference.size(); ++i) {
    const Rigid3d expected = first_inverse * reference[i];
    const Rigid3d& actual = (*sequence.ground_truth())[i];
    max_translation = std::max(max_translation, (expected.translation - actual.translation).norm());
    max_rotation_deg = std::max(max_rotation_deg,
                                RotationAngle(expected.rotation, actual.rotation) * 180.0 / M_PI);
  }
  std::cout << "[   info   ] OXTS vs poses_cam02.txt: max " << max_translation * 100 << " cm, "
            << max_rotation_deg << " deg\n";
  EXPECT_LT(max_translation, 0.01);
  EXPECT_LT(max_rotation_deg, 0.01);
}

TEST(KittiSequenceOdometry, SyntheticGreySequenceWithGroundTruth) {
  TempDir dir;
  const SyntheticOdometry data = WriteSyntheticOdometry(dir.path(), {});
  const KittiSequence sequence = KittiSequence::Open(data.folder);
  EXPECT_EQ(sequence.layout(), KittiLayout::kOdometry);
  ASSERT_EQ(sequence.size(), 3u);
  EXPECT_DOUBLE_EQ(sequence.camera().fx, 707.0912);
  EXPECT_DOUBLE_EQ(sequence.camera().cx, 601.8873);
  EXPECT_DOUBLE_EQ(sequence.camera().cy, 183.1104);
  EXPECT_NEAR(sequence.camera().baseline, 0.537, 1e-3);
  EXPECT_EQ(sequence.camera().width, data.width);
  EXPECT_EQ(sequence.camera().height, data.height);
  EXPECT_EQ(sequence.timestamps(), (std::vector<double>{0.0, 0.1038752, 0.2078941}));
  EXPECT_EQ(sequence.left_image_path(2).filename(), "000002.png");

  const StereoPair pair = sequence.LoadStereoPair(1);
  EXPECT_EQ(pair.left.size(), cv::Size(data.width, data.height));
  EXPECT_EQ(cv::norm(pair.left, data.left_image(1), cv::NORM_INF), 0.0);

  // Velodyne: only frame 1 has a scan; cam_from_velo is Tr for camera 0.
  EXPECT_FALSE(sequence.velodyne_path(0).has_value());
  ASSERT_TRUE(sequence.velodyne_path(1).has_value());
  EXPECT_EQ(sequence.velodyne_path(1)->filename(), "000001.bin");
  ASSERT_TRUE(sequence.cam_from_velo().has_value());
  EXPECT_TRUE(sequence.cam_from_velo()->translation.isApprox(data.cam0_from_velo.translation));

  // GT from ../../poses/05.txt, rebased so that the first pose is the identity.
  ASSERT_TRUE(sequence.ground_truth().has_value());
  ASSERT_EQ(sequence.ground_truth()->size(), 3u);
  ExpectIdentity(sequence.ground_truth()->at(0));
  for (std::size_t i = 0; i < 3; ++i) {
    const Rigid3d expected = data.world_from_cam0[0].Inverse() * data.world_from_cam0[i];
    EXPECT_TRUE(sequence.ground_truth()->at(i).translation.isApprox(expected.translation, 1e-9));
    EXPECT_NEAR(RotationAngle(sequence.ground_truth()->at(i).rotation, expected.rotation), 0, 1e-9);
  }
}

TEST(KittiSequenceOdometry, ColourPairUsesP2P3AndShiftsPosesByTheCameraOffset) {
  TempDir dir;
  SyntheticOdometryOptions options;
  options.colour = true;
  const SyntheticOdometry data = WriteSyntheticOdometry(dir.path(), options);
  const KittiSequence auto_choice = KittiSequence::Open(data.folder);  // grey first
  EXPECT_EQ(auto_choice.left_image_path(0).parent_path().filename(), "image_0");
  const KittiSequence sequence = KittiSequence::Open(data.folder, CameraChoice::kColor);
  EXPECT_EQ(sequence.left_image_path(0).parent_path().filename(), "image_2");
  EXPECT_NEAR(sequence.camera().baseline, (46.88783 + 333.4597) / 707.0912, 1e-9);
  const StereoPair pair = sequence.LoadStereoPair(0);
  EXPECT_EQ(pair.left.type(), CV_8UC1);

  // Camera 2 sits o = P2(0,3)/fx = 0.0663 m along x from camera 0 (x_cam2 = x_cam0 + o).
  const Eigen::Vector3d offset(46.88783 / 707.0912, 0, 0);
  EXPECT_TRUE(sequence.cam_from_velo()->translation.isApprox(
      data.cam0_from_velo.translation + offset, 1e-9));
  // Camera 0 moves by (R, t) in its first frame; camera 2's centre, -o in camera 0, moves to
  // R (-o) + t, which is R (-o) + t + o in the first camera-2 frame.
  const Rigid3d cam0_motion = data.world_from_cam0[0].Inverse() * data.world_from_cam0[2];
  const Eigen::Vector3d expected =
      cam0_motion.translation + offset - cam0_motion.RotationMatrix() * offset;
  ExpectIdentity(sequence.ground_truth()->at(0));
  EXPECT_TRUE(sequence.ground_truth()->at(2).translation.isApprox(expected, 1e-9))
      << sequence.ground_truth()->at(2).translation.transpose() << " vs " << expected.transpose();
}

TEST(KittiSequenceRaw, SyntheticRawWithCalibInDateFolderAndNanosecondTimestamps) {
  TempDir dir;
  const auto folder = WriteSyntheticRaw(dir.path(), /*calib_in_parent=*/true);
  std::ofstream(folder / "image_00" / "timestamps.txt")
      << "2011-09-26 23:59:59.999999999\n2011-09-27 00:00:00.100000001\n";
  const KittiSequence sequence = KittiSequence::Open(folder, CameraChoice::kGrey);
  EXPECT_EQ(sequence.layout(), KittiLayout::kRaw);
  ASSERT_EQ(sequence.size(), 2u);
  EXPECT_EQ(sequence.timestamp(0), 0.0);
  EXPECT_NEAR(sequence.timestamp(1), 0.100000002, 1e-12);
  EXPECT_NEAR(sequence.camera().baseline, 0.537, 1e-3);
  EXPECT_FALSE(sequence.ground_truth().has_value());
}

TEST(ParseCameraChoice, AcceptsSpellingsAndRejectsOthers) {
  EXPECT_EQ(ParseCameraChoice("auto"), CameraChoice::kAuto);
  EXPECT_EQ(ParseCameraChoice("grey"), CameraChoice::kGrey);
  EXPECT_EQ(ParseCameraChoice("gray"), CameraChoice::kGrey);
  EXPECT_EQ(ParseCameraChoice("color"), CameraChoice::kColor);
  EXPECT_EQ(ParseCameraChoice("colour"), CameraChoice::kColor);
  EXPECT_THROW(ParseCameraChoice("rgb"), InputError);
}

TEST(Velodyne, ReadsRealScanAndRoundTrips) {
  PLANELOC_SHARED_DATA_OR_SKIP(path, "kitti00-velodyne/000094.bin");
  const VelodyneScan scan = ReadVelodyneScan(path);
  EXPECT_EQ(scan.points.size() * 16, std::filesystem::file_size(path));
  EXPECT_GT(scan.points.size(), 100000u);
  EXPECT_LT(scan.points.size(), 140000u);
  ASSERT_EQ(scan.reflectance.size(), scan.points.size());
  // Sensor 1.73 m above the road: the median height of the points lies below the sensor.
  std::vector<double> heights;
  for (const auto& point : scan.points) heights.push_back(point.z());
  std::nth_element(heights.begin(), heights.begin() + heights.size() / 2, heights.end());
  EXPECT_LT(heights[heights.size() / 2], 0.0);

  TempDir dir;
  WriteVelodyneScan(dir.path() / "copy.bin", scan);
  EXPECT_EQ(std::filesystem::file_size(dir.path() / "copy.bin"), std::filesystem::file_size(path));
  const VelodyneScan copy = ReadVelodyneScan(dir.path() / "copy.bin");
  ASSERT_EQ(copy.points.size(), scan.points.size());
  for (std::size_t i = 0; i < scan.points.size(); i += 97) {
    EXPECT_EQ(copy.points[i], scan.points[i]);
    EXPECT_EQ(copy.reflectance[i], scan.reflectance[i]);
  }
}

TEST(Velodyne, RoundTripKeepsReflectance) {
  VelodyneScan scan;
  scan.points = {{1.5, -2.25, 0.125}, {10, 20, -1.75}};  // exact in float32
  scan.reflectance = {0.5f, 0.0625f};
  TempDir dir;
  WriteVelodyneScan(dir.path() / "scan.bin", scan);
  const VelodyneScan copy = ReadVelodyneScan(dir.path() / "scan.bin");
  EXPECT_EQ(copy.points, scan.points);
  EXPECT_EQ(copy.reflectance, scan.reflectance);
}

// Runs `action`, expects an InputError whose path ends with `path_suffix` (and `line` if > 0).
template <typename Action>
void ExpectInputError(Action action, const std::string& path_suffix, int line = 0) {
  try {
    action();
    ADD_FAILURE() << "expected InputError about " << path_suffix;
  } catch (const InputError& error) {
    EXPECT_TRUE(error.path().size() >= path_suffix.size() &&
                error.path().compare(error.path().size() - path_suffix.size(), path_suffix.size(),
                                     path_suffix) == 0)
        << error.what();
    if (line > 0) {
      EXPECT_EQ(error.line(), line) << error.what();
    }
    EXPECT_FALSE(error.fix().empty()) << error.what();
  }
}

TEST(KittiSequenceBadInput, MissingOrForeignFolder) {
  TempDir dir;
  ExpectInputError([&] { KittiSequence::Open(dir.path() / "nope"); }, "nope");
  ExpectInputError([&] { KittiSequence::Open(dir.path()); }, dir.path().filename().string());
}

TEST(KittiSequenceBadInput, RealDriveWithoutRightCamera) {
  PLANELOC_SHARED_DATA_OR_SKIP(folder, "kitti-raw-2011_09_26_drive_0052-lidar-camera");
  ExpectInputError([&] { KittiSequence::Open(folder); }, "image_01/data");
  ExpectInputError([&] { KittiSequence::Open(folder, CameraChoice::kColor); }, "image_03/data");
}

TEST(KittiSequenceBadInput, MissingCalibration) {
  TempDir dir;
  const SyntheticOdometry data = WriteSyntheticOdometry(dir.path(), {});
  fs::remove(data.folder / "calib.txt");
  ExpectInputError([&] { KittiSequence::Open(data.folder); }, "05/calib.txt");
  TempDir raw_dir;
  const fs::path raw = WriteSyntheticRaw(raw_dir.path(), /*calib_in_parent=*/false);
  fs::remove(raw / "calib_cam_to_cam.txt");
  ExpectInputError([&] { KittiSequence::Open(raw); }, "calib_cam_to_cam.txt");
}

TEST(KittiSequenceBadInput, CalibLineWithTooFewNumbers) {
  TempDir dir;
  const SyntheticOdometry data = WriteSyntheticOdometry(dir.path(), {});
  std::string calib = kOdometryCalib;
  const auto p1_end = calib.find('\n', calib.find("P1:"));
  calib.erase(calib.rfind(' ', p1_end), p1_end - calib.rfind(' ', p1_end));  // drop last number
  WriteText(data.folder / "calib.txt", calib);
  ExpectInputError([&] { KittiSequence::Open(data.folder); }, "calib.txt", 2);
}

TEST(KittiSequenceBadInput, ZeroBaseline) {
  TempDir dir;
  const SyntheticOdometry data = WriteSyntheticOdometry(dir.path(), {});
  std::string calib = kOdometryCalib;
  calib.replace(calib.find("-3.798145e+02"), 13, "0");
  WriteText(data.folder / "calib.txt", calib);
  ExpectInputError([&] { KittiSequence::Open(data.folder); }, "calib.txt", 2);
}

TEST(KittiSequenceBadInput, ImageThatDoesNotDecode) {
  TempDir dir;
  const SyntheticOdometry data = WriteSyntheticOdometry(dir.path(), {});
  WriteText(data.folder / "image_0" / "000001.png", "this is not a png");
  const KittiSequence sequence = KittiSequence::Open(data.folder);  // frame 0 is fine
  EXPECT_NO_THROW(sequence.LoadStereoPair(0));
  ExpectInputError([&] { sequence.LoadStereoPair(1); }, "image_0/000001.png");
  // A broken first image fails at Open, where the image size is read.
  WriteText(data.folder / "image_0" / "000000.png", "garbage");
  ExpectInputError([&] { KittiSequence::Open(data.folder); }, "image_0/000000.png");
  // A deleted frame is reported by HasFrame and by LoadStereoPair.
  EXPECT_TRUE(sequence.HasFrame(2));
  fs::remove(data.folder / "image_1" / "000002.png");
  EXPECT_FALSE(sequence.HasFrame(2));
  ExpectInputError([&] { sequence.LoadStereoPair(2); }, "image_1/000002.png");
}

TEST(KittiSequenceBadInput, LeftRightSizeMismatch) {
  TempDir dir;
  const SyntheticOdometry data = WriteSyntheticOdometry(dir.path(), {});
  WritePng(data.folder / "image_1" / "000001.png", Pattern(60, 48, 0));
  WritePng(data.folder / "image_0" / "000002.png", Pattern(32, 24, 0));
  WritePng(data.folder / "image_1" / "000002.png", Pattern(32, 24, 0));
  const KittiSequence sequence = KittiSequence::Open(data.folder);
  ExpectInputError([&] { sequence.LoadStereoPair(1); }, "image_1/000001.png");
  ExpectInputError([&] { sequence.LoadStereoPair(2); }, "image_0/000002.png");
}

TEST(KittiSequenceGaps, MissingRightImageMidSequenceIsASkippableFrame) {
  TempDir dir;
  const SyntheticOdometry data = WriteSyntheticOdometry(dir.path(), {});
  fs::remove(data.folder / "image_1" / "000001.png");
  const KittiSequence sequence = KittiSequence::Open(data.folder);
  ASSERT_EQ(sequence.size(), 3u);
  EXPECT_TRUE(sequence.HasFrame(0));
  EXPECT_FALSE(sequence.HasFrame(1));
  EXPECT_TRUE(sequence.HasFrame(2));
  ExpectInputError([&] { sequence.LoadStereoPair(1); }, "image_1/000001.png");
  EXPECT_NO_THROW(sequence.LoadStereoPair(2));
  EXPECT_NEAR(sequence.timestamp(2), 0.2078941, 1e-12);
}

TEST(KittiSequenceGaps, FrameMissingInBothCamerasKeepsItsNumberAndTime) {
  TempDir dir;
  const SyntheticOdometry data = WriteSyntheticOdometry(dir.path(), {});
  fs::remove(data.folder / "image_0" / "000001.png");
  fs::remove(data.folder / "image_1" / "000001.png");
  const KittiSequence sequence = KittiSequence::Open(data.folder);
  ASSERT_EQ(sequence.size(), 3u);
  EXPECT_FALSE(sequence.HasFrame(1));
  EXPECT_EQ(sequence.left_image_path(2).filename(), "000002.png");
  EXPECT_NEAR(sequence.timestamp(1), 0.1038752, 1e-12);
  ASSERT_TRUE(sequence.ground_truth().has_value());
  EXPECT_EQ(sequence.ground_truth()->size(), 3u);
}

TEST(KittiSequenceBadInput, LeftRightCountMismatch) {
  TempDir dir;
  const SyntheticOdometry data = WriteSyntheticOdometry(dir.path(), {});
  // Two of three right images gone: not a gap, the cameras do not belong together.
  fs::remove(data.folder / "image_1" / "000001.png");
  fs::remove(data.folder / "image_1" / "000002.png");
  ExpectInputError([&] { KittiSequence::Open(data.folder); }, "image_1");
  TempDir other;
  const SyntheticOdometry renumbered = WriteSyntheticOdometry(other.path(), {});
  fs::copy_file(renumbered.folder / "image_1" / "000001.png",
                renumbered.folder / "image_1" / "000007.png");
  ExpectInputError([&] { KittiSequence::Open(renumbered.folder); }, "image_1");
}

TEST(KittiSequenceBadInput, FirstLeftImageMissing) {
  TempDir dir;
  const SyntheticOdometry data = WriteSyntheticOdometry(dir.path(), {});
  fs::remove(data.folder / "image_0" / "000000.png");
  ExpectInputError([&] { KittiSequence::Open(data.folder); }, "image_0/000000.png");
}

TEST(KittiSequenceBadInput, FirstFrameIncompleteOrOfAnotherSize) {
  TempDir dir;
  const SyntheticOdometry data = WriteSyntheticOdometry(dir.path(), {});
  fs::remove(data.folder / "image_1" / "000000.png");
  ExpectInputError([&] { KittiSequence::Open(data.folder); }, "image_1/000000.png");
  WritePng(data.folder / "image_1" / "000000.png", Pattern(60, 48, 0));
  ExpectInputError([&] { KittiSequence::Open(data.folder); }, "image_1/000000.png");
}

TEST(KittiSequenceBadInput, BlankImageIsAnError) {
  TempDir dir;
  const SyntheticOdometry data = WriteSyntheticOdometry(dir.path(), {});
  WritePng(data.folder / "image_1" / "000001.png", cv::Mat(48, 64, CV_8UC1, cv::Scalar(0)));
  const KittiSequence sequence = KittiSequence::Open(data.folder);
  EXPECT_NO_THROW(sequence.LoadStereoPair(0));
  ExpectInputError([&] { sequence.LoadStereoPair(1); }, "image_1/000001.png");
}

TEST(KittiSequenceBadInput, TimesNotIncreasing) {
  TempDir dir;
  const SyntheticOdometry data = WriteSyntheticOdometry(dir.path(), {});
  WriteText(data.folder / "times.txt", "0.0\n0.1\n0.1\n");
  ExpectInputError([&] { KittiSequence::Open(data.folder); }, "times.txt", 3);
  WriteText(data.folder / "times.txt", "0\n0\n0\n");  // all zero
  ExpectInputError([&] { KittiSequence::Open(data.folder); }, "times.txt", 2);
  TempDir raw_dir;
  const fs::path raw = WriteSyntheticRaw(raw_dir.path(), /*calib_in_parent=*/false);
  std::ifstream in(raw / "image_00" / "timestamps.txt");
  std::string first, second;
  std::getline(in, first);
  std::getline(in, second);
  in.close();
  WriteText(raw / "image_00" / "timestamps.txt", second + "\n" + first + "\n");
  ExpectInputError([&] { KittiSequence::Open(raw); }, "image_00/timestamps.txt", 2);
}

TEST(KittiSequenceBadInput, TimesCountMismatch) {
  TempDir dir;
  const SyntheticOdometry data = WriteSyntheticOdometry(dir.path(), {});
  WriteText(data.folder / "times.txt", "0.0\n0.1\n");
  ExpectInputError([&] { KittiSequence::Open(data.folder); }, "times.txt");
  WriteText(data.folder / "times.txt", "0.0\n0.1\nabc\n");
  ExpectInputError([&] { KittiSequence::Open(data.folder); }, "times.txt", 3);
  TempDir raw_dir;
  const fs::path raw = WriteSyntheticRaw(raw_dir.path(), /*calib_in_parent=*/false);
  WriteText(raw / "image_00" / "timestamps.txt", "2011-09-26 13:02:25.964389445\n");
  ExpectInputError([&] { KittiSequence::Open(raw); }, "image_00/timestamps.txt");
  WriteText(raw / "image_00" / "timestamps.txt", "2011-09-26 13:02:25.9\n26.09.2011 13:02\n");
  ExpectInputError([&] { KittiSequence::Open(raw); }, "image_00/timestamps.txt", 2);
}

TEST(KittiSequenceBadInput, GroundTruthCountOrLine) {
  TempDir dir;
  const SyntheticOdometry data = WriteSyntheticOdometry(dir.path(), {});
  const std::string pose_line = KittiPoseLine(Rigid3d());
  WriteText(dir.path() / "poses" / "05.txt", pose_line + pose_line);
  ExpectInputError([&] { KittiSequence::Open(data.folder); }, "poses/05.txt");
  WriteText(dir.path() / "poses" / "05.txt", pose_line + "1 0 0 0 0 1 0 0 0 0 1\n" + pose_line);
  ExpectInputError([&] { KittiSequence::Open(data.folder); }, "poses/05.txt", 2);
}

TEST(KittiSequenceBadInput, OxtsCountMismatch) {
  TempDir dir;
  const fs::path raw = WriteSyntheticRaw(dir.path(), /*calib_in_parent=*/false);
  fs::create_directories(raw / "oxts" / "data");
  WriteText(raw / "oxts" / "data" / "0000000000.txt", "49 8 110 0 0 0");
  ExpectInputError([&] { KittiSequence::Open(raw); }, "oxts/data");
}

TEST(KittiSequenceBadInput, VelodyneSizeNotMultipleOf16) {
  TempDir dir;
  WriteText(dir.path() / "000000.bin", std::string(20, '\0'));
  ExpectInputError([&] { ReadVelodyneScan(dir.path() / "000000.bin"); }, "000000.bin");
  ExpectInputError([&] { ReadVelodyneScan(dir.path() / "missing.bin"); }, "missing.bin");
}

}  // namespace
}  // namespace planeloc
