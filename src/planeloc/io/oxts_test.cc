#include "planeloc/io/oxts.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"
#include "planeloc/util/test_data.h"

namespace planeloc {
namespace {

TEST(Oxts, MercatorMatchesDevkitFormulas) {
  EXPECT_NEAR(MercatorScale(60.0), 0.5, 1e-15);
  const Eigen::Vector2d origin = LatLonToMercator(0.0, 0.0, 1.0);
  EXPECT_NEAR(origin.norm(), 0.0, 1e-9);
  // One degree of longitude at the equator is pi * er / 180 metres.
  EXPECT_NEAR(LatLonToMercator(0.0, 1.0, 1.0).x(), 111319.490793, 1e-5);
  // my = s er ln(tan((90 + lat) pi / 360)); at lat 45: ln(tan(67.5 deg)) = 0.881373587.
  EXPECT_NEAR(LatLonToMercator(45.0, 0.0, 0.5).y(), 0.5 * 6378137.0 * 0.881373587019543, 1e-4);
}

TEST(Oxts, PosesAreRelativeToTheFirstPacket) {
  // Heading north (yaw = 90 deg), then 10 m further north and turned by 30 deg.
  const double lat0 = 49.0;
  const double metres_per_degree_lat = M_PI * kOxtsEarthRadius / 180.0;
  const std::vector<OxtsPacket> packets = {
      {lat0, 8.4, 110.0, 0.0, 0.0, M_PI / 2},
      {lat0 + 10.0 / metres_per_degree_lat, 8.4, 111.0, 0.0, 0.0, M_PI / 2 + M_PI / 6}};
  const std::vector<Rigid3d> imu0_from_imu = OxtsToImuPoses(packets);
  ASSERT_EQ(imu0_from_imu.size(), 2u);
  EXPECT_NEAR(imu0_from_imu[0].translation.norm(), 0.0, 1e-9);
  EXPECT_NEAR(RotationAngle(imu0_from_imu[0].rotation, Eigen::Quaterniond::Identity()), 0, 1e-9);
  // Northward motion is the first IMU's forward (x) axis; Mercator stretches by ~1/cos(lat) and
  // the scale cos(lat0) undoes it.
  EXPECT_NEAR(imu0_from_imu[1].translation.x(), 10.0, 1e-3);
  EXPECT_NEAR(imu0_from_imu[1].translation.y(), 0.0, 1e-6);
  EXPECT_NEAR(imu0_from_imu[1].translation.z(), 1.0, 1e-9);
  EXPECT_NEAR(RotationAngle(imu0_from_imu[1].rotation, Eigen::Quaterniond::Identity()), M_PI / 6,
              1e-9);
}

TEST(Oxts, RotationOrderIsYawPitchRoll) {
  const OxtsPacket packet{49.0, 8.4, 100.0, 0.1, 0.2, 0.3};
  const Rigid3d world_from_imu = OxtsToWorldFromImu({packet}).front();
  const double cr = std::cos(0.1), sr = std::sin(0.1), cp = std::cos(0.2), sp = std::sin(0.2),
               cy = std::cos(0.3), sy = std::sin(0.3);
  Eigen::Matrix3d rx, ry, rz;
  rx << 1, 0, 0, 0, cr, -sr, 0, sr, cr;
  ry << cp, 0, sp, 0, 1, 0, -sp, 0, cp;
  rz << cy, -sy, 0, sy, cy, 0, 0, 0, 1;
  EXPECT_TRUE(world_from_imu.RotationMatrix().isApprox(rz * ry * rx, 1e-12));
}

TEST(Oxts, CameraPosesFollowTheRigidMount) {
  // Camera 1 m ahead of the IMU, looking forward (z_cam = x_imu, x_cam = -y_imu, y_cam = -z_imu).
  Eigen::Matrix3d cam_rotation_from_imu;
  cam_rotation_from_imu << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  const Rigid3d cam_from_imu(cam_rotation_from_imu,
                             cam_rotation_from_imu * Eigen::Vector3d(-1, 0, 0));
  // IMU turns left by 90 deg in place.
  const std::vector<Rigid3d> imu_poses = {
      Rigid3d(), Rigid3d(Eigen::Matrix3d(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ())),
                         Eigen::Vector3d::Zero())};
  const std::vector<Rigid3d> cam_poses = ImuPosesToCameraPoses(imu_poses, cam_from_imu);
  EXPECT_NEAR(cam_poses[0].translation.norm(), 0, 1e-12);
  // The camera swings from (1,0,0)_imu to (0,1,0)_imu: in the first camera frame that is 1 m
  // left (-x) and 1 m back (-z).
  EXPECT_TRUE(cam_poses[1].translation.isApprox(Eigen::Vector3d(-1, 0, -1), 1e-12));
}

TEST(OxtsBadInput, ShortOrNonNumericPacket) {
  TempDir dir;
  const auto short_path = dir.path() / "0000000000.txt";
  std::ofstream(short_path) << "49.0 8.4 110 0 0 0.5\n";
  try {
    ReadOxtsPacket(short_path);
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(error.path(), short_path.string());
    EXPECT_EQ(error.line(), 1);
    EXPECT_NE(error.problem().find("6 values, expected 30"), std::string::npos);
  }
  const auto junk_path = dir.path() / "0000000001.txt";
  std::ofstream(junk_path) << "49.0 north 110\n";
  EXPECT_THROW(ReadOxtsPacket(junk_path), InputError);
  EXPECT_THROW(ReadOxtsPacket(dir.path() / "missing.txt"), InputError);
}

TEST(Oxts, ReadsRealPacket) {
  PLANELOC_SHARED_DATA_OR_SKIP(path,
                               "kitti-raw-2011_09_26_drive_0023-7frames/oxts/data/0000000000.txt");
  const OxtsPacket packet = ReadOxtsPacket(path);
  EXPECT_DOUBLE_EQ(packet.lat_deg, 49.032806841152);
  EXPECT_DOUBLE_EQ(packet.lon_deg, 8.4385595703734);
  EXPECT_DOUBLE_EQ(packet.alt_m, 113.9702835083);
  EXPECT_DOUBLE_EQ(packet.yaw, 2.9196693267949);
}

}  // namespace
}  // namespace planeloc
