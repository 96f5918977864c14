#include "planeloc/io/initial_pose.h"

#include <gtest/gtest.h>

#include <fstream>

#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc {
namespace {

TEST(InitialPoseTest, ParsesTwelveNumbersRowMajor) {
  const Rigid3d pose = ParsePose12("0 -1 0 1.5  1 0 0 -2  0 0 1 0.25");
  EXPECT_NEAR((pose * Eigen::Vector3d(1, 0, 0) - Eigen::Vector3d(1.5, -1, 0.25)).norm(), 0, 1e-12);
  EXPECT_EQ(ParseNumberList("1 2 x"), std::vector<double>{});
  EXPECT_EQ(ParseNumberList("1 2.5e1"), (std::vector<double>{1, 25}));
}

TEST(InitialPoseTest, RefusesTheWrongCountAndNonRotations) {
  EXPECT_THROW(ParsePose12("1 0 0 0 0 1 0 0 0 0 1"), InputError);    // 11 numbers
  EXPECT_THROW(ParsePose12("2 0 0 0 0 1 0 0 0 0 1 0"), InputError);  // not a rotation
  EXPECT_THROW(ParsePose12("1 0 0 nan 0 1 0 0 0 0 1 0"), InputError);
}

TEST(InitialPoseTest, ReadsTheFirstPoseOfKittiAndTumFiles) {
  TempDir dir("initial_pose");
  const auto kitti = dir.path() / "kitti.txt";
  std::ofstream(kitti) << "# comment\n1 0 0 3 0 1 0 4 0 0 1 5\n1 0 0 9 0 1 0 9 0 0 1 9\n";
  EXPECT_NEAR((ReadFirstPose(kitti).translation - Eigen::Vector3d(3, 4, 5)).norm(), 0, 1e-12);
  const auto tum = dir.path() / "tum.txt";
  std::ofstream(tum) << "0.0 1 2 3 0 0 0.7071067811865476 0.7071067811865476\n";
  const Rigid3d pose = ReadFirstPose(tum);
  EXPECT_NEAR((pose.translation - Eigen::Vector3d(1, 2, 3)).norm(), 0, 1e-12);
  EXPECT_NEAR((pose.rotation * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 0,
              1e-12);
  const auto empty = dir.path() / "empty.txt";
  std::ofstream(empty) << "";
  EXPECT_THROW(ReadFirstPose(empty), InputError);
  const auto bad = dir.path() / "bad.txt";
  std::ofstream(bad) << "1 2 3\n";
  try {
    ReadFirstPose(bad);
    FAIL() << "a 3-number line was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.txt"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace planeloc
