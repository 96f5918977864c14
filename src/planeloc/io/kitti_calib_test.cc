#include "planeloc/io/kitti_calib.h"

#include <gtest/gtest.h>

#include <fstream>

#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"
#include "planeloc/util/test_data.h"

namespace planeloc {
namespace {

// P0/P1 of KITTI odometry sequences 04-12 (sequences/07/calib.txt).
constexpr const char* kP0 =
    "P0: 7.070912e+02 0 6.018873e+02 0 0 7.070912e+02 1.831104e+02 0 0 0 1 0";
constexpr const char* kP1 =
    "P1: 7.070912e+02 0 6.018873e+02 -3.798145e+02 0 7.070912e+02 1.831104e+02 0 0 0 1 0";

std::filesystem::path WriteText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
  return path;
}

TEST(KittiCalib, ParsesOdometryCalibOfSequence07) {
  PLANELOC_SHARED_DATA_OR_SKIP(path, "kitti-odometry-gt/sequences/07/calib.txt");
  const KittiOdometryCalib calib = ReadKittiOdometryCalib(path);
  EXPECT_DOUBLE_EQ(calib.p[0](0, 0), 707.0912);
  EXPECT_DOUBLE_EQ(calib.p[0](0, 2), 601.8873);
  EXPECT_DOUBLE_EQ(calib.p[0](1, 2), 183.1104);
  EXPECT_DOUBLE_EQ(calib.p[1](0, 3), -379.8145);
  ASSERT_TRUE(calib.has_cam0_from_velo);
  // Tr maps the Velodyne's forward axis (x) onto the camera's forward axis (z).
  const Eigen::Vector3d forward = calib.cam0_from_velo.rotation * Eigen::Vector3d::UnitX();
  EXPECT_GT(forward.z(), 0.999);
  EXPECT_NEAR(calib.cam0_from_velo.translation.z(), -0.334, 1e-3);

  const StereoCamera camera =
      StereoCameraFromCalib(KittiCalibFile::Read(path), "P0", "P1", 1226, 370);
  EXPECT_DOUBLE_EQ(camera.fx, 707.0912);
  EXPECT_DOUBLE_EQ(camera.cx, 601.8873);
  EXPECT_DOUBLE_EQ(camera.cy, 183.1104);
  EXPECT_NEAR(camera.baseline, 0.537, 1e-3);
  EXPECT_NEAR(camera.baseline, 379.8145 / 707.0912, 1e-12);
}

TEST(KittiCalib, ParsesRawCamToCamAndSkipsTextLines) {
  PLANELOC_SHARED_DATA_OR_SKIP(path, "kitti-raw-2011_09_26_drive_0001/calib_cam_to_cam.txt");
  const KittiCalibFile calib = KittiCalibFile::Read(path);
  EXPECT_TRUE(calib.Has("calib_time"));  // a date, parsed only if asked for
  EXPECT_EQ(calib.LineOf("P_rect_01"), 18);
  const Matrix3x4d p_rect_01 = calib.Matrix3x4("P_rect_01");
  EXPECT_DOUBLE_EQ(p_rect_01(0, 0), 721.5377);
  EXPECT_DOUBLE_EQ(p_rect_01(0, 3), -387.5744);
  EXPECT_EQ(calib.Numbers("S_rect_00", 2), (std::vector<double>{1242, 375}));
  const Eigen::Matrix3d r_rect = calib.Matrix3("R_rect_00");
  EXPECT_NEAR((r_rect.transpose() * r_rect - Eigen::Matrix3d::Identity()).norm(), 0, 1e-5);
  EXPECT_THROW(calib.Numbers("calib_time", 2), InputError);
}

TEST(KittiCalib, RectifiedCameraOffsetIsXOffsetOfProjection) {
  Matrix3x4d p2;
  p2 << 721.5377, 0, 609.5593, 44.85728, 0, 721.5377, 172.854, 0.2163791, 0, 0, 1, 0.002745884;
  const Rigid3d cam2_from_cam0 = RectifiedCameraFromCam0(p2);
  EXPECT_NEAR(cam2_from_cam0.translation.x(), 0.06217, 1e-5);
  EXPECT_EQ(cam2_from_cam0.translation.y(), 0.0);
  EXPECT_EQ(cam2_from_cam0.translation.z(), 0.0);
  EXPECT_NEAR(RotationAngle(cam2_from_cam0.rotation, Eigen::Quaterniond::Identity()), 0, 1e-12);
}

TEST(KittiCalib, RigidFromRotationAndTranslation) {
  TempDir dir;
  const auto path = WriteText(dir.path() / "calib_velo_to_cam.txt",
                              "calib_time: 15-Mar-2012 11:37:16\n"
                              "R: 0 -1 0 0 0 -1 1 0 0\n"
                              "T: 0.1 0.2 0.3\n");
  const Rigid3d cam_from_velo = KittiCalibFile::Read(path).RigidFromRT("R", "T");
  // Velodyne x (forward) -> camera z; velodyne y (left) -> camera -x.
  EXPECT_TRUE(
      (cam_from_velo * Eigen::Vector3d(1, 0, 0)).isApprox(Eigen::Vector3d(0.1, 0.2, 1.3), 1e-12));
  EXPECT_TRUE(
      (cam_from_velo * Eigen::Vector3d(0, 1, 0)).isApprox(Eigen::Vector3d(-0.9, 0.2, 0.3), 1e-12));
}

TEST(KittiCalibBadInput, MissingFile) {
  TempDir dir;
  try {
    KittiCalibFile::Read(dir.path() / "calib.txt");
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(error.path(), (dir.path() / "calib.txt").string());
    EXPECT_NE(error.fix(), "");
  }
}

TEST(KittiCalibBadInput, LineWithTooFewNumbersNamesFileAndLine) {
  TempDir dir;
  const auto path =
      WriteText(dir.path() / "calib.txt", std::string(kP0) + "\nP1: 7.070912e+02 0 6.018873e+02\n");
  const KittiCalibFile calib = KittiCalibFile::Read(path);
  try {
    calib.Matrix3x4("P1");
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(error.path(), path.string());
    EXPECT_EQ(error.line(), 2);
    EXPECT_NE(std::string(error.what()).find("calib.txt:2"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("3 numbers, expected 12"), std::string::npos);
  }
  EXPECT_NO_THROW(calib.Matrix3x4("P0"));
}

TEST(KittiCalibBadInput, NonNumericValueMissingKeyAndLineWithoutKey) {
  TempDir dir;
  const auto path = WriteText(dir.path() / "calib.txt", "T: 0.1 abc 0.3\n");
  const KittiCalibFile calib = KittiCalibFile::Read(path);
  try {
    calib.Vector3("T");
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(error.line(), 1);
    EXPECT_NE(error.problem().find("'abc'"), std::string::npos);
  }
  try {
    calib.Matrix3("R");
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(error.problem().find("`R` is missing"), std::string::npos);
  }
  const auto no_key = WriteText(dir.path() / "bad.txt", std::string(kP0) + "\n\n1 2 3\n");
  try {
    KittiCalibFile::Read(no_key);
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(error.line(), 3);
  }
}

TEST(KittiCalibBadInput, ZeroBaselineNamesRightCameraLine) {
  TempDir dir;
  std::string p1_same_as_p0 = kP0;
  p1_same_as_p0[1] = '1';
  const auto path =
      WriteText(dir.path() / "calib.txt", std::string(kP0) + "\n" + p1_same_as_p0 + "\n");
  try {
    StereoCameraFromCalib(KittiCalibFile::Read(path), "P0", "P1", 1226, 370);
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(error.path(), path.string());
    EXPECT_EQ(error.line(), 2);
    EXPECT_NE(error.problem().find("baseline"), std::string::npos);
  }
  const auto good = WriteText(dir.path() / "good.txt", std::string(kP0) + "\n" + kP1 + "\n");
  EXPECT_NO_THROW(StereoCameraFromCalib(KittiCalibFile::Read(good), "P0", "P1", 1226, 370));
}

TEST(KittiCalibBadInput, NonRotationIsRejected) {
  TempDir dir;
  const auto path = WriteText(dir.path() / "calib.txt", "R: 1 0 0 0 2 0 0 0 1\nT: 0 0 0\n");
  try {
    KittiCalibFile::Read(path).RigidFromRT("R", "T");
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(error.line(), 1);
    EXPECT_NE(error.problem().find("not a rotation"), std::string::npos);
  }
}

}  // namespace
}  // namespace planeloc
